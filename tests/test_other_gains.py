"""Gains designed elsewhere on a cruise loop: the dry gains of paper 003's
Table 3 on the wet-rail loop (issue 19, item 2), and the links from a
finding to the section that shows it."""
from pathlib import Path

import numpy as np
import pytest

from workbench.design import load_design
from workbench.papers.p003.antiskid_cruise import operating_point
from workbench.features.other_gains import check_other_gains, other_gain_quantities
from workbench.report.findings import section_link
from workbench.report.markdown import slug

REPORTS = Path(__file__).resolve().parents[1] / "reports"


@pytest.fixture(scope="module")
def wet():
    design = load_design("designs/antiskid-cruise-wet.toml")
    lin = operating_point(design.spec)[3]
    return design, lin, check_other_gains(lin.A, lin.B, design.spec.sweep.other_gains)


def test_table3_gains_are_unstable_on_wet_rail(wet):
    design, lin, checks = wet
    assert [c.gain.name for c in checks][0] == "table3-eps0.35"
    # 003 Table 3, eps = 0.35: K = [-0.0049, 10.5080] (dry rail, v_d = 70 m/s)
    assert checks[0].gain.K == (-0.0049, 10.508)
    for c in checks:
        assert not c.stable and c.exact.h == 0.0 and c.exact.reason == "unstable-at-zero-delay"
        Acl = lin.A + lin.B @ np.array([c.gain.K])
        assert c.abscissa == pytest.approx(max(np.linalg.eigvals(Acl).real), rel=1e-12)
        # B = [0, 1]^T: the trace condition alone already fails
        assert np.trace(Acl) > 0
    q = other_gain_quantities(checks)
    assert q["other_gains.stable"] == 0
    assert q["other_gains.min_abscissa"] == pytest.approx(1.8737, abs=1e-4)
    assert q["other_gains[table3-eps0.35].stable"] == "no"


def test_the_same_gains_are_stable_where_they_were_designed():
    dry = load_design("designs/antiskid-cruise-dry.toml")
    lin = operating_point(dry.spec)[3]
    gains = load_design("designs/antiskid-cruise-wet.toml").spec.sweep.other_gains
    assert all(c.stable for c in check_other_gains(lin.A, lin.B, gains))


def test_slug_is_githubs_anchor():
    assert slug("Gains designed elsewhere, on this loop") == "gains-designed-elsewhere-on-this-loop"
    assert slug("`smarc-eq19-printed` — REFUTED") == "smarc-eq19-printed--refuted"
    assert slug("Figures") == "figures"


def test_finding_links_to_its_section():
    anchors = (("other_gains", "Gains designed elsewhere, on this loop"),)
    assert section_link("other_gains.min_abscissa", anchors) == (
        "[Gains designed elsewhere, on this loop](#gains-designed-elsewhere-on-this-loop)")
    assert section_link("synthesis.best.h_certified", anchors) == ""
    md = (REPORTS / "antiskid-cruise-wet.md").read_text(encoding="utf-8")
    findings = md.split("## Findings")[1].split("\n## ")[0]
    assert "`dry-gains-unstable-on-wet`" in findings and "**safety**" in findings
    assert "(#gains-designed-elsewhere-on-this-loop)" in findings
    assert "\n## Gains designed elsewhere, on this loop\n" in md
