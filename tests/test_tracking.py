"""Paper 002: target profiles, the delay+lag train, CFDL-MFAC, indices, the study."""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from workbench.controllers.mfac import MFAC, MFACGains, frozen_ppd_poles
from workbench.design import load_design
from workbench.errors import DesignError, ModelError
from workbench.plants.train002 import Train002, davis
from workbench.profiles import ProfileSpec, build_profile, cruise_speed, run_time
from workbench.sim.tracking import Route, TrackingRun, objectives, simulate_tracking

DESIGN = Path("designs/ato-mfac-pid-002.toml")
# paper 002 §4: Macun - Nanhu 1657.8 m, 114.9 s planned, 80 km/h
MACUN = ProfileSpec(1657.8, 80 / 3.6, 0.8, 0.8, 0.75, 114.9)


# -- profiles -----------------------------------------------------------------------
def test_profile_meets_distance_time_and_limits():
    p = build_profile(MACUN, dt=0.01)
    assert p.t[-1] == pytest.approx(114.9, abs=1e-12)
    assert p.s[-1] == pytest.approx(1657.8, abs=1e-6)
    assert p.v[-1] == 0.0 and p.v.max() <= MACUN.v_limit
    assert p.a.max() <= MACUN.accel + 1e-12 and -p.a.min() <= MACUN.brake + 1e-12
    jerk = np.abs(np.diff(p.a) / np.diff(p.t))
    assert jerk.max() <= MACUN.jerk * (1 + 1e-9)
    assert run_time(MACUN, p.v_cruise) == pytest.approx(114.9, rel=1e-10)


def test_profile_phase_distance_closed_form():
    # a phase covers v T / 2: check against the sampled integral, both jerk regimes
    for v in (0.3, 18.0):   # 0.3 < a^2/j = 0.853: the peak acceleration is not reached
        S = 100.0 * v
        spec = ProfileSpec(S, v, 0.8, 0.8, 0.75, 0.0)
        spec = ProfileSpec(S, v * 1.5, 0.8, 0.8, 0.75, run_time(spec, v))
        p = build_profile(spec, dt=1e-3)
        assert p.v_cruise == pytest.approx(v, rel=1e-9)
        assert p.s[-1] == pytest.approx(S, rel=1e-9)


def test_infeasible_run_time_is_a_clear_error():
    with pytest.raises(ModelError, match="shorter than the fastest"):
        cruise_speed(ProfileSpec(1657.8, 80 / 3.6, 0.8, 0.8, 0.75, 60.0))


# -- train ----------------------------------------------------------------------------
def test_delay_lag_step_response_is_exact():
    """Constant command on a level, resistance-free train: after the delay d the
    speed is A (t - d - T (1 - exp(-(t - d)/T))) (integral of a first-order lag)."""
    tr = Train002(f=0.8, e=0.05, delay=0.3, lag=0.65, c0=0.0, c1=0.0, c2=0.0, g=9.81)
    run = simulate_tracking(tr, Route(1e6), lambda t: np.zeros_like(t),
                            lambda k, y, yn: np.full(1, 0.5), 1, Ts=0.1, dt=0.01,
                            horizon=10.0, brake_start=1e9)
    A = 0.8 * 0.5 + 0.05
    tau = np.clip(run.t - 0.3, 0.0, None)
    expected = A * (tau - 0.65 * (1 - np.exp(-tau / 0.65)))
    assert np.max(np.abs(run.v[0] - expected)) < 1e-12
    assert np.all(run.v[0][run.t <= 0.3] == 0.0)       # nothing before the delay


def test_davis_matches_formula_and_train_holds_at_rest():
    assert davis(10.0, 0.01, 0.001, 1e-5) == pytest.approx(0.01 + 0.01 + 1e-3)
    tr = Train002(1.0, 0.0, 0.3, 0.65, 0.0118, 7.8e-4, 1.6e-5, 9.81)
    run = simulate_tracking(tr, Route(1e6), lambda t: np.zeros_like(t),
                            lambda k, y, yn: np.full(1, -1.0), 1, Ts=0.1, dt=0.01,
                            horizon=5.0, brake_start=1e9)
    assert np.all(run.v == 0.0) and np.all(run.s == 0.0)   # braking at rest: no reversing


# -- MFAC -------------------------------------------------------------------------------
def test_mfac_control_law_minimises_eq6_criterion():
    """With rho = 1 the increment of eq 7 minimises eq 6, |y* - y - phi du|^2 + lambda du^2."""
    g = MFACGains(lam=0.3, rho=1.0, eta=0.5, mu=1.0, phi1=0.7)
    c = MFAC(g, 1)
    u = c.step(np.array([1.0]), np.array([2.5]))[0]
    J = lambda du: (2.5 - 1.0 - 0.7 * du) ** 2 + 0.3 * du ** 2
    assert u == pytest.approx(minimize_scalar(J).x, rel=1e-6)


def test_mfac_ppd_update_minimises_eq8_criterion_and_resets():
    g = MFACGains(lam=1.0, rho=0.5, eta=1.0, mu=0.2, phi1=0.5)
    c = MFAC(g, 1)
    c.step(np.array([0.0]), np.array([1.0]))
    du, phi0 = c.du_prev[0], c.phi[0]
    c.step(np.array([0.3]), np.array([1.0]))
    J = lambda p: (0.3 - p * du) ** 2 + 0.2 * (p - phi0) ** 2
    assert c.phi[0] == pytest.approx(minimize_scalar(J).x, rel=1e-6)
    # an output moving against the input flips the estimate's sign -> reset to phi(1)
    c2 = MFAC(g, 1)
    c2.step(np.array([0.0]), np.array([1.0]))
    c2.step(np.array([-5.0]), np.array([1.0]))
    assert c2.phi[0] == 0.5 and c2.resets[0] == 1


def test_frozen_ppd_loop_is_undamped_then_unstable():
    g = MFACGains(lam=0.001, rho=1.0, eta=0.5, mu=1.0, phi1=0.02)
    z = frozen_ppd_poles(g, 0.02, 0.1)            # G Ts = 1.43 < 4
    assert np.allclose(np.abs(z), 1.0, atol=1e-12)
    z = frozen_ppd_poles(g, 0.02, 0.3)            # G Ts = 4.3 > 4: a real pole < -1
    assert np.max(np.abs(z)) > 1.0


# -- indices -----------------------------------------------------------------------------
def test_objectives_on_a_known_history():
    t = np.arange(5) * 1.0
    a = np.array([[0.0, 1.0, 0.0, -1.0, 0.0]])
    run = TrackingRun(t, np.ones((1, 5)), np.zeros((1, 5)), a, np.zeros((1, 5)),
                      np.ones((1, 5)) * 1.5, np.array([4.5]), np.array([99.0]),
                      np.array([20.0]))
    q = objectives(run, distance=100.0, run_time=5.0)
    assert q.stop_error[0] == pytest.approx(1.0)
    assert q.punctuality[0] == pytest.approx(0.5)                 # |4.5 - 5| s
    assert q.comfort[0] == pytest.approx(1.0)                     # jerks +-1 m/s^3, RMS 1
    assert q.energy[0] == pytest.approx(20.0)                     # J/kg, not per metre
    assert q.rms_speed_error[0] == pytest.approx(0.5)
    assert q.matrix().shape == (1, 4)
    assert q.peak_jerk[0] == pytest.approx(1.0)                   # 1 s windows = one step here
    # at Ts = 0.5 s a 1 s window spans two steps: (1 - 0) / 1 s, not the step jerk 2 m/s^3
    run2 = TrackingRun(t / 2, np.ones((1, 5)), np.zeros((1, 5)),
                       np.array([[0.0, 0.0, 1.0, 1.0, 1.0]]), np.zeros((1, 5)),
                       np.ones((1, 5)), np.array([2.5]), np.array([100.0]), np.array([0.0]))
    assert objectives(run2, 100.0, 2.5).peak_jerk[0] == pytest.approx(1.0)
    # a stop on the planned time is exactly 0 late, not its last-bit rounding
    # (Pareto ties at 0 must not depend on it)
    assert objectives(run2, 100.0, math.nextafter(2.5, 3.0)).punctuality[0] == 0.0


def test_grid_edges_name_parameters_at_either_end():
    from workbench.tuning.pareto import grid_edges
    P = np.array([[a, b, 5.0] for a in (1.0, 2.0, 3.0) for b in (0.1, 0.2)])
    assert grid_edges(P, 2, ("a", "b", "c")) == ("b",)       # a = 2 inside; c not searched
    assert grid_edges(P, 5, ("a", "b", "c")) == ("a", "b")


# -- design ---------------------------------------------------------------------------------
def _bad(tmp_path, old, new):
    text = DESIGN.read_text()
    assert old in text
    p = tmp_path / DESIGN.name
    p.write_text(text.replace(old, new, 1))
    return p


@pytest.mark.parametrize("old, new, key", [
    ('Ts = { value = 0.1,', 'Ts = { value = 0.105,', "simulation.Ts"),
    ("rho = [0.2, 0.5, 1.0]", "rho = [0.2, 0.5, 1.5]", "plant_readings[0].mfac.rho"),
    ('name = "first-order"', 'name = "integrating"', "plant_readings"),
    ("weights = [1.0, 1.0, 0.0, 1.0]", "weights = [1.0, 1.0, 1.0]", "tuning.weights"),
    ('peak_jerk = { value = 0.75, unit = "m/s^3"', 'peak_jerk = { value = 0.75, unit = "m/s^2"',
     "tuning.peak_jerk.unit"),
    ('run_time = { value = 114.9, unit = "s", source = "paper 002 §4 (planned)" }',
     'run_time = { value = 60.0, unit = "s", source = "x" }', "route.run_time"),
    ('delay = { value = 0.3, unit = "s"', 'delay = { value = 0.3, unit = "ms"', "train.delay.unit"),
])
def test_bad_designs_name_the_key(tmp_path, old, new, key):
    with pytest.raises(DesignError) as exc:
        load_design(_bad(tmp_path, old, new))
    assert exc.value.key == key


@pytest.fixture(scope="module")
def evaluation():
    from workbench.verify import evaluate_design
    return evaluate_design(load_design(DESIGN))


@pytest.mark.slow     # the design is run at dt, dt/2 and dt/4 (refinement of the findings)
def test_study_runs_and_claims_are_ok(evaluation):
    from workbench.kinds.tracking.run import study_quantities
    assert evaluation.ok
    res = evaluation.result
    q = study_quantities(res)
    assert [r.reading.name for r in res.readings] == ["integrating", "first-order"]
    for r in res.readings:
        # both chosen controllers stop on the main pair; each chosen point is on its front
        # or is held off it by the peak-jerk constraint, which it then meets
        assert all(np.isfinite(r.main.value(k, "stop_error")) for k in ("MFAC", "PID"))
        lim = evaluation.design.spec.peak_jerk.value
        for c, tun in (("MFAC", r.mfac), ("PID", r.pid)):
            assert tun.front[tun.chosen] or r.main.value(c, "peak_jerk") <= lim
            # only reproducible runs (+-3 ulp on the train) are chosen or on a front
            assert tun.reproducible[tun.chosen] and not (tun.front & ~tun.reproducible).any()
        # the grid row of the chosen point and its re-run agree (same batch arithmetic)
        row = r.mfac.objectives[r.mfac.chosen]
        assert row[0] == pytest.approx(r.main.value("MFAC", "stop_error"), rel=1e-9)
        assert r.mfac.reset_rate[r.mfac.chosen] == pytest.approx(r.ppd.reset_rate, rel=1e-12)
    # every finding's metric went through the three-level refinement, and converged
    rows = evaluation.refinement.rows
    assert {x.claim_id for x in rows} == {r.claim.id for r in evaluation.claims
                                          if r.claim.is_finding and r.got is not None}
    assert all(x.converged for x in rows)
    assert math.isclose(q["profile.v_cruise"], res.profile.v_cruise)
    assert res.to_json()["readings"][1]["name"] == "first-order"


def test_most_sensitive_ignores_parameters_without_a_reproducible_neighbour():
    from workbench.kinds.tracking.run import most_sensitive
    assert most_sensitive({"eta": 0.01, "rho": math.nan, "lam": 0.09}) == "lam"
    assert most_sensitive({"eta": 0.2, "rho": math.nan, "lam": 0.09}) == "eta"


def test_dominance_ties_within_the_relative_band_are_equal():
    """Two runs whose objectives differ only in the last bits dominate neither
    way (the front and the dominated share must not rest on them); a real
    improvement beyond the band still dominates."""
    from workbench.tuning.pareto import TIE_REL, dominated_share, dominates, pareto_mask
    a = np.array([0.25, 0.0, 1.0, 3.0])
    b = np.nextafter(a, np.inf)          # one ulp worse in every objective
    b[1] = 0.0                           # (rounding-level punctuality is exactly 0 upstream)
    assert not dominates(a, b) and not dominates(b, a)
    assert pareto_mask(np.vstack([a, b])).tolist() == [True, True]
    assert dominated_share([a], [b]) == 0.0
    c = a.copy()
    c[0] *= 1 + 10 * TIE_REL             # worse beyond the band
    assert dominates(a, c) and not dominates(c, a)
    assert pareto_mask(np.vstack([a, c])).tolist() == [True, False]
