"""The design verdict, traceability, registers and configuration lines (issue 33)."""
from __future__ import annotations

from pathlib import Path

import pytest

from workbench.claims import Claim, Hazard, check_claim, origin_of
from workbench.design import load_design
from workbench.errors import DesignError
from workbench.report.verdict import (decide, design_items, hazards_markdown,
                                      traceability_section)
from workbench.report.writer import COMMIT_LINE, _sans_commit

DESIGNS = Path(__file__).resolve().parents[1] / "designs"


def _claim(cid, *, expect="pass", severity=None, source="003 Table 3", hazard=None,
           untested=""):
    return Claim(cid, f"claim {cid}", "q", "<=", 1.0, 0.0, None, "round", source, False,
                 expect, "why" if expect == "fail" else "", severity, origin_of(source),
                 requirement=f"R-{cid}", criterion="q <= 1", hazard=hazard,
                 untested=untested)


def _verdict(*pairs, hazards=()):
    results = tuple(check_claim(c, got) for c, got in pairs)
    return decide(design_items(results, hazards))


def test_minor_findings_accept():
    v = _verdict((_claim("ok"), 0.5), (_claim("m", expect="fail", severity="minor"), 2.0))
    assert v.verdict == "accept" and [i.id for i in v.observations] == ["m"]


def test_changes_the_result_accepts_with_conditions():
    v = _verdict((_claim("c", expect="fail", severity="changes-the-result"), 2.0))
    assert v.verdict == "accept with conditions" and v.conditions[0][0].id == "c"


def test_an_untested_requirement_is_a_condition():
    v = _verdict((_claim("circ", untested="circular"), 0.5))
    assert v.verdict == "accept with conditions"


def test_safety_rejects_unless_its_hazard_is_closed():
    spin = _claim("spin", severity="safety", source="workbench", hazard="HZ-1")
    open_ = Hazard("HZ-1", "spin", "c", "q", "m", "open")
    assert _verdict((spin, 0.5), hazards=(open_,)).verdict == "reject"
    closed = Hazard("HZ-1", "spin", "c", "q", "m", "closed")
    assert _verdict((spin, 0.5), hazards=(closed,)).verdict == "accept with conditions"
    # the finding's claim no longer shows the defect: the requirement is met
    assert _verdict((spin, 2.0), hazards=(open_,)).verdict == "accept"
    # a safety finding with no hazard in the log rejects, and says so
    v = _verdict((_claim("lock", severity="safety", source="workbench"), 0.5))
    assert v.verdict == "reject" and "no hazard id" in v.decisive[0][1]


def test_no_claims_is_not_an_accept():
    assert decide(()).verdict == "accept with conditions"


def test_traceability_coverage_counts_requirements():
    results = (check_claim(_claim("a"), 0.5),
               check_claim(_claim("b", expect="fail", severity="minor"), 2.0),
               check_claim(_claim("c"), None))
    text = traceability_section(results, lambda c: "[Claims](#claims)")
    assert "Coverage: 3 requirements — 1 met, 1 not met, 1 not tested" in text
    assert "**not met** (minor)" in text


def test_the_check_ignores_only_the_commit_line():
    a = "x\n- Project commit: `abc`\n- Design file: `d`, SHA-256 `1`\n"
    assert _sans_commit(a) == _sans_commit(a.replace("`abc`", "uncommitted"))
    assert _sans_commit(a) != _sans_commit(a.replace("SHA-256 `1`", "SHA-256 `2`"))
    assert len(COMMIT_LINE.findall(a)) == 1


def _write(tmp_path, extra: str) -> Path:
    src = (DESIGNS / "brake-fit-000.toml").read_text(encoding="utf-8")
    p = tmp_path / "brake-fit-000.toml"
    p.write_text(src + extra, encoding="utf-8")
    return p


@pytest.mark.parametrize("extra, key", [
    ('\n[[claims]]\nid = "x"\ndescription = "d"\nquantity = "rmse.existing"\ncompare = ">="\n'
     'value = 1.0\nsource = "s"\nbasis = "standard"\n', "claims[.*].standard"),
    ('\n[[claims]]\nid = "x"\ndescription = "d"\nquantity = "rmse.existing"\ncompare = ">="\n'
     'value = 1.0\nsource = "workbench"\nseverity = "safety"\nhazard = "HZ-none"\n',
     "claims[.*].hazard"),
    ('\n[[hazards]]\nid = "HZ-1"\nhazard = "h"\ncause = "c"\nconsequence = "q"\n'
     'mitigation = "m"\nstatus = "unknown"\n', "hazards[0].status"),
])
def test_bad_traceability_input_names_the_key(tmp_path, extra, key):
    import re
    with pytest.raises(DesignError) as e:
        load_design(_write(tmp_path, extra))
    assert re.search(key.replace("[", r"\[").replace("]", r"\]").replace(r"\[.*\]", r"\[\d+\]"),
                     str(e.value))


def test_design_hash_and_registers(tmp_path):
    p = _write(tmp_path, '\n[[assumptions]]\ntext = "we chose t"\neffect = "e"\n')
    d = load_design(p)
    assert len(d.sha256) == 64 and d.assumptions[-1].effect == "e"
    import hashlib
    assert d.sha256 == hashlib.sha256(p.read_bytes()).hexdigest()


def test_hazards_markdown_lists_orphans():
    lock = _claim("lock", severity="safety", source="workbench")
    spin = _claim("spin", severity="safety", source="workbench", hazard="HZ-1")
    h = Hazard("HZ-1", "spin", "c", "q", "m", "open")
    md = hazards_markdown([("d", (h,), (lock, spin))])
    assert "`HZ-1`" in md and "`spin`" in md
    assert md.split("## Safety findings without a hazard id")[1].strip().endswith("`lock`")


def test_project_commit_or_uncommitted(tmp_path):
    import shutil
    import subprocess

    from workbench.verify import pinned_versions, project_commit
    if shutil.which("git") is None:
        pytest.skip("no git")
    run = lambda *a: subprocess.run(["git", *a], cwd=tmp_path, check=True, capture_output=True)
    assert project_commit(tmp_path) == ""                       # not a checkout
    run("init", "-q")
    (tmp_path / "constraints.txt").write_text("numpy==2.4.6\n# a comment\nSciPy==1.17.1\n")
    run("add", ".")
    run("-c", "user.name=t", "-c", "user.email=t@t", "commit", "-qm", "x")
    head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=tmp_path, capture_output=True,
                          text=True).stdout.strip()
    assert project_commit(tmp_path) == head
    (tmp_path / "reports").mkdir()
    (tmp_path / "reports" / "r.md").write_text("a report\n")   # reports/ never counts
    assert project_commit(tmp_path) == head
    (tmp_path / "design.toml").write_text("x = 1\n")           # an untracked design does
    assert project_commit(tmp_path) == ""
    assert pinned_versions(tmp_path) == {"numpy": "2.4.6", "scipy": "1.17.1"}
