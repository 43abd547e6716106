"""The general robust gain (workbench/features/robust_gain.py) on loops of no
paper: the Fridman & Shaked 2002 (IEEE TAC 47(11)) example A = [[0, 0],
[0, 1]], B = [1; 1], and the same loop with its unstable pole moved to 1.2."""
import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.robust_gain import (load_robust_settings, robust_quantities,
                                            robust_quantity_names, run_robust)
from workbench.features.robust_gain_render import (eps_search_figure, robust_gain_section,
                                                   robust_method_text)
from workbench.margins import spectral_abscissa
from workbench.reader import Reader

B = np.array([[1.0], [1.0]])
POINTS = [(np.array([[0.0, 0.0], [0.0, a]]), B) for a in (1.0, 1.2)]
IDS = ["a1", "a1.2"]
TABLE = {"alpha": 0.05, "eps_grid": [0.1, 1.0, 10.0], "golden_steps": 1, "h_max": 5.0}


def test_settings_defaults_and_bad_input():
    s = load_robust_settings(Reader("toy.toml", TABLE, "synthesis"))
    assert (s.alpha, s.eps_grid, s.golden_steps, s.order, s.rel_tol) == \
        (0.05, (0.1, 1.0, 10.0), 1, 2, 1e-2)
    with pytest.raises(DesignError, match="synthesis.alpha"):
        load_robust_settings(Reader("toy.toml", {**TABLE, "alpha": -0.1}, "synthesis"))


@pytest.fixture(scope="module")
def robust():
    return run_robust(POINTS, load_robust_settings(Reader("toy.toml", TABLE, "synthesis")))


def test_one_gain_certified_at_every_point(robust):
    syn = robust.synthesis
    assert syn.K is not None and syn.gain.h_certified > 0
    assert len(robust.checks) == len(POINTS) == len(robust.abscissa)
    for (A, B_), c, a in zip(POINTS, robust.checks, robust.abscissa):
        assert c.stable_at_zero and c.exact.h >= syn.gain.h_certified * (1 - 1e-3)
        # the decay rate certified at h holds at every point (cross-check)
        assert a <= -0.05 + 1e-6
        assert a == pytest.approx(spectral_abscissa(A, B_ @ syn.K, syn.gain.h_certified))
    # beyond the exact margin of the worse point the same K loses stability
    h_bad = 1.01 * min(c.exact.h for c in robust.checks)
    assert max(spectral_abscissa(A, B_ @ syn.K, h_bad) for A, B_ in POINTS) > 0


def test_quantities_match_their_names(robust):
    q = robust_quantities(IDS, 2, robust)
    assert set(q) == robust_quantity_names(IDS, 2)
    assert q["robust.all_stable"] == "yes"
    assert q["synthesis.K2"] == float(robust.synthesis.K[0, 1])
    assert q["points[a1.2].exact_margin"] == robust.checks[1].exact.h
    text = robust_gain_section(IDS, robust)
    assert text.startswith("## Robust gain") and "`a1.2`" in text
    assert eps_search_figure(robust).name == "eps-search"
    method = robust_method_text(robust.settings)
    assert method.startswith("Synthesis: descriptor method") and "order 2." in method


def test_robust_points_study_on_toy_points():
    """The general study over points (workbench/kinds/delay_feedback/robust_points.py):
    any points with an id and A, B; its tables read, its quantities declared
    exactly as computed."""
    from types import SimpleNamespace

    from workbench.features.quantities import names, values
    from workbench.kinds.delay_feedback.robust_points import (load_robust_points,
                                                              robust_points_quantities,
                                                              run_robust_points)
    pts = [SimpleNamespace(id=i, A=A, B=B_) for i, (A, B_) in zip(IDS, POINTS)]
    root = Reader("toy.toml", {"synthesis": TABLE, "compare": [
        {"name": "zero", "K": [0.0, 0.0], "source": "the open loop, unstable"}]})
    spec = load_robust_points(root, pts)
    assert spec.ids == IDS and spec.requirements is None and spec.compare[0].name == "zero"
    res = run_robust_points(spec)
    table = robust_points_quantities()
    q = values(table, spec, res)
    assert set(q) == names(table, spec)
    assert q["compare[zero].all_stable"] == "no" and q["compare[zero].unstable_points"] == 2.0
    assert q["synthesis.K1"] == float(res.robust.synthesis.K[0, 0])
    with pytest.raises(DesignError, match="compare"):
        load_robust_points(Reader("toy.toml", {"synthesis": TABLE, "compare": [
            {"name": "short", "K": [1.0], "source": "x"}]}), pts)


def test_requirements_section_of_toy_points():
    """robust_points_render.requirements_section on toy points (no paper): the
    objective, the delay range and the requirements table with the rounded gain."""
    from types import SimpleNamespace

    from workbench.kinds.delay_feedback.robust_points_render import (requirements_section,
                                                                     robust_points_report)
    q = SimpleNamespace(objective="decay", delay=(0.0, 0.25), sources={"decay": "toy"})
    row = SimpleNamespace(name="decay", required=">= 0.1", certified=0.123, exact=0.2,
                          verdict="met")
    r = SimpleNamespace(rows=(row,), K=np.array([[-1.5, 0.25]]), reason=None)
    spec = SimpleNamespace(requirements=q, settings=SimpleNamespace(gain_digits=3), ids=["p"])
    text = requirements_section(SimpleNamespace(requirements=r, spec=spec))
    assert text.startswith("## Requirements\n\nOne gain for every operating point below")
    assert "objective **decay**, every constant delay in [0, 0.25] s" in text
    assert "| decay | >= 0.1 | 0.12 | 0.2 | **met** | toy |" in text
    assert "K = " in text and "-1.5" in text
    # the report: requirements, the study's note, its problem, then the robust gain
    syn = SimpleNamespace(K=None, eps=1.0, reason="toy", bracket=SimpleNamespace(h_certified=0.0))
    res = SimpleNamespace(requirements=r, spec=spec, robust=SimpleNamespace(
        synthesis=syn, settings=SimpleNamespace(alpha=0.1)))
    out = robust_points_report(res, "## Problem\n\ntoy", "toy K", "A note.")
    assert out.sections[0] == text + "\n\nA note.\n\n## Problem\n\ntoy"
    assert out.sections[1].startswith("## Robust gain\n\n**No gain was certified**")
    res.requirements = None
    assert robust_points_report(res, "## Problem", "toy K", "A note.").sections[0] == "## Problem"
