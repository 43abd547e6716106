"""Severities and the verdict-first Findings block of every report."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from workbench.claims import SEVERITIES, Claim, Verdict, check_claim, origin_of
from workbench.report.findings import findings_section, index_cells, summarise
from workbench.report.verdict import decide, design_items

REPORTS = Path(__file__).resolve().parents[1] / "reports"


def _claim(cid, value, *, compare="within", tol=0.0, expect="pass", severity=None,
           source="003 Table 3", reason=""):
    return Claim(cid, f"claim {cid}", "q", compare, value, tol, None, "round", source, False,
                 expect, reason or ("why" if expect == "fail" else ""), severity,
                 origin_of(source))


def test_origin_from_the_source():
    assert origin_of("003 Table 3") == origin_of("paper 002 §4") == "paper"
    assert origin_of("workbench cross-check") == origin_of("synthetic") == "workbench"


def test_rounding_severity_is_checked():
    # the paper's 40.754 against our 40.751: a rounding of printed inputs (7e-5 relative)
    r = check_claim(_claim("d", 40.754, expect="fail", severity="rounding"), 40.751)
    assert r.verdict is Verdict.FAIL and r.severity_holds and r.ok
    # 2 % off is not a rounding: the claim is not ok although it fails as expected
    r = check_claim(_claim("d", 40.754, expect="fail", severity="rounding"), 41.6)
    assert r.verdict is Verdict.FAIL and not r.severity_holds and not r.ok


def test_summary_orders_findings_most_severe_first():
    results = (
        check_claim(_claim("ok", 1.0, tol=0.1), 1.05),
        check_claim(_claim("minor", 1.0, expect="fail", severity="minor"), 1.2),
        check_claim(_claim("spin", 0.0, compare="<=", expect="fail", severity="safety"), 3.0),
        check_claim(_claim("offset", -3.0, compare="<=", severity="changes-the-result",
                           source="workbench finding"), -3.4),
    )
    s = summarise(results)
    assert [f.id for f in s.findings] == ["spin", "offset", "minor"]
    assert (s.paper, s.reproduced, s.not_ok) == (3, 1, ())
    assert s.by_severity("paper") == {"safety": 1, "minor": 1}
    assert s.by_severity("workbench") == {"changes-the-result": 1}
    text = findings_section(results)
    assert "Verified" not in text
    assert text.index("claim spin") < text.index("claim offset") < text.index("claim minor")
    assert "**no hazard id** (flagged)" in text        # the safety finding links to none
    cells = index_cells(results, decide(design_items(results)))
    assert cells[:2] == ["**reject**", "1 decisive: `spin`"]
    assert cells[3] == "1 of 3" and cells[4] == "<sub>4 of 4</sub>"


def test_a_claim_that_does_not_hold_is_decisive_and_not_ok():
    results = (check_claim(_claim("broken", 1.0, tol=0.1), 2.0),)
    v = decide(design_items(results))
    assert v.verdict == "reject" and "no severity assessed" in v.decisive[0][1]
    assert index_cells(results, v)[4] == "<sub>0 of 1 **NOT OK**</sub>"


@pytest.mark.parametrize("path", sorted(p for p in REPORTS.glob("*.md")
                                        if p.stem not in ("README", "HAZARDS")),
                         ids=lambda p: p.stem)
def test_every_report_opens_with_the_design_verdict(path):
    md = path.read_text(encoding="utf-8")
    first = re.search(r"^## .*$", md, re.M)[0]
    assert first == "## Design verdict"
    assert not re.search(r"^\**Verified", md, re.M)


def test_index_shows_severities():
    index = (REPORTS / "README.md").read_text(encoding="utf-8")
    assert "all ok" not in index and "Verified" not in index
    assert "design verdict" in index
    assert any(f"1 {s}" in index for s in SEVERITIES)      # findings counted by severity
