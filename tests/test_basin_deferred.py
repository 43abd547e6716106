"""The basin k2 sweep's deferred certificate (issue 36, item 4): the falsifier
settles a REFUTED verdict and a diverging fate without the box cover, and
the answers are those of the full estimate (workbench.papers.p003.antiskid_basin)."""
import numpy as np
import pytest

from workbench.outcome import Outcome
from workbench.plants.adhesion import NumericAdhesion
from workbench.roa.basin import falsified_top
from workbench.features import basin_select as SEL
from workbench.papers.p003 import antiskid_basin as AB

# as tests/test_roa_antiskid.py: 003 Tables 1-2 (dry rail), the certified gain at eps = 0.35
DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)
K = (-0.004575, 10.27)
VALS = tuple(sorted(DRY.items()))


@pytest.fixture(scope="module")
def switch():
    """The printed switch state (v_d, lambda_opt) in error coordinates."""
    lam_opt = NumericAdhesion.from_dict(DRY).lambda_opt()
    return (0.0, lam_opt - AB.cruise_loop(VALS, 70.0)[1])


@pytest.fixture(scope="module")
def deferred(switch):
    """One weight of the grid at the printed switch, K of the design: REFUTED."""
    return SEL.DeferredEstimate(*AB.cruise_loop(VALS, 70.0)[0].problem(K, 100.0, [switch]), 0)


def test_refuted_point_needs_no_cover(deferred, switch, monkeypatch):
    monkeypatch.delenv(SEL.EAGER_ENV, raising=False)
    assert deferred.outcome(switch) is Outcome.REFUTED
    assert deferred._est is None                       # the cover did not run


def test_diverging_path_above_c_top_needs_no_cover(deferred, switch):
    path = np.array([switch, (switch[0] * 2, switch[1] * 1.5)])
    assert np.all(deferred.prob.V(path) > deferred.c_top)
    assert deferred.enters(path) is False and deferred._est is None


def test_deferred_answers_are_the_full_estimate(deferred, switch):
    """The shortcut's premise and its answers, against the full estimate of
    the same problem (GainLoop.estimate's, bit for bit)."""
    out_short = deferred.outcome(switch)
    est = deferred.est                                  # the cover now runs
    _, full = AB.cruise_loop(VALS, 70.0)[0].estimate(K, 100.0, [switch], seed=0)
    assert est == full
    assert est.c_certified <= deferred.c_top <= est.c_refuted
    assert out_short is est.point_verdict(switch).outcome
    inside = np.array([[0.0, 0.0], switch])            # the equilibrium is in the certified set
    assert deferred.enters(inside) is bool(est.c_certified > 0)


def test_first_stage_settles_the_refuted_switch(switch, monkeypatch):
    """The printed switch is REFUTED on the falsifier's samples alone: its
    optimiser (SLSQP) and the cover never run, and the answers equal the full
    ones (issue 36, item 4)."""
    from workbench.roa import falsify as F
    monkeypatch.delenv(SEL.EAGER_ENV, raising=False)
    ran = []
    monkeypatch.setattr(F, "minimize", lambda *a, **k: ran.append(1) or pytest.fail("SLSQP"))
    d = SEL.DeferredEstimate(*AB.cruise_loop(VALS, 70.0)[0].problem(K, 100.0, [switch]), 0)
    path = np.array([switch, (switch[0] * 2, switch[1] * 1.5)])
    assert d.outcome(switch) is Outcome.REFUTED and d.enters(path) is False
    assert d._stage._done is None and d._est is None and not ran
    monkeypatch.undo()
    fal = d.fal                                          # the optimiser now runs
    assert fal.c_refuted <= d._stage.c_upper < np.inf
    assert fal == falsified_top(d.prob, d._c, seed=0)[0]


def test_staged_falsification_is_falsify():
    """Both stages give falsify's result bit for bit, and the first stage's
    bound holds, on the textbook problems of tests/test_roa.py and a problem
    without any hit."""
    import sympy as sp
    from workbench.roa import BasinProblem
    from workbench.roa.falsify import StagedFalsification, falsify
    x, y = sp.symbols("x y", real=True)
    probs = [BasinProblem([-x + x**3, -y], (x, y), (0.0, 0.0), np.eye(2)),
             BasinProblem([-y, x - (1 - x**2) * y], (x, y), (0.0, 0.0), np.eye(2)),
             BasinProblem([-x, -y], (x, y), (0.0, 0.0), np.eye(2))]
    for prob, c in zip(probs, (4.0, 9.0, 1.0)):
        for seed in (0, 3):
            st = StagedFalsification(prob, c, seed=seed)
            upper = st.c_upper
            full = falsify(prob, c, seed=seed)
            assert st.finish() == full and st.finish() is st.finish()
            assert full.c_refuted <= upper and st.c_upper == full.c_refuted
    assert falsify(probs[2], 1.0).c_refuted == np.inf


def test_falsified_top_is_the_estimates_falsifier(deferred):
    fal, c_top = falsified_top(deferred.prob, deferred._c, seed=0)
    assert fal == deferred.fal and c_top == min(deferred._c, fal.c_refuted)
    with pytest.raises(ValueError):
        falsified_top(deferred.prob, 0.0)


@pytest.mark.slow
@pytest.mark.parametrize("k2", [3.75, 10.0])
def test_switch_verdict_equals_the_eager_path(switch, k2, monkeypatch):
    """Every certificate computed (the path before issue 36) gives the same
    verdict, weight and fate as the deferred one (> 20 s: slow tier)."""
    loop = AB.cruise_loop(VALS, 70.0)[0]
    fast = loop.judge((K[0], k2), switch, AB.T_JUDGE)
    monkeypatch.setenv(SEL.EAGER_ENV, "1")
    assert loop.judge((K[0], k2), switch, AB.T_JUDGE) == fast


def test_k2_sweep_is_shared_through_the_run_folder(tmp_path, monkeypatch):
    """Designs that differ only in the plant's mass share the controller's
    nominal model and so the k2 sweep: a second process of the same run reads
    it from the run folder (here: the same key, the in-process results emptied)."""
    from workbench import memo
    from workbench.features import basin_loop
    from workbench.features.basin_points import GainSweep
    calls = []

    def fake(judge, point, K, index, grid, **kw):
        calls.append((point, K, grid, kw))
        return GainSweep(point, K, index, (), (), None, min(grid), False)

    monkeypatch.setenv(memo.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(basin_loop, "sweep_gain_entry", fake)
    monkeypatch.setattr(memo, "_RESULTS", {})
    args = dict(grid=[0.0, 2.0], compare=[("row", (K[0], 10.5))], bisect=2, seed=0)
    a = AB.safe_k2_range(DRY, 70.0, K[0], (70.0, 0.1), **args)
    monkeypatch.setattr(memo, "_RESULTS", {})
    b = AB.safe_k2_range(dict(reversed(list(DRY.items()))), 70, K[0], (70.0, 0.1), **args)
    assert a == b and len(calls) == 1 and len(list(tmp_path.glob("*.pickle"))) == 1
    AB.safe_k2_range(DRY, 70.0, K[0], (70.0, 0.1), **dict(args, seed=1))
    assert len(calls) == 2                               # another key: computed


def test_score_bound_bounds_the_score(deferred, switch):
    """The coarse pass of cruise_basin skips a P's box cover when this bound
    cannot beat the best score: it must bound the score the cover gives."""
    est = deferred.est
    for pts in ([switch], [switch, (0.0, 0.0), (-1.0, 0.001)], []):
        assert SEL.score(est, pts) <= SEL.score_bound(deferred.prob, deferred.c_top, pts)
    # c_certified = c_top: the bound is the score itself (it is not loose)
    from dataclasses import replace
    top = replace(est, c_certified=deferred.c_top)
    assert SEL.score(top, [switch]) == SEL.score_bound(deferred.prob, deferred.c_top, [switch])


@pytest.mark.slow
def test_cruise_basin_coarse_pass_equals_every_cover(monkeypatch):
    """cruise_basin with the coarse pass (covers skipped) chooses the same P
    and gives the same estimate, verdicts and trajectories as with every
    weight's cover computed (the path before issue 36), and skips some."""
    lam_opt = NumericAdhesion.from_dict(DRY).lambda_opt()
    pts = [("printed", (70.0, lam_opt)), ("near", (69.5, AB.cruise_loop(VALS, 70.0)[1] + 0.002))]
    calls = []
    orig = SEL.estimate_basin
    monkeypatch.setattr(SEL, "estimate_basin", lambda *a, **k: calls.append(1) or orig(*a, **k))
    monkeypatch.delenv(SEL.EAGER_ENV, raising=False)
    fast = AB.cruise_basin(DRY, 70.0, K, pts, n_traj=2)
    n_fast = len(calls)
    monkeypatch.setenv(SEL.EAGER_ENV, "1")
    eager = AB.cruise_basin(DRY, 70.0, K, pts, n_traj=2)
    assert n_fast < len(calls) - n_fast == len(AB.W_GRID)
    assert (fast.w, fast.check, fast.K, fast.lambda_d) == (eager.w, eager.check, eager.K,
                                                           eager.lambda_d)
    for a, b in zip(fast.trajectories, eager.trajectories, strict=True):
        assert (a.x0, a.fate) == (b.x0, b.fate) and np.array_equal(a.path, b.path)
