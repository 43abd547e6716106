"""The general claim-level refinement (workbench.features.refinement, issue
35) on systems that are no paper's: a toy study refining its own steps with
a quantity-pattern -> metric-reader table, the screen of several metrics of
a toy ODE, and a toy Monte Carlo share claim over runs refined in part."""
from __future__ import annotations

import math
import re

from workbench.claims import Claim, ClaimResult, Verdict
from workbench.features import refinement as R
from workbench.sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED


def _euler(h: float, a: float = 1.0) -> float:
    """y' = -a y, y(0) = 1, by explicit Euler to t = 1 (order 1)."""
    y = 1.0
    for _ in range(round(1.0 / h)):
        y -= h * a * y
    return y


def _claim(cid, quantity, compare, value, tol=0.0):
    return Claim(cid, f"claim {cid}", quantity, compare, value, tol, None, "round", "workbench",
                 False, "pass", "", "safety", "workbench")


def test_readers_refine_a_toy_studys_findings_by_quantity():
    """Two toy readers: ``decay[a].y1`` by explicit Euler at dt, dt/2, dt/4
    (the pattern's group is the rate a), ``label`` a word at every level; a
    finding no reader knows has no three-level check and is INCONCLUSIVE."""
    seen = []

    def decay(m, r):
        seen.append(m.group(1))
        a = float(m.group(1))
        return R.Levels(tuple(_euler(0.01 / 2 ** k, a) for k in R.LEVELS), "dt", 0.01)

    readers = ((re.compile(r"decay\[([0-9.]+)\]\.y1$"), decay),
               (re.compile(r"label$"), lambda m, r: R.Levels(("ok",) * 3)))
    finds = [ClaimResult(_claim("y", "decay[2].y1", "within", math.exp(-2), 5e-3),
                         _euler(0.01, 2.0), Verdict.PASS),
             ClaimResult(_claim("w", "label", "==", "ok"), "ok", Verdict.PASS),
             ClaimResult(_claim("u", "other.q", "<=", 1.0), 0.5, Verdict.PASS)]
    lv = R.refine_by_readers(finds, readers)
    assert seen == ["2"] and set(lv) == {"y", "u", "w"}
    assert lv["y"].label == "dt = 0.01 s" and lv["u"].values == ()
    assert lv["u"].reason == "no three-level check of `other.q` in this study"
    rows = {r.claim.id: R._own_row(r, lv[r.claim.id], "dt") for r in finds}
    assert rows["y"].outcome == CONVERGED and rows["w"].outcome == CONVERGED
    assert rows["u"].outcome == INCONCLUSIVE and "other.q" in rows["u"].reason
    tight = ClaimResult(_claim("y", "decay[2].y1", "within", math.exp(-2), 1e-6),
                        _euler(0.01, 2.0), Verdict.PASS)
    assert R._own_row(tight, lv["y"], "dt").outcome == NOT_CONVERGED


def test_screen_levels_and_reason_on_a_toy_ode():
    """Euler's y(1) converges at first order within 1 % of |y|; an
    oscillating toy sequence does not, and the reason names it, its
    Richardson error and the quantity to use instead."""
    vals = {"y1": tuple(_euler(0.01 / 2 ** k) for k in R.LEVELS),
            "wobble": (10.0, 11.0, 10.2), "never": (math.nan,) * 3}
    conv, bad = R.screen_levels(vals, 0.01, {"wobble": 0.0})
    assert conv == {"y1": True, "wobble": False, "never": True} and bad == ("wobble",)
    tol = R.screen_tolerances(vals, 0.01, {"y1": 1e-3})
    assert math.isclose(tol["y1"], 1e-3 + 0.01 * max(vals["y1"])) and tol["never"] == 0.0
    why = R.screen_reason({k: vals[k] for k in bad}, 0.01, {}, lambda k: f"toy.{k}",
                          {"wobble": "y1"}, "another metric")
    assert why.startswith("not converged: toy.wobble 10 / 11 / 10.2 at dt, dt/2, dt/4, ")
    assert why.endswith("; use `toy.y1` instead") and "Richardson error" in why
    # an alternative that did not converge either is not offered
    both = R.screen_reason({k: vals[k] for k in ("wobble", "y1")}, 0.01, {}, str,
                           {"wobble": "y1"}, "another metric")
    assert "use `y1` instead" not in both and both.count("use another metric instead") == 2
    assert R.screen_reason({}, 0.01, {}, str, {}, "x") == ""


def test_share_claim_levels_on_a_toy_batch():
    """At most 20 % of 10 toy runs fail: 1 fails at dt, and of the first 4
    refined none fails at dt/2 and dt/4, so 0-6 of 10: undecided there;
    Wilson bounds and fractions of a count by the general quantity names."""
    c = _claim("share", "toy.fraction.failed", "<=", 0.2)
    whole = (True,) + (False,) * 9
    lv = R.share_claim_levels(c, whole, (False,) * 4, (False,) * 4, "failed", "dt", 0.1)
    assert lv.decides == ("holds", "undecided", "undecided")
    assert lv.values[1] == "0 of the first 4, so 0-6 of 10 failed: undecided"
    assert R.share_value("toy.fraction.failed", 3, 10) == 0.3
    lo, hi = (R.share_value(f"toy.wilson.failed.{b}", 3, 10) for b in ("lo", "hi"))
    assert 0 < lo < 0.3 < hi < 1
    full = R.share_claim_levels(c, whole, whole, whole, "failed", "dt", 0.1)
    assert full.decides == ("holds",) * 3
