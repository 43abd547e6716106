"""The three-level refinement check (workbench.sim.convergence), on schemes
of known order: explicit Euler (p = 1) and Heun's RK2 (p = 2) on x' = -x,
x(0) = 1, whose exact value at t = 1 is exp(-1)."""
import math
from pathlib import Path

import pytest

from workbench.sim.convergence import (CONVERGED, INCONCLUSIVE, NOT_CONVERGED, P_MAX,
                                       refinement_check)


def _euler(dt, t=1.0):
    x = 1.0
    for _ in range(round(t / dt)):
        x += dt * -x
    return x


def _heun(dt, t=1.0):
    x = 1.0
    for _ in range(round(t / dt)):
        k1 = -x
        k2 = -(x + dt * k1)
        x += dt / 2 * (k1 + k2)
    return x


@pytest.mark.parametrize("scheme, order", [(_euler, 1.0), (_heun, 2.0)])
def test_observed_order_and_estimate_of_known_schemes(scheme, order):
    q = [scheme(0.01 / 2 ** k) for k in range(3)]
    r = refinement_check(*q, tolerance=1.0)
    assert r.outcome == CONVERGED
    assert r.order == pytest.approx(order, abs=0.02)
    true_err = abs(q[2] - math.exp(-1))
    assert r.estimate == pytest.approx(true_err, rel=0.03)


def test_estimate_above_tolerance_is_not_converged():
    q = [_euler(0.01 / 2 ** k) for k in range(3)]
    true_err = abs(q[2] - math.exp(-1))
    r = refinement_check(*q, tolerance=true_err / 2)
    assert r.outcome == NOT_CONVERGED and r.estimate > r.tolerance
    assert refinement_check(*q, tolerance=2 * true_err).outcome == CONVERGED


def test_ratio_other_than_two():
    q = [_heun(0.05 / 3 ** k) for k in range(3)]
    r = refinement_check(*q, ratio=3.0, tolerance=1.0)
    assert r.order == pytest.approx(2.0, abs=0.05)
    assert r.estimate == pytest.approx(abs(q[2] - math.exp(-1)), rel=0.05)


def test_rounding_level_differences_converge():
    r = refinement_check(1.0, 1.0 + 1e-16, 1.0, tolerance=1e-9)
    assert r.outcome == CONVERGED and r.order is None
    assert "rounding" in r.note


def test_order_below_guard_uses_the_larger_difference():
    # differences that do not shrink: not in the asymptotic range
    r = refinement_check(1.0, 1.1, 1.2, tolerance=0.1)
    assert r.outcome == INCONCLUSIVE
    assert r.order == pytest.approx(0.0)
    assert r.estimate == pytest.approx(0.1 / (2 ** 0.5 - 1))
    # growing differences, still far below the tolerance: converged (guarded)
    r = refinement_check(1.0, 1.01, 1.2, tolerance=1.0)
    assert r.order < 0 and r.outcome == CONVERGED
    assert r.estimate == pytest.approx(0.19 / (2 ** 0.5 - 1))
    assert "asymptotic" in r.note


def test_order_above_guard_is_clipped_conservatively():
    r = refinement_check(1.0, 1.1, 1.1001, tolerance=1.0)
    assert r.order > P_MAX
    assert r.estimate == pytest.approx(1e-4 / (2 ** P_MAX - 1), rel=1e-6)
    assert "clipped" in r.note
    # only the finer difference is noise: p taken as P_MAX on the floor
    r = refinement_check(1.0, 1.1, 1.1, tolerance=1.0, floor=1e-8)
    assert r.outcome == CONVERGED and r.order == math.inf
    assert r.estimate == pytest.approx(1e-8 / (2 ** P_MAX - 1))


def test_non_finite_is_inconclusive_and_bad_arguments_raise():
    assert refinement_check(1.0, math.nan, 1.0, tolerance=1.0).outcome == INCONCLUSIVE
    with pytest.raises(ValueError):
        refinement_check(1.0, 1.0, 1.0, ratio=1.0, tolerance=1.0)
    with pytest.raises(ValueError):
        refinement_check(1.0, 1.0, 1.0, tolerance=-1.0)


# -- findings on converged numbers (workbench.features.refinement, workbench.verify) ---------------
def _finding(cid, value, compare, tol=0.0, expect="pass", allow=False):
    from workbench.claims import Claim
    return Claim(cid, f"claim {cid}", "x", compare, value, tol, None, "round", "workbench",
                 allow, expect, "why" if expect == "fail" else "", "minor", "workbench")


def test_converged_instead_names_a_quantity_of_the_design(tmp_path):
    from workbench.design import load_design
    from workbench.errors import DesignError
    src = (Path(__file__).resolve().parents[1] / "designs" / "stopping-line5.toml").read_text()
    old = 'id = "smarc-under-8cm"'
    assert old in src
    p = tmp_path / "stopping-line5.toml"
    p.write_text(src.replace(old, old + '\nconverged_instead = "smarc.nominal_m"'))
    c = next(c for c in load_design(p).claims if c.id == "smarc-under-8cm")
    assert c.converged_instead == "smarc.nominal_m"
    p.write_text(src.replace(old, old + '\nconverged_instead = "no.such"'))
    with pytest.raises(DesignError) as exc:
        load_design(p)
    assert exc.value.key.endswith("converged_instead")


def test_claim_tolerance_is_what_could_change_the_verdict():
    from workbench.features.refinement import claim_tolerance
    assert claim_tolerance(_finding("a", 1.0, "within", 0.2), 1.1) == 0.2
    assert claim_tolerance(_finding("b", 1.0, "<="), 0.7) == pytest.approx(0.3)
    assert claim_tolerance(_finding("c", 1.0, ">=", 0.1), 1.5) == pytest.approx(0.6)
    assert claim_tolerance(_finding("d", "yes", "=="), "yes") is None


class _EulerStudy:
    """A stand-in study: its one quantity is explicit Euler's x(1) on x' = -x
    at the spec's step (first order in dt)."""
    kind = "fake"
    refine_field, refine_unit = "dt", "s"

    def run(self, design):
        return _euler(design.spec.dt)

    def quantities(self, res):
        return {"x": res}


@pytest.mark.parametrize("tol, outcome", [(1e-2, CONVERGED), (1e-5, NOT_CONVERGED)])
def test_unconverged_finding_is_inconclusive(monkeypatch, tol, outcome):
    from dataclasses import dataclass

    from workbench import kinds, verify
    from workbench.claims import Verdict
    from workbench.design import Design

    @dataclass(frozen=True)
    class Spec:
        dt: float

    monkeypatch.setattr(kinds, "REGISTRY", {"fake": _EulerStudy()})
    x = _euler(0.01)
    from dataclasses import replace
    claims = (replace(_finding("f", x, "within", tol, expect="pass"), converged_instead="y"),
              _finding("g", x + 1.0, "within", tol, expect="fail", allow=True))
    ev = verify.evaluate_design(Design("fake.toml", "fake", "fake", "t", "s", Spec(0.01), claims))
    row = {r.claim_id: r for r in ev.refinement.rows}
    assert row["f"].outcome == outcome
    assert row["f"].check.order == pytest.approx(1.0, abs=0.05)
    f, g = ev.claims
    if outcome == CONVERGED:
        assert f.verdict is Verdict.PASS and g.verdict is Verdict.FAIL and ev.ok
    else:
        assert f.verdict is Verdict.INCONCLUSIVE and "not converged: x estimate" in f.note
        assert f.note.endswith("use `y` instead")
        assert not f.ok                       # a finding on an unconverged number fails the design
        assert g.verdict is Verdict.INCONCLUSIVE and g.ok     # allowed: shown, not failing
