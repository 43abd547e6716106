"""Severities and the verdict-first Findings block of every report."""
from __future__ import annotations

import re
from pathlib import Path

import pytest

from workbench.claims import SEVERITIES, Claim, Verdict, check_claim, origin_of
from workbench.report.findings import findings_section, index_cells, summarise

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
    assert text.startswith("## Findings\n\n**Verified: all 4 claims hold")
    assert text.index("claim spin") < text.index("claim offset") < text.index("claim minor")
    cells = index_cells(results)
    assert cells[0] == "verified" and cells[1] == "1 of 3"
    assert cells[3].startswith("**safety** (not reproduced: claim spin")


def test_a_claim_that_does_not_hold_leads_the_block():
    results = (check_claim(_claim("broken", 1.0, tol=0.1), 2.0),)
    assert findings_section(results).startswith("## Findings\n\n**NOT OK: 1 of 1 claims")
    assert index_cells(results)[0] == "**NOT OK** (1)"


@pytest.mark.parametrize("path", sorted(p for p in REPORTS.glob("*.md")
                                        if p.stem != "README"),
                         ids=lambda p: p.stem)
def test_every_design_report_opens_with_findings(path):
    md = path.read_text(encoding="utf-8")
    first = re.search(r"^## .*$", md, re.M)[0]
    assert first == "## Findings"


def test_index_shows_severities():
    index = (REPORTS / "README.md").read_text(encoding="utf-8")
    assert "all ok" not in index
    assert "most severe finding" in index
    assert any(f"**{s}**" in index for s in SEVERITIES)
