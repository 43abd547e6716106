"""Claims in CI: project root, init, JUnit XML (schema-validated), timings,
--changed-since and the pytest plugin (issue 18)."""
import subprocess
import tomllib
from dataclasses import replace
from pathlib import Path

import pytest
import xmlschema
# pytester runs pytest in this process and drops the modules the inner run imported;
# numpy's C extensions (numpy.fft's, which scipy.sparse loads) cannot be loaded twice in
# one process, so they are imported here first (the test failed when it ran first on a worker)
import numpy.fft  # noqa: F401, E402
import scipy.sparse  # noqa: F401, E402

from workbench.ci import VerifyRun, design_cases
from workbench.claims import check_claim
from workbench.cli import main
from workbench.design import load_design
from workbench.junit import junit_xml
from workbench.project import MARKER, find_project
from workbench.verify import Evaluation

pytest_plugins = ["pytester"]
ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"
SCHEMA = xmlschema.XMLSchema(DATA / "junit.xsd")


def _project(tmp_path, name="proj") -> Path:
    assert main(["init", str(tmp_path / name)]) == 0
    return tmp_path / name


# -- project root and init ------------------------------------------------------------
def test_init_writes_the_skeleton(tmp_path, capsys):
    p = _project(tmp_path)
    for f in ["workbench.toml", "README.md", "designs/example-cruise.toml",
              "proofs/braking_distance.py", "reports/.gitkeep",
              ".github/workflows/workbench.yml", ".gitlab-ci.yml", ".gitignore"]:
        assert (p / f).is_file(), f
    assert tomllib.loads((p / MARKER).read_text()) == {"project": {"name": "proj"}}
    for ci in (".github/workflows/workbench.yml", ".gitlab-ci.yml"):
        text = (p / ci).read_text()
        assert "workbench verify --junit-xml reports/junit.xml" in text
        assert "pip install \"traincontrol-workbench==" in text
        assert "{" not in text.split("pip")[1][:40]
    assert load_design(p / "designs/example-cruise.toml").name == "example-cruise"


def test_init_never_overwrites(tmp_path, capsys):
    (tmp_path / "full").mkdir()
    (tmp_path / "full" / "x").write_text("keep")
    assert main(["init", str(tmp_path / "full")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "PATH" in err and "never overwrites" in err
    assert sorted(p.name for p in (tmp_path / "full").iterdir()) == ["x"]
    (tmp_path / "empty").mkdir()
    assert main(["init", str(tmp_path / "empty")]) == 0


def test_init_papers_copies_the_shipped_designs_and_proofs(tmp_path):
    assert main(["init", "--papers", str(tmp_path / "papers")]) == 0
    p = tmp_path / "papers"
    assert sorted(f.name for f in (p / "designs").glob("*.toml")) == \
        sorted(f.name for f in (ROOT / "designs").glob("*.toml"))
    assert (p / "designs/benchmarks/classic-2x2.toml").is_file()
    assert (p / "proofs/p004_brake.py").read_text() == (ROOT / "proofs/p004_brake.py").read_text()
    assert not (p / "designs/example-cruise.toml").exists()


def test_project_root_is_the_nearest_marker_upwards(tmp_path, monkeypatch):
    p = _project(tmp_path)
    (p / "designs" / "deep").mkdir()
    assert find_project(p / "designs" / "deep").root == p.resolve()
    assert find_project(tmp_path).root == tmp_path.resolve()    # no marker: the folder itself
    assert not find_project(tmp_path).marked
    monkeypatch.chdir(p / "designs" / "deep")
    assert main(["prove", "example"]) == 0                      # proofs/ of the project root


def test_bad_marker_exits_2(tmp_path, monkeypatch, capsys):
    p = _project(tmp_path)
    (p / MARKER).write_text('[project]\nnmae = "x"\n')
    monkeypatch.chdir(p)
    assert main(["verify", "--changed-since", "HEAD"]) == 2
    err = capsys.readouterr().err
    assert "workbench.toml" in err and "project.nmae" in err and "Traceback" not in err


# -- JUnit XML --------------------------------------------------------------------------
def test_junit_failure_names_expected_got_tolerance_source(tmp_path, capsys):
    out = tmp_path / "j" / "junit.xml"
    assert main(["verify", str(DATA / "failing-claim.toml"), "--junit-xml", str(out)]) == 1
    std = capsys.readouterr()
    assert "| design | seconds |" in std.err and "failing-claim" in std.err
    assert "seconds" not in std.out                 # timings on stderr: stdout stays stable
    SCHEMA.validate(str(out))
    doc = SCHEMA.to_dict(str(out))
    (suite,) = doc["testsuite"]
    assert suite["@name"] == "failing-claim" and suite["@tests"] == 2 and suite["@failures"] == 1
    cases = {c["@name"]: c for c in suite["testcase"]}
    assert set(cases) == {"failing-claim::lambda_d", "failing-claim::h-0.35"}
    assert all(c["@classname"] == "failing-claim" for c in cases.values())
    fail = cases["failing-claim::h-0.35"]["failure"]
    assert fail["@type"] == "FAIL"
    for part in ("expected == 0.05", "got 0.0433", "tolerance 0", "source: 003 Table 3"):
        assert part in fail["@message"], part
    assert "failure" not in cases["failing-claim::lambda_d"]


def test_junit_inconclusive_fails_and_expected_failure_passes():
    d = load_design(DATA / "small-cruise.toml")
    c0, c1 = d.claims
    results = (check_claim(c0, None),                                        # INCONCLUSIVE
               check_claim(replace(c1, expect="fail", reason="known: see note"), 0.04),
               check_claim(replace(c0, id="allowed", allow_inconclusive=True), None),
               check_claim(replace(c1, id="gone", expect="fail", reason="r"), 0.0433))
    run = VerifyRun((Evaluation(d, None, results),), (), (("small-cruise", 1.5),), ())
    text = junit_xml(run, name="t")
    SCHEMA.validate(text)
    cases = {c["@name"].split("::")[1]: c for c in SCHEMA.to_dict(text)["testsuite"][0]["testcase"]}
    assert cases["lambda_d"]["failure"]["@type"] == "INCONCLUSIVE"
    assert "counted as a failure" in cases["lambda_d"]["failure"]["@message"]
    assert "failure" not in cases["h-0.35"]
    assert "known: see note" in cases["h-0.35"]["system-out"]
    assert "failure" not in cases["allowed"]
    assert "went away" in cases["gone"]["failure"]["@message"]       # expected FAIL passed
    assert [c.ok for c in design_cases(run.evaluations[0])] == [False, True, True, False]


def test_junit_of_proof_claims(tmp_path, monkeypatch):
    p = _project(tmp_path)
    monkeypatch.chdir(p)
    (p / "designs" / "example-cruise.toml").unlink()
    bad = p / "proofs" / "braking_distance.py"
    bad.write_text(bad.read_text().replace("96.451", "96.466"))
    assert main(["verify", "--junit-xml", "reports/junit.xml"]) == 1
    SCHEMA.validate("reports/junit.xml")
    (suite,) = SCHEMA.to_dict("reports/junit.xml")["testsuite"]
    cases = {c["@name"]: c for c in suite["testcase"]}
    fail = cases["proofs/braking_distance::stop-distance-50kmh"]["failure"]
    assert fail["@type"] == "REFUTED" and "expected PROVED" in fail["@message"]
    assert "3 printed digits" in fail["@message"] and "source: paper example" in fail["@message"]


# -- --changed-since ----------------------------------------------------------------------
def _git(cwd, *args):
    subprocess.run(["git", *args], cwd=cwd, check=True, capture_output=True,
                   env={"GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@t", "HOME": str(cwd),
                        "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@t",
                        "PATH": "/usr/bin:/bin:/usr/local/bin"})


def test_changed_since_checks_only_what_changed(tmp_path, monkeypatch, capsys):
    p = _project(tmp_path)
    _git(p, "init", "-q")
    _git(p, "add", "-A")
    _git(p, "commit", "-qm", "init")
    monkeypatch.chdir(p)
    assert main(["verify", "--changed-since", "HEAD"]) == 0       # nothing changed
    std = capsys.readouterr()
    assert "0 of 0 claims ok" in std.out
    assert "nothing changed since HEAD" in std.out and "| design |" not in std.out
    assert "2 unchanged" in std.err and "example-cruise" in std.err
    proof = p / "proofs" / "braking_distance.py"
    proof.write_text(proof.read_text() + "\n")
    assert main(["verify", "--changed-since", "HEAD", "--json"]) == 0
    import json
    data = json.loads(capsys.readouterr().out)
    assert data["designs"] == [] and len(data["proofs"]) == 2
    assert main(["verify", "--changed-since", "no-such-ref"]) == 2
    err = capsys.readouterr().err
    assert "--changed-since" in err and "no-such-ref" in err and "Traceback" not in err


def test_changed_since_follows_the_study_imports(tmp_path):
    from workbench.changes import PACKAGE_DIR, design_changed, study_files
    files = study_files("antiskid-cruise")
    assert PACKAGE_DIR / "papers" / "p003" / "antiskid_cruise.py" in files
    assert PACKAGE_DIR / "lmi" / "freeweighting003.py" in files      # imported by the study
    assert PACKAGE_DIR / "claims.py" in files                         # claim machinery
    assert PACKAGE_DIR / "papers" / "p004" / "closed_loop_brake.py" not in files  # another study
    d = tmp_path / "designs"
    d.mkdir()
    design = d / "x.toml"
    assert design_changed(design, "antiskid-cruise", d, {design.resolve()})
    assert design_changed(design, "antiskid-cruise", d, {PACKAGE_DIR / "lmi" / "core.py"})
    assert not design_changed(design, "antiskid-cruise", d,
                              {PACKAGE_DIR / "papers" / "p004" / "closed_loop_brake.py"})
    assert design_changed(design, "antiskid-cruise", d, {(d / "benchmarks" / "a.toml").resolve()})
    assert design_changed(design, "antiskid-cruise", d, {(tmp_path / "constraints.txt").resolve()})


# -- pytest plugin -----------------------------------------------------------------------
def test_pytest_plugin_collects_claims_as_items(pytester):
    assert main(["init", str(pytester.path / "proj")]) == 0
    proj = pytester.path / "proj"
    design = proj / "designs" / "example-cruise.toml"
    design.write_text(design.read_text().replace("value = 0.043\n", "value = 0.045\n"))
    pytester.chdir()
    import os
    os.chdir(proj)
    res = pytester.runpytest("--workbench", "-k", "certified-delay or formula", "-rA")
    res.assert_outcomes(passed=2, failed=1)
    text = res.stdout.str()
    assert "FAILED designs/example-cruise.toml::certified-delay " in text
    assert "expected >= 0.045, got 0.0433" in text and "source: 003 Table 3" in text
    assert "known discrepancy" in text                     # expected failure: its reason shown


def test_pytest_plugin_inactive_without_option_and_ini_selects(pytester):
    assert main(["init", str(pytester.path / "proj")]) == 0
    proj = pytester.path / "proj"
    import os
    os.chdir(proj)
    res = pytester.runpytest()
    assert res.ret == pytest.ExitCode.NO_TESTS_COLLECTED
    (proj / "pytest.ini").write_text("[pytest]\nworkbench_designs = designs/none.toml\n"
                                     "workbench_proofs = false\n")
    res = pytester.runpytest("--workbench", "--collect-only", "-q")
    assert res.ret == pytest.ExitCode.NO_TESTS_COLLECTED
    (proj / "pytest.ini").write_text("[pytest]\ntestpaths = tests\n"
                                     "workbench_designs = designs/example-cruise.toml\n")
    (proj / "tests").mkdir()
    (proj / "tests" / "test_own.py").write_text("def test_own():\n    pass\n")
    res = pytester.runpytest("--workbench", "--collect-only", "-q")
    text = res.stdout.str()
    assert "tests/test_own.py::test_own" in text                        # the team's tests
    assert "designs/example-cruise.toml::certified-delay" in text       # plus the claims
    assert "proofs/braking_distance.py::stop-distance-formula" in text


def test_changed_since_follows_the_analysis_module():
    """A design whose [analysis] table names a paper module (imported by name)
    is checked again when that module, or one it imports, changed."""
    from workbench.changes import PACKAGE_DIR, design_changed
    d = Path("designs").resolve()
    design = d / "stopping-line5.toml"
    p000 = PACKAGE_DIR / "papers" / "p000"
    for f in ("station_stopping.py", "station_stopping_run.py", "station_stopping_render.py"):
        assert design_changed(design, "stop-accuracy", d, {p000 / f}), f
    assert not design_changed(d / "stop-accuracy-synthetic.toml", "stop-accuracy", d,
                              {p000 / "station_stopping.py"})
