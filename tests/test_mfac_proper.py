"""Paper 002, issue 20 item 2: the published CFDL-MFAC (reset rule as written),
the two plant readings, Pareto fronts and the multi-objective study's determinism."""
import dataclasses
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from workbench.controllers.mfac import (MFAC, MFACGains, frozen_loop_poles, frozen_ppd_poles,
                                        ppd_update, reset_conditions)
from workbench.controllers.pid import PID, BatchPID
from workbench.plants.train002 import FirstOrderTrain002, Train002, dc_gain, speed_time_constant
from workbench.sim.tracking import Route, simulate_tracking
from workbench.tuning.pareto import choose, dominated_share, pareto_mask, weighted_cost

DESIGN = Path("designs/ato-mfac-pid-002.toml")
EPS = 1e-5


# -- the reset rule of eq 9, condition by condition, on hand-made sequences ------------
def _two_samples(g, y0, y1, target=1.0):
    """MFAC fed y(1) = y0, then y(2) = y1; returns the controller after the second
    sample (the first estimate is formed there, from du(1) and dy(2))."""
    c = MFAC(g, 1)
    c.step(np.array([y0]), np.array([target]))
    c.step(np.array([y1]), np.array([target]))
    return c


def test_no_reset_when_no_condition_holds():
    g = MFACGains(lam=1.0, rho=0.5, eta=1.0, mu=0.2, phi1=0.5, epsilon=EPS)
    c = _two_samples(g, 0.0, 0.3)            # du(1) = 0.2, output moves with the input
    assert c.resets[0] == 0 and c.phi[0] != 0.5
    assert not any(c.history[k][0][0] for k in ("small_phi", "small_du", "sign_change"))


def test_reset_small_phi():
    """dy = 0 after a move with mu tiny drives the estimate to ~ phi mu / (mu + du^2) <= eps."""
    g = MFACGains(lam=1.0, rho=0.5, eta=1.0, mu=1e-9, phi1=0.5, epsilon=EPS)
    c = _two_samples(g, 0.0, 0.0)
    fresh = ppd_update(0.5, 0.2, 0.0, 1.0, 1e-9)          # du(1) = 0.5 * 0.5 * 1 / (1 + .25)
    assert 0 < fresh <= EPS
    assert c.history["small_phi"][0][0] and not c.history["sign_change"][0][0]
    assert c.phi[0] == 0.5 and c.resets[0] == 1


def test_reset_small_du_on_both_sides_of_epsilon():
    """|du(k-1)| <= eps resets, a move just above eps does not (the target equals the
    output, so the first command is 0 + rho phi (y* - y) / (lam + phi^2) = the offset)."""
    def run(du):
        phi1, lam, rho = 0.5, 1.0, 1.0
        g = MFACGains(lam=lam, rho=rho, eta=1.0, mu=1.0, phi1=phi1, epsilon=EPS)
        target = du * (lam + phi1 ** 2) / (rho * phi1)     # makes u(1) = du exactly
        return _two_samples(g, 0.0, 0.0, target=target)
    below = run(0.999 * EPS)
    assert below.history["small_du"][0][0] and below.resets[0] == 1
    above = run(1.001 * EPS)
    assert not above.history["small_du"][0][0] and above.resets[0] == 0


def test_reset_small_du_when_the_command_is_held_at_its_limit():
    """A command clipped at u_max twice in a row has du = 0: reset, whatever the output."""
    g = MFACGains(lam=1e-4, rho=1.0, eta=1.0, mu=1.0, phi1=0.02, epsilon=EPS)
    c = MFAC(g, 1, u_min=-1.0, u_max=1.0)
    for y in (0.0, 0.0, 0.1):
        u = c.step(np.array([y]), np.array([5.0]))
    assert u[0] == 1.0
    # second sample: du = 1 (0 -> the limit), no reset; third: du = 0 at the limit, reset
    assert [h[0] for h in c.history["small_du"]] == [False, True] and c.resets[0] == 1


def test_reset_sign_change():
    g = MFACGains(lam=1.0, rho=0.5, eta=1.0, mu=0.2, phi1=0.5, epsilon=EPS)
    c = _two_samples(g, 0.0, -5.0)                     # output moves against the input
    assert c.history["sign_change"][0][0] and not c.history["small_du"][0][0]
    assert c.phi[0] == 0.5


def test_reset_conditions_function_matches_the_rule():
    got = reset_conditions(np.array([1e-6, 0.3, -0.3, 0.3]), np.array([0.1, 1e-6, 0.1, 0.1]),
                           0.5, EPS)
    assert got["small_phi"].tolist() == [True, False, False, False]
    assert got["small_du"].tolist() == [False, True, False, False]
    assert got["sign_change"].tolist() == [False, False, True, False]


# -- eq 9, the estimate, against a hand calculation -----------------------------------------
def test_ppd_update_hand_calculation():
    # phi = 0.5 + 0.8 * 0.2 * (0.3 - 0.5 * 0.2) / (1 + 0.2^2) = 0.5 + 0.032 / 1.04
    assert ppd_update(0.5, 0.2, 0.3, 0.8, 1.0) == pytest.approx(0.5 + 0.032 / 1.04, abs=1e-15)
    g = MFACGains(lam=1.0, rho=0.5, eta=0.8, mu=1.0, phi1=0.5, epsilon=EPS)
    c = MFAC(g, 1)
    u1 = c.step(np.array([0.0]), np.array([0.5]))[0]     # 0.5 * 0.5 * 0.5 / 1.25 = 0.1
    assert u1 == pytest.approx(0.1, abs=1e-15)
    c.step(np.array([0.07]), np.array([0.5]))
    assert c.phi[0] == pytest.approx(0.5 + 0.8 * 0.1 * (0.07 - 0.05) / 1.01, abs=1e-15)


# -- frozen-PPD loops ------------------------------------------------------------------------
def test_frozen_loop_poles_reduce_to_the_integrator_case():
    """On y(k+1) = y(k) + Ts u(k) (num = Ts, den = z - 1) the general routine gives the
    roots of z^2 - (2 - G Ts) z + 1; G Ts = 4 is the double pole at z = -1."""
    g = MFACGains(lam=1e-4, rho=1.0, eta=1.0, mu=1.0, phi1=0.02)
    G = 0.02 / (1e-4 + 0.02 ** 2)
    z = frozen_loop_poles(G, [0.1], [1.0, -1.0])
    assert np.allclose(np.sort_complex(z), np.sort_complex(frozen_ppd_poles(g, 0.02, 0.1)))
    assert np.allclose(z, -1.0, atol=1e-6)
    # a stable first-order plant y(k+1) = 0.5 y(k) + 0.5 u(k) with a small gain: inside
    assert np.max(np.abs(frozen_loop_poles(0.2, [0.5], [1.0, -0.5]))) < 1.0


def test_frozen_integrator_at_a_tuning_s_chosen_point():
    """The tracking kind's diagnosis of a chosen MFAC point (a toy tuning): G
    and the integrator roots of :func:`frozen_ppd_poles`, on the unit circle."""
    from types import SimpleNamespace

    from workbench.kinds.tracking.mfac import frozen_integrator
    p = {"eta": 1.0, "mu": 1.0, "rho": 0.5, "lam": 1e-3, "phi1": 0.02}
    G, z = frozen_integrator(SimpleNamespace(chosen_params=lambda: p), 0.1)
    assert G == pytest.approx(0.5 * 0.02 / (1e-3 + 0.02 ** 2))
    assert np.allclose(np.abs(z), 1.0) and np.prod(z) == pytest.approx(1.0)    # 0 < G Ts < 4


# -- the two readings: DC gain -------------------------------------------------------------
FO = dict(f=1.3, e=0.2, delay=0.3, lag=0.65, g=9.81, u_min=-5.0, u_max=25.0)


def _hold(train, u, horizon):
    run = simulate_tracking(train, Route(1e7), lambda t: np.zeros_like(t),
                            lambda k, y, yn: np.full(1, u), 1, Ts=0.1, dt=0.01,
                            horizon=horizon, brake_start=1e9)
    return run.v[0, -1]


def test_first_order_dc_gain_without_resistance_is_f():
    tr = FirstOrderTrain002(**FO, c0=0.0, c1=0.0, c2=0.0)
    assert dc_gain(tr, 10.0) == pytest.approx(1.3, rel=1e-12)
    assert speed_time_constant(tr, 10.0) == pytest.approx(0.65, rel=1e-12)
    # held command 8: the speed settles at f u + e (the acceleration limit only slows the rise)
    assert _hold(tr, 8.0, 40.0) == pytest.approx(1.3 * 8.0 + 0.2, abs=1e-6)


def test_first_order_dc_gain_with_resistance_matches_its_definition():
    """dv/du = f / (1 + T_l r'(v)): against the steady states of two held commands.

    The simulated steady state is the fixed point of the plant step (exact lag over a
    step, resistance held over it): (A - v)(1 - exp(-dt/T_l)) = r(v) dt, within
    O(dt / T_l) of the continuous one (A - v) / T_l = r(v)."""
    tr = FirstOrderTrain002(**FO, c0=0.01, c1=0.02, c2=0.003)
    r = lambda v: 0.01 + 0.02 * v + 0.003 * v * v
    k = -np.expm1(-0.01 / 0.65)
    v_step = lambda u: brentq(lambda v: (1.3 * u + 0.2 - v) * k - r(v) * 0.01, 0.0, 50.0,
                              xtol=1e-14)
    v_cont = lambda u: brentq(lambda v: (1.3 * u + 0.2 - v) / 0.65 - r(v), 0.0, 50.0,
                              xtol=1e-14)
    v1, v2 = _hold(tr, 10.0, 120.0), _hold(tr, 10.1, 120.0)
    assert v1 == pytest.approx(v_step(10.0), abs=1e-9) and v2 == pytest.approx(v_step(10.1),
                                                                               abs=1e-9)
    assert v1 == pytest.approx(v_cont(10.0), rel=1e-3)
    expected = 1.3 / (1 + 0.65 * (0.02 + 2 * 0.003 * v1))
    assert dc_gain(tr, v1) == pytest.approx(expected, rel=1e-12)
    assert (v2 - v1) / 0.1 == pytest.approx(expected, rel=1e-2)        # finite difference
    assert np.isfinite(dc_gain(tr, v1)) and dc_gain(tr, v1) < 1.3


def test_integrating_reading_gain_is_the_resistance_slope():
    tr = Train002(f=1.0, e=0.0, delay=0.3, lag=0.65, c0=0.01176, c1=0.00077616, c2=1.6e-5,
                  g=9.81)
    slope = 0.00077616 + 2 * 1.6e-5 * 18.0
    assert dc_gain(tr, 18.0) == pytest.approx(1.0 / slope, rel=1e-12)
    assert speed_time_constant(tr, 18.0) == pytest.approx(1.0 / slope, rel=1e-12)
    assert speed_time_constant(tr, 18.0) > 114.9        # slower than paper 002's planned run


# -- Pareto fronts -------------------------------------------------------------------------
TOY = np.array([[1.0, 5.0], [2.0, 2.0], [5.0, 1.0], [3.0, 3.0], [2.0, 2.0], [np.nan, 0.0],
                [6.0, 6.0], [2.0, 4.0]])


def test_pareto_mask_on_a_toy_set():
    # [3,3], [6,6] and [2,4] are dominated by [2,2]; the nan row is never on the front;
    # the duplicate [2,2] rows do not dominate each other
    assert pareto_mask(TOY).tolist() == [True, True, True, False, True, False, False, False]
    # brute force: a row is on the front iff no finite row dominates it
    fin = np.all(np.isfinite(TOY), axis=1)
    brute = [bool(fin[i]) and not any(np.all(TOY[j] <= TOY[i]) and np.any(TOY[j] < TOY[i])
                                      for j in range(len(TOY)) if fin[j])
             for i in range(len(TOY))]
    assert pareto_mask(TOY).tolist() == brute


def test_weighted_choice_lies_on_the_front_and_respects_admissibility():
    cost = weighted_cost(TOY, [1.0, 1.0], [1.0, 1.0])
    assert np.isinf(cost[5])
    i = choose(TOY, [1.0, 1.0], [1.0, 1.0])
    assert i == 1 and pareto_mask(TOY)[i]
    assert choose(TOY, [1.0, 1.0], [0.0, 1.0]) == 2             # only the second objective
    adm = TOY[:, 0] <= 1.0
    assert choose(TOY, [1.0, 1.0], [1.0, 1.0], adm) == 0         # only row 0 admissible
    assert choose(TOY, [1.0, 1.0], [1.0, 1.0], np.zeros(len(TOY), bool)) == 1
    with pytest.raises(ValueError):
        choose(np.full((2, 2), np.nan), [1.0, 1.0], [1.0, 1.0])


def test_dominated_share():
    a, b = np.array([[1.0, 1.0]]), np.array([[2.0, 2.0], [0.5, 3.0], [1.0, 1.0]])
    assert dominated_share(a, b) == pytest.approx(1 / 3)
    assert dominated_share(b, a) == 0.0 and dominated_share(a, np.zeros((0, 2))) == 0.0


# -- batched PID and determinism --------------------------------------------------------------
def test_batch_pid_equals_the_scalar_pid():
    gains = [(2.0, 1.0, 0.3), (0.5, 0.0, 0.0), (4.0, 3.0, 1.0)]
    scal = [PID(*k, dt=0.1, u_min=-1.0, u_max=1.0) for k in gains]
    batch = BatchPID(*np.array(gains).T, 3, dt=0.1, u_min=-1.0, u_max=1.0)
    rng = np.random.default_rng(np.random.SeedSequence(20))
    for e in rng.normal(0.0, 2.0, (200, 3)):
        assert np.array_equal(batch.step(e), [p.step(x) for p, x in zip(scal, e)])


@pytest.fixture(scope="module")
def small_reading():
    from workbench.design import load_design
    spec = load_design(DESIGN).spec
    grids = {"mfac_grid": {"eta": (0.1,), "mu": (0.01,), "rho": (0.5, 1.0), "lam": (3.0, 10.0),
                           "phi1": (0.2,)},
             "pid_grid": {"kp": (2.0,), "ki": (3.0,), "kd": (0.0, 0.3)}}
    reading = dataclasses.replace(spec.readings[1], **grids)
    return dataclasses.replace(spec, readings=(reading,), line=())


@pytest.mark.slow
def test_study_is_deterministic(small_reading):
    from workbench.kinds.tracking.run import run_study, study_quantities
    a, b = run_study(small_reading), run_study(small_reading)
    ra, rb = a.readings[0], b.readings[0]
    for x, y in ((ra.mfac.objectives, rb.mfac.objectives), (ra.pid.objectives, rb.pid.objectives),
                 (ra.mfac.reset_rate, rb.mfac.reset_rate), (ra.ppd.phi, rb.ppd.phi)):
        assert np.array_equal(x, y, equal_nan=True)
    assert study_quantities(a) == study_quantities(b)
    assert ra.mfac.front[ra.mfac.chosen]


def test_a_grid_where_nothing_stops_is_a_model_error(small_reading):
    from workbench.errors import ModelError
    from workbench.kinds.tracking.run import run_study
    r = small_reading.readings[0]
    # a command pinned at a demanded speed of 2 cm/s: the train creeps and never stands still
    creep = dataclasses.replace(r.train, u_min=0.02, u_max=0.02)
    bad = dataclasses.replace(r, train=creep)
    with pytest.raises(ModelError, match="no reproducible run of the MFAC grid"):
        run_study(dataclasses.replace(small_reading, readings=(bad,)))
