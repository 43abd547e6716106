"""Issue 33 item 4 for the two antiskid-run checks that were two-level
screens: the sampled plant mesh (claimed rate metrics at plant_step, /2, /4)
and the Monte Carlo findings (all runs at dt, the first n at dt/2 and dt/4,
the others bounded)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from workbench.claims import Claim, ClaimResult, Verdict, check_claim
from workbench.features import rate_sweep as RS
from workbench.papers.p003 import antiskid_sampled as S
from workbench.features.montecarlo_render import refined_runs_text
from workbench.features.refinement import _own_row, share_claim_levels, share_value
from workbench.sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED

DRY = Path("designs/antiskid-run-dry.toml")

#: Dry rail, zoh_q_tau at 200 Hz, max creep-speed error (m/s) at plant_step,
#: /2, /4 (measured on this tree; /8 and /16 give 0.0066728, 0.0066731): the
#: last mesh point before omega = 3 rad/s moves, and the sign of the
#: differences changes.
EVS_200 = (0.006806080222141159, 0.006809850645913634, 0.006672128682961687)
#: The same at 100 Hz (a claimed metric of the dry design): converges at order 1.
EVS_100 = (0.015409348162022496, 0.015411913506372082, 0.01541319236232458)


def _claim(cid, quantity, compare, value, tol=0.0, expect="pass"):
    return Claim(cid, f"claim {cid}", quantity, compare, value, tol, None, "round", "workbench",
                 False, expect, "why" if expect == "fail" else "", "safety", "workbench")


def test_three_level_check_of_a_rate_metric():
    tol = S.MESH_ATOL["evs_max_tracking"]
    ok = RS.three_level_check("zoh_q_tau", 100.0, "evs_max_tracking", EVS_100, tol)
    assert ok.converged and ok.estimate < 1e-5 and ok.tolerance == S.MESH_ATOL[
        "evs_max_tracking"] and ok.reason() == ""
    bad = RS.three_level_check("zoh_q_tau", 200.0, "evs_max_tracking", EVS_200, tol)
    # every difference is below the two-level screen's 2e-4; the guarded
    # estimate (sign change: the larger difference at order 0.5) is not
    assert max(abs(a - b) for a, b in zip(EVS_200, EVS_200[1:])) < 2e-4
    assert bad.outcome == INCONCLUSIVE and bad.estimate > 2e-4
    assert bad.reason().startswith("not converged: zoh_q_tau 200 Hz evs_max_tracking")
    word = RS.three_level_check("zoh", 20.0, "braking_ok", ("no", "no", "yes"))
    assert word.outcome == NOT_CONVERGED and word.tolerance is None
    assert RS.three_level_check("zoh", 20.0, "braking_ok", ("no",) * 3).converged
    nan = math.nan
    assert RS.three_level_check("zoh", 20.0, "stop_distance", (nan,) * 3).converged
    part = RS.three_level_check("zoh", 20.0, "stop_distance", (nan, 1.0, 1.0))
    assert part.outcome == INCONCLUSIVE and "some levels" in part.note


def _metrics(**over):
    m = {k: 1.0 for k in S.RATE_METRICS}
    m.update(traction_ok="yes", braking_ok="yes", ok="yes", traction_diverged=math.nan,
             braking_diverged=math.nan)
    m.update(over)
    return m


def _result(three_level, agree=True):
    spec = S.SampledSpec((100.0, 200.0), 1e-4, 0, case="compensated", creep_margin=1e-3,
                         predictor_step=1e-3)
    rows = tuple(RS.RateRow(f, _metrics()) for f in spec.rates)
    v = RS.Variant("zoh", 0.0, 0.0, rows, (), 100.0, (None, 100.0),
                  tuple((f, agree, {}) for f in spec.rates), three_level=three_level)
    return S.SampledResult(spec, RS.RateRow(math.nan, _metrics()), 0.005, (v,),
                           lambda_opt=0.1, u_peak=1.0)


def test_a_non_converged_mesh_metric_makes_the_mesh_claim_inconclusive():
    """The two-level screen agrees everywhere, one claimed metric does not
    converge over three levels: the mesh claim is INCONCLUSIVE (not FAIL),
    and the section's three-level table says which metric and why."""
    from workbench.papers.p003.antiskid_sampled_render import three_level_text
    claim = _claim("mesh", "sampled.zoh.mesh_converged", "==", "yes")
    tol = S.MESH_ATOL["evs_max_tracking"]
    good = (RS.three_level_check("zoh", 100.0, "evs_max_tracking", EVS_100, tol),)
    q = S.sampled_quantities(_result(good))
    assert q["sampled.zoh.mesh_converged"] == "yes"
    assert check_claim(claim, q["sampled.zoh.mesh_converged"]).verdict is Verdict.PASS
    bad = good + (RS.three_level_check("zoh", 200.0, "evs_max_tracking", EVS_200, tol),)
    res = _result(bad)
    q = S.sampled_quantities(res)
    assert q["sampled.zoh.mesh_converged"] is None
    assert check_claim(claim, q["sampled.zoh.mesh_converged"]).verdict is Verdict.INCONCLUSIVE
    text = three_level_text(res)
    assert "**not converged: zoh 200 Hz evs_max_tracking" in text and "| converged |" in text
    # a disagreement of the two-level screen is not converged either (was "no": FAIL)
    q = S.sampled_quantities(_result(good, agree=False))
    assert q["sampled.zoh.mesh_converged"] is None


def test_the_claimed_rate_metrics_of_a_design():
    spec = S.SampledSpec((20.0, 100.0, 1000.0, 5000.0), 1e-4, 0, case="c", creep_margin=1e-3,
                         predictor_step=1e-3)
    raw = [{"quantity": "sampled.zoh.rate[100].evs_max_tracking"},
           {"quantity": "sampled.zoh.rate[1000].stop_distance_minus_emulation"},
           {"quantity": "sampled.zoh.rate[5000].lam_max_over_opt"},      # above 1 kHz
           {"quantity": "sampled.zoh.rate[50].ok"},                      # not a grid rate
           {"quantity": "sampled.zoh_q_tau.rate[100].ok"},               # no such variant
           {"quantity": "sampled.zoh.rate[x].ok"}, {"id": "no quantity"}, "not a table",
           {"quantity": "sampled.zoh.rate[20].braking_ok"},
           {"quantity": "sampled.zoh.rate[100].evs_max_tracking"}]
    assert S.SECTION.claimed(spec, raw) == (
        ("zoh", 20.0, "braking_ok"), ("zoh", 100.0, "evs_max_tracking"),
        ("zoh", 1000.0, "stop_distance"))
    assert S.SECTION.claimed(spec, "not a list") == ()
    from workbench.design import load_design
    assert load_design(DRY).spec.sampled.three_level == (
        ("zoh", 20.0, "braking_ok"), ("zoh_q_tau", 50.0, "traction_ok"),
        ("zoh_q_tau", 100.0, "evs_max_tracking"), ("zoh_q_tau", 100.0, "ok"),
        ("zoh_q_tau", 1000.0, "stop_distance"))
    decl = S.model(None, 1e-3)[1]      # the context is used only when a row is computed
    assert decl.scenarios_of("traction_ok") == (0,)
    assert decl.scenarios_of("stop_distance") == (1,)
    assert decl.scenarios_of("ok") == (0, 1) and decl.scenarios_of("u_max_over_peak") == (0, 1)


def test_a_partial_row_is_the_rate_row_of_its_scenarios():
    """The plant_step/4 level runs only the scenario a metric needs, with
    the calls rate_row makes: the same numbers, bit for bit."""
    pytest.importorskip("numba")
    from workbench.design import load_design
    from workbench.papers.p003.antiskid_run_spec import sampled_context
    design = load_design(DRY)
    ctx = sampled_context(design.spec, design.spec.K_table)
    runs, decl = S.model(ctx, 1e-3)
    full = RS.rate_row(runs, decl, 100.0, 8.0, 0.002, 1e-3).metrics

    def part(scenarios):       # a fresh memo: runs of their own, the same numbers
        return RS.partial_row(*S.model(ctx, 1e-3), 100.0, scenarios, 8.0, 0.002,
                              1e-3).metrics
    brake = part((1,))
    assert set(brake) == set(S.NEEDS[1])
    assert {k: repr(v) for k, v in brake.items()} == {k: repr(full[k]) for k in brake}
    both = part((0, 1))
    assert {k: repr(v) for k, v in both.items()} == {k: repr(full[k]) for k in both}
    assert set(both) == set(full)


@pytest.mark.parametrize("quantity, compare, value, decided", [
    ("montecarlo.fraction.diverged", "<=", 0.0, ("fails",) * 3),
    ("montecarlo.wilson.diverged.lo", ">=", 0.776, ("holds", "undecided", "undecided")),
])
def test_mc_share_levels_bound_the_runs_not_refined(quantity, compare, value, decided):
    """All 64 runs diverge at dt and the first 16 at dt/2 and dt/4: 'no run
    diverges' fails whatever the other 48 do there; the Wilson bound of the
    diverged rate needs 57 of 64 and is undecided. Checked against every
    completion of the 48 unrefined runs by a count (the metric depends on the
    count only)."""
    c = _claim("mc", quantity, compare, value)
    lv = share_claim_levels(c, (True,) * 64, (True,) * 16, (True,) * 16, "diverged",
                            "montecarlo.dt", 0.005)
    assert lv.decides == decided and lv.parameter == "montecarlo.dt" and lv.step == 0.005
    assert lv.values[0] == f"64 of 64 diverged: {decided[0]}"
    assert lv.values[1] == f"16 of the first 16, so 16-64 of 64 diverged: {decided[1]}"
    for k in range(16, 65):    # every count the 48 unrefined runs allow at dt/2, dt/4
        v = check_claim(c, share_value(quantity, k, 64)).verdict
        if decided[1] != "undecided":
            assert v is {"holds": Verdict.PASS, "fails": Verdict.FAIL}[decided[1]]
    row = _own_row(ClaimResult(c, 1.0, Verdict.PASS), lv, "dt")
    if decided[1] == "undecided":
        assert row.outcome == NOT_CONVERGED and row.reason.startswith("not converged: ")
        assert "16-64 of 64 diverged: undecided" in row.reason
    else:
        assert row.outcome == CONVERGED and row.values == lv.values


def test_mc_share_levels_with_every_run_refined_use_the_counts():
    c = _claim("mc", "montecarlo.wilson.diverged.lo", ">=", 0.776)
    rng = np.random.default_rng(33)
    whole = tuple(bool(x) for x in rng.random(64) < 0.95)
    lv = share_claim_levels(c, whole, whole, whole, "diverged", "montecarlo.dt", 0.005)
    k = sum(whole)
    assert lv.values == (f"{k} of 64 diverged: {lv.decides[0]}",) * 3
    assert len(set(lv.decides)) == 1 and lv.decides[0] in ("holds", "fails")


def test_the_report_text_says_what_the_mc_refinement_covers():
    text = refined_runs_text(16, 64)
    assert "all 64 runs" in text and "The other 48 runs are not run at dt / 2 and dt / 4" in text
    assert "between k and k + 48 of the 64 runs" in text and "INCONCLUSIVE" in text
    assert refined_runs_text(64, 64) == "" and refined_runs_text(16, None) == ""
    from workbench.design import load_design
    ms = load_design(DRY).spec.montecarlo
    assert (ms.halving, ms.samples) == (16, 64)     # what the dry report's text states
