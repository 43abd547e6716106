"""The installable package, end to end (issue 18).

Builds the wheel from a copy of the source (tracked and new files), installs
it with its pinned dependencies (``constraints.txt``, from the package index)
into a fresh venv in a temporary folder, and from a folder outside the
checkout runs the README's "Verify in your CI" snippets, then breaks a claim
in a copy of the scaffold and checks it is a named failing test in both the
JUnit XML and pytest's output. Also: ``init --papers`` and ``prove`` from the
wheel. Slow (about 2-4 minutes, most of it pip).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import xmlschema

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = xmlschema.XMLSchema(ROOT / "tests" / "data" / "junit.xsd")

pytestmark = [pytest.mark.slow, pytest.mark.wheel]   # run by `make test-wheel` (.ci/run)


def _run(cmd, cwd, env, ok=(0,), timeout=900):
    res = subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True,
                         timeout=timeout, shell=isinstance(cmd, str), check=False,
                         executable="/bin/bash" if isinstance(cmd, str) else None)
    assert res.returncode in ok, (cmd, res.returncode, res.stdout[-3000:], res.stderr[-3000:])
    return res


def readme_snippets() -> list[str]:
    """The ```sh blocks of README.md marked ``<!-- ci-snippet -->``, in order."""
    text = (ROOT / "README.md").read_text()
    return re.findall(r"<!-- ci-snippet -->\n```sh\n(.*?)```", text, flags=re.DOTALL)


@pytest.fixture(scope="module")
def venv(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("wheel")
    src = tmp / "src"
    files = subprocess.run(["git", "ls-files", "--cached", "--others", "--exclude-standard"],
                           cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    for f in files:
        if (ROOT / f).is_file() and not f.startswith("reports/"):
            (src / f).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(ROOT / f, src / f)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "VIRTUAL_ENV")}
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(tmp / "dist"),
          str(src)], tmp, env)
    (wheel,) = (tmp / "dist").glob("traincontrol_workbench-*.whl")
    _run([sys.executable, "-m", "venv", str(tmp / "venv")], tmp, env)
    py = tmp / "venv" / "bin" / "python"
    _run([str(py), "-m", "pip", "install", "-q", "-c", str(ROOT / "constraints.txt"),
          f"{wheel}[test]"], tmp, env)
    env["PATH"] = f"{tmp / 'venv' / 'bin'}{os.pathsep}{env.get('PATH', '')}"
    work = tmp / "work"
    work.mkdir()
    return work, env, py, wheel


def test_the_wheel_imports_from_the_venv(venv):
    work, env, py, _ = venv
    out = _run([str(py), "-c", "import workbench, sys; print(workbench.__file__)"],
               work, env).stdout.strip()
    assert str(py.parent.parent) in out and str(ROOT) not in out, out


def test_readme_snippets_run_from_the_wheel(venv):
    work, env, _, _ = venv
    snippets = readme_snippets()
    assert len(snippets) == 3 and "workbench init" in snippets[0]
    assert "--junit-xml" in snippets[1] and "pytest --workbench" in snippets[2]
    res = _run("set -e\n" + "\n".join(snippets), work, env)
    assert "6 of 6 claims ok" in res.stdout and "6 passed" in res.stdout
    assert "| design | seconds |" in res.stderr
    junit = work / "my-claims" / "reports" / "junit.xml"
    SCHEMA.validate(str(junit))
    names = {c["@name"] for s in SCHEMA.to_dict(str(junit))["testsuite"] for c in s["testcase"]}
    assert "example-cruise::certified-delay" in names
    assert "proofs/braking_distance::stop-distance-formula" in names
    for ci in (".github/workflows/workbench.yml", ".gitlab-ci.yml"):
        assert snippets[1].strip() in (work / "my-claims" / ci).read_text()


def test_a_broken_claim_is_a_named_failing_test(venv):
    work, env, _, _ = venv
    if not (work / "my-claims").is_dir():
        _run("workbench init my-claims", work, env)
    broken = work / "broken"
    shutil.copytree(work / "my-claims", broken)
    design = broken / "designs" / "example-cruise.toml"
    design.write_text(design.read_text().replace("value = 0.043\n", "value = 0.045\n"))
    res = _run(["workbench", "verify", "--junit-xml", "reports/junit.xml"], broken, env, ok=(1,))
    assert "5 of 6 claims ok; 1 not ok" in res.stdout
    SCHEMA.validate(str(broken / "reports" / "junit.xml"))
    doc = SCHEMA.to_dict(str(broken / "reports" / "junit.xml"))
    failed = {c["@name"]: c["failure"]["@message"] for s in doc["testsuite"]
              for c in s["testcase"] if "failure" in c}
    assert list(failed) == ["example-cruise::certified-delay"]
    assert "expected >= 0.045, got 0.0433" in failed["example-cruise::certified-delay"]
    res = _run(["pytest", "--workbench", "-p", "no:cacheprovider"], broken, env, ok=(1,))
    assert "FAILED designs/example-cruise.toml::certified-delay " in res.stdout
    assert "1 failed, 5 passed" in res.stdout
    res = _run(["pytest", "--workbench", "-k", "certified-delay and not 50ms",
                "-p", "no:cacheprovider"], broken, env, ok=(1,))
    assert "1 failed, 5 deselected" in res.stdout


def test_the_papers_from_the_wheel(venv):
    work, env, _, _ = venv
    _run(["workbench", "init", "--papers", "papers"], work, env)
    papers = work / "papers"
    assert (papers / "designs" / "antiskid-cruise-dry.toml").is_file()
    res = _run(["workbench", "prove", "004"], papers, env)
    assert "11 of 11 proof claims ok" in res.stdout
    res = _run(["workbench", "verify", "designs/closed-loop-brake-004.toml"], papers, env)
    assert "claims ok" in res.stdout and "not ok" not in res.stdout
    res = _run(["workbench", "init", "papers"], work, env, ok=(2,))
    assert "never overwrites" in res.stderr and "Traceback" not in res.stderr


def test_the_ci_install_line_installs_our_package(venv, tmp_path):
    """A project from ``workbench init --requirement WHEEL`` installs our
    distribution in a fresh venv by its GitHub CI file's own install line."""
    work, env, _, wheel = venv
    _run(["workbench", "init", "--requirement", str(wheel), "ci-proj"], work, env)
    line = next(ln for ln in (work / "ci-proj" / ".github/workflows/workbench.yml")
                .read_text().splitlines() if "pip install" in ln)
    cmd = line.split("run:", 1)[1].split("#")[0].strip()
    assert cmd == f'python -m pip install "{wheel}"', cmd
    fresh = tmp_path / "fresh"
    _run([sys.executable, "-m", "venv", str(fresh)], tmp_path, env)
    env2 = dict(env, PATH=f"{fresh / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
    _run(cmd, work / "ci-proj", env2)
    res = _run(["workbench", "--version"], work / "ci-proj", env2)
    assert "(distribution traincontrol-workbench)" in res.stdout
    res = _run([str(fresh / "bin" / "python"), "-m", "pip", "list"], work, env2)
    assert re.search(r"^traincontrol-workbench\s", res.stdout, flags=re.M), res.stdout
    assert not re.search(r"^workbench\s", res.stdout, flags=re.M), res.stdout
