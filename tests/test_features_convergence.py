"""The general convergence feature (workbench.features.convergence, issue 35)
on systems that are no paper's: a toy ODE by explicit Euler and Heun through
a ``metrics_at(step)`` callback, a toy batch of runs for the dt-halving
comparison, and a toy share claim over runs refined in part."""
from __future__ import annotations

import math

import pytest

from workbench.claims import Claim
from workbench.features import convergence as C
from workbench.sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED, Convergence


def _decay(h: float, heun: bool = False) -> dict:
    """y' = -y, y(0) = 1 to t = 1 by explicit Euler (order 1) or Heun (order 2);
    ``never``: a time the run never reaches (NaN at every step)."""
    y = 1.0
    for _ in range(round(1.0 / h)):
        k1 = -y
        y = y + h * (0.5 * (k1 - (y + h * k1)) if heun else k1)
    return {"y1": y, "never": math.nan}


def _claim(cid, quantity, compare, value, tol=0.0):
    return Claim(cid, f"claim {cid}", quantity, compare, value, tol, None, "round", "workbench",
                 False, "pass", "", "safety", "workbench")


def test_three_levels_call_the_callback_at_dt_half_and_quarter():
    seen = []

    def metrics_at(h):
        seen.append(h)
        return _decay(h)

    levels = C.three_levels(metrics_at, 0.1)
    assert seen == [0.1, 0.05, 0.025] and len(levels) == len(C.LEVELS)
    first = {"y1": 0.0, "never": math.nan}
    again = C.three_levels(metrics_at, 0.1, first=first)
    assert again[0] is first and seen[3:] == [0.05, 0.025]


@pytest.mark.parametrize("heun, order", [(False, 1.0), (True, 2.0)])
def test_observed_order_and_richardson_estimate_of_a_toy_ode(heun, order):
    levels = C.three_levels(lambda h: _decay(h, heun), 0.01)
    values = C.by_metric(levels)
    assert list(values) == ["y1", "never"]
    checks = C.level_checks(values, tolerance=1e-3)
    y = checks["y1"]
    assert y.order == pytest.approx(order, abs=0.05)
    true_error = abs(values["y1"][2] - math.exp(-1.0))
    assert y.estimate == pytest.approx(true_error, rel=0.1)
    assert y.outcome is Convergence.CONVERGED and y.outcome == "CONVERGED"
    assert checks["never"].outcome is INCONCLUSIVE        # not determined: NaN
    assert "never" not in C.level_checks(values, finite=True)
    tight = C.level_checks(values, tolerance=true_error / 10)["y1"]
    assert tight.outcome is NOT_CONVERGED and f"{tight.outcome}" == "NOT_CONVERGED"


def test_claim_rows_on_a_toy_ode_against_the_claims_tolerance():
    levels = C.three_levels(_decay, 0.01)
    values = C.by_metric(levels)
    loose = _claim("loose", "y1", "within", math.exp(-1.0), 0.01)
    tight = _claim("tight", "y1", "within", math.exp(-1.0), 1e-5)
    unset = _claim("unset", "never", ">=", 0.0)
    rows = C.rows_of([(c, values[c.quantity]) for c in (loose, tight, unset)])
    assert [r.claim_id for r in rows] == ["loose", "tight"]      # NaN: not determined, left out
    assert rows[0].outcome is CONVERGED and rows[0].reason == ""
    assert rows[1].outcome is NOT_CONVERGED
    assert rows[1].reason.startswith("not converged: y1 estimate ")
    assert C.unconverged(rows) == {"tight": rows[1].reason}
    table = C.claim_table(rows)
    assert "`loose`" in table and "**NOT_CONVERGED**: not converged" in table
    assert C.claim_table([]) == "_No claim on a scenario metric._"


def test_claim_rows_by_scenario_with_the_reported_level():
    target = C.ClaimTarget(_claim("c", "s.a.y1", "within", math.exp(-1.0), 0.01), "a", "y1")
    other = C.ClaimTarget(_claim("d", "s.b.y1", "within", 1.0, 0.01), "b", "y1")
    levels = C.three_levels(_decay, 0.01)
    rows = C.claim_rows((target, other), "a", levels, reported=1)
    assert [r.claim_id for r in rows] == ["c"] and rows[0].values == tuple(
        lv["y1"] for lv in levels)


def test_agree_and_the_dt_halving_comparison_of_a_toy_batch():
    assert C.agree(math.nan, math.nan, 0.0, 0.0) and not C.agree(1.0, math.nan, 1.0, 1.0)
    assert C.agree(1.0, 1.01, 0.01, 0.0) and not C.agree(1.0, 1.03, 0.01, 0.0)
    assert C.agree(0.0, 0.004, 0.0, 0.005)
    # three runs of the toy ODE (rates 1, 2, 50) at dt and dt/2; "stiff": Euler unstable at dt
    rates, dt = (1.0, 2.0, 50.0), 0.05

    def batch(h):
        ys = [(1 - r * h) ** round(1.0 / h) for r in rates]
        return {"y1": ys, "stiff": [abs(1 - r * h) > 1 for r in rates]}

    c, f, same = C.compare_steps(batch(dt), batch(dt / 2), 0.1, {"y1": 1e-3}, ("y1",), ("stiff",))
    assert list(c) == ["y1", "stiff"] and all(isinstance(x, float) for x in c["y1"])
    assert same["y1"][:2] == (True, True) and same["y1"][2] is False
    assert c["stiff"] == (False, False, True) and f["stiff"] == (False,) * 3
    assert same["stiff"] == (True, True, False)
    cmp = C.StepComparison(dt, 0.1, {"y1": 1e-3}, c, f, same)
    assert cmp.n == 3 and cmp.run_agree == (True, True, False)
    assert cmp.quantities("toy.halving") == {"toy.halving.runs": 3, "toy.halving.agree": 2,
                                             "toy.halving.fraction_agree": 2 / 3}


def test_share_levels_bound_the_runs_not_refined():
    """A toy share claim (at most 2 of 10 runs fail): all 10 runs at dt, the
    first 4 again at dt/2 and dt/4. One failure in the first 4 leaves 1-7 of
    10: undecided; four fail there, 4-10 of 10: the claim fails whatever
    the other 6 do."""
    claim = _claim("share", "toy.failed_share", "<=", 0.2)
    share = lambda k, n: k / n       # noqa: E731
    whole = (True,) + (False,) * 9
    vals, dec = C.share_levels(claim, whole, whole[:4], whole[:4], share, "failed")
    assert vals[0] == "1 of 10 failed: holds" and dec == ("holds", "undecided", "undecided")
    assert vals[1] == "1 of the first 4, so 1-7 of 10 failed: undecided"
    _, dec = C.share_levels(claim, whole, (True,) * 4, (True,) * 4, share, "failed")
    assert dec == ("holds", "fails", "fails")
    vals, dec = C.share_levels(claim, whole, whole, whole, share, "failed")
    assert vals == ("1 of 10 failed: holds",) * 3 and dec == ("holds",) * 3


def test_verify_puts_a_studys_reason_on_unconverged_claims(monkeypatch):
    """workbench.verify with a kind's ``unconverged(result)`` (claim id or
    claimed quantity -> reason): a PASS claim becomes INCONCLUSIVE with it, a
    claim whose quantity was not determined gets it instead of "not
    determined" (issue 33), and a claim without a reason stays as it is."""
    from workbench import kinds, verify
    from workbench.claims import Verdict
    from workbench.design import Design

    class Study:
        kind = "fake-conv"

        def run(self, design):
            return "result"

        def quantities(self, res):
            return {"a": 1.0, "b": None, "c": 2.0, "d": 3.0}

        def unconverged(self, res):
            return {"pass-a": "not converged: a", "b": "not converged: b", "c": "n/a"}

    claims = (_claim("pass-a", "a", ">=", 0.0), _claim("undetermined-b", "b", ">=", 0.0),
              _claim("fail-c", "c", "<=", 1.0), _claim("untouched-d", "d", ">=", 0.0))
    monkeypatch.setattr(kinds, "REGISTRY", {"fake-conv": Study()})
    ev = verify.evaluate_design(Design("f.toml", "fake", "fake-conv", "t", "s", None, claims))
    got = {r.claim.id: (r.verdict, r.note) for r in ev.claims}
    assert got["pass-a"] == (Verdict.INCONCLUSIVE, "not converged: a")
    assert got["undetermined-b"] == (Verdict.INCONCLUSIVE, "not converged: b")
    assert got["fail-c"] == (Verdict.INCONCLUSIVE, "n/a")       # keyed by quantity
    assert got["untouched-d"][0] is Verdict.PASS


def test_not_converged_text_of_a_toy_metric():
    values = C.by_metric(C.three_levels(_decay, 0.01))["y1"]
    chk = C.level_checks({"y1": values}, tolerance=1e-6)["y1"]
    text = C.not_converged_text("toy.y1", values, chk.estimate, 1e-6, "`toy.y2`")
    assert text.startswith("toy.y1 0.366032 / 0.366958 / 0.367419 at dt, dt/2, dt/4, Richardson ")
    assert text.endswith(" > tol 1e-6; use `toy.y2` instead") and "error 0.00046" in text
    assert "error not determined (a value is not finite)" in C.not_converged_text(
        "q", (1.0, math.nan, 2.0), None, 0.1, "p")
