"""Paper 000: brake plant, sliding-mode controllers, station-stop study."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from workbench.controllers.smarc import AdaptiveSlidingModeController, projection
from workbench.controllers.smc import SlidingGains, sliding_law, switching
from workbench.design import load_design
from workbench.errors import DesignError
from workbench.papers.p000.station_stopping_run import run_station_stops
from workbench.plants.brake000 import (BrakeParams, air_gain, brake_model, existing_model,
                                       resistance)
from workbench.sim.stopping import TargetCurve, batch_params, simulate

DESIGN = "designs/stopping-line5.toml"
TABLE1 = dict(T1=0.9, T2=0.83, P1=0.85, T3=0.8, T4=1.741, K1=1.0142, K2=0.01191,  # 000 Table 1
              k_bra=0.4, v_ho=8 / 3.6, d0=2.755, d1=0.014, d2=0.00075, g=9.8)
NO_RES = dict(TABLE1, d0=0.0, d1=0.0, d2=0.0)


def test_air_gain_at_standstill_is_table1_ratio_in_percent():
    # 000 Table 1: K1/K2 = 1.0142/0.01191 = 85.16 cm/s^2 for a full 1 m/s^2 demand
    assert air_gain(0.0, TABLE1) == pytest.approx(0.8516, abs=1e-4)
    # composite-shoe factor (V+150)/(2V+150) with V in km/h: 0.8 at 50 km/h
    assert air_gain(50 / 3.6, TABLE1) == pytest.approx(air_gain(0.0, TABLE1) * 200 / 250, rel=1e-9)


def test_davis_is_per_kilonewton_with_kmh():
    # eq 3: (d0 + d1 V + d2 V^2 + theta) g / 1000, V = 36 km/h at 10 m/s
    w0 = 2.755 + 0.014 * 36 + 0.00075 * 36**2 + 3.0
    assert resistance(10.0, 3.0, TABLE1) == pytest.approx(w0 * 9.8 / 1000, rel=1e-12)


def test_symbolic_model_depends_on_k1_k2_only_through_ratio():
    m = brake_model()
    k = sp.Symbol("k", positive=True)
    K1, K2 = m.params["K1"], m.params["K2"]
    assert sp.simplify(m.air_gain.subs({K1: k * K1, K2: k * K2}, simultaneous=True)
                       - m.air_gain) == 0


def test_existing_model_stop_distance_matches_closed_form():
    """Delay tau + lag T, constant command c, no resistance: x_stop =
    v0 tau + v0^2/(2c) + v0 T - c T^2/2 (when exp(-(t_s - tau)/T) ~ 0)."""
    ex = existing_model(BrakeParams.from_dict(NO_RES), delay=0.3, lag=0.65).as_dict()
    v0, c = 14.0, 0.8
    tr = simulate(batch_params(ex, 1), lambda t, o: np.full(1, c), n=1, t_end=40.0, dt=0.002,
                  dt_ctrl=0.1, v0=v0)
    exact = v0 * 0.3 + v0**2 / (2 * c) + v0 * 0.65 - c * 0.65**2 / 2
    assert tr.x_stop[0] == pytest.approx(exact, abs=0.03)
    assert not tr.x_stop[0] == pytest.approx(exact + 0.3 * v0, abs=0.03)   # delay counted once


def test_electric_stage_delivers_p1_of_the_command_above_hand_over():
    n = 1
    tr = simulate(batch_params(NO_RES, n), lambda t, o: np.full(n, 0.5), n=n, t_end=8.0,
                  v0=20.0, dt_rec=0.01)
    assert -tr.a[-1, 0] == pytest.approx(0.85 * 0.5, rel=1e-3)
    # nothing before the transmission delay T1 = 0.9 s
    assert np.all(tr.a[tr.t < 0.9, 0] == 0.0) and tr.a[tr.t > 1.0, 0][0] < 0


def test_fractional_delay_is_interpolated():
    p = batch_params(NO_RES, 2, {"T1": [0.9, 0.905]})
    tr = simulate(p, lambda t, o: np.full(2, 0.5), n=2, t_end=3.0, v0=20.0, dt_rec=0.01)
    assert tr.v[-1, 1] > tr.v[-1, 0]          # later brake, more speed left
    assert tr.v[-1, 1] - tr.v[-1, 0] < 0.0035  # but only by ~0.005 s of 0.425 m/s^2


def test_sliding_law_brakes_when_ahead_and_boundary_layer_saturates():
    g = SlidingGains(c=0.25, k_s=0.3, eta=0.01, phi=0.05)
    assert sliding_law(1.0, 1.0, 0.0, 0.0, g) < 0     # ahead of target -> brake force
    assert sliding_law(1.0, -1.0, 0.0, 0.0, g) > 0
    assert switching(0.01, 0.05) == pytest.approx(0.2) and switching(1.0, 0.05) == 1.0
    assert switching(0.01, 0.0) == 1.0


@pytest.mark.parametrize("theta, s, blocked", [(1.6, 1.0, True), (1.6, -1.0, False),
                                               (1.5999, 1.0, False), (0.8, -1.0, True),
                                               (0.8, 1.0, False), (0.8001, -1.0, False)])
def test_projection_eq27_on_both_sides_of_each_bound(theta, s, blocked):
    out = projection(s, np.array(theta), 0.8, 1.6)
    assert (out == 0.0) == blocked


def test_smarc_estimate_stays_in_bounds():
    ctl = AdaptiveSlidingModeController(SlidingGains(0.25, 0.3, 0.01), lam=50.0, theta_min=0.8,
                                        theta_max=1.6, theta0=np.ones(3), dt=0.1)
    for _ in range(200):
        ctl.step(np.array([5.0, -5.0, 0.0]), 0.0, -0.7)
    assert ctl.theta_hat[0] == 1.6 and ctl.theta_hat[1] == 0.8 and ctl.theta_hat[2] == 1.0


def test_target_curve_ends_at_length_with_zero_speed():
    tc = TargetCurve.build([1026.0, 300.0], v_max=22.222, a_acc=0.8, a_dec=0.7)
    x, v, a = tc.at(tc.t_final)
    assert np.allclose(x, [1026.0, 300.0]) and np.allclose(v, 0.0)
    assert tc.v_top[1] < 22.222                     # a short section cannot reach v_max


@pytest.fixture(scope="module")
def small_spec():
    spec = load_design(DESIGN).spec
    return replace(spec, sections=replace(spec.sections, count=3))


@pytest.mark.slow
def test_stop_study_is_deterministic_and_batching_invariant(small_spec):
    """The study again gives the same statistics; section 1 alone (its draws are
    the first stream) gives the stop errors it has in the batch of all sections."""
    a = run_station_stops(small_spec)
    rp = replace(small_spec.sections, sections=small_spec.sections.sections[:1])
    b = run_station_stops(replace(small_spec, sections=rp))
    for c in ("pid", "smc", "smarc", "smarc-sgn"):
        assert a.stats[c, 0].errors == pytest.approx(b.stats[c, 0].errors, abs=1e-9)
    assert run_station_stops(small_spec).stats == a.stats


def test_smarc_beats_smc_on_every_section(small_spec):
    res = run_station_stops(small_spec)
    for i in range(len(res.sections)):
        assert res.stats["smarc", i].mean_abs < res.stats["smc", i].mean_abs


@pytest.mark.parametrize("design, old, new, key", [
    (DESIGN, 'T1    = { value = 0.9,     unit = "s"', 'T1    = { value = 0.9,     unit = "ms"',
     "plant.T1.unit"),
    ("designs/closed-loop-brake-004.toml", "force_error = [-0.15, 0.0, 0.15]",
     "force_error = [-0.15, 0.0, 1.5]", "grid.force_error"),
    ("designs/brake-fit-000.toml", "step_levels = [0.0, 0.6, 0.8, 0.7]",
     "step_levels = [0.0, 0.6, 0.8]", r"logs\[0\].step_levels"),
])
def test_bad_input_is_a_design_error_naming_the_key(tmp_path, design, old, new, key):
    text = Path(design).read_text()
    assert old in text
    bad = tmp_path / Path(design).name
    bad.write_text(text.replace(old, new))
    with pytest.raises(DesignError, match=key):
        load_design(bad)


def test_within_rate_is_the_wilson_interval():
    from workbench.features.montecarlo import within_rate
    k, n, p, lo, hi = within_rate([40.0] * 10, 30.0)          # none within: 0 / 10
    assert (k, n, p, lo) == (0, 10, 0.0, 0.0)
    assert hi == pytest.approx(1.959963984540054 ** 2 / (10 + 1.959963984540054 ** 2))
    k, n, p, lo, hi = within_rate([-10.0, 5.0, 31.0, -29.9], 30.0)
    assert (k, n, p) == (3, 4, 0.75) and 0.3 < lo < 0.75 < hi < 1.0


def test_each_run_of_a_batch_equals_the_run_alone_bit_for_bit():
    # simulate is elementwise per run: dropping stopped runs from the stepped arrays,
    # equal parameters taken as floats, the block delay line must not change a bit
    rng = np.random.default_rng(7)
    n = 6
    # T1 < T3 in every run: the delay line's row offset (from the longest delay of the
    # batch) is then the same alone and batched; it enters the weights' last bits
    over = {"T1": rng.uniform(0.2, 0.75, n), "K1": TABLE1["K1"] * rng.uniform(0.8, 1.2, n),
            "v_ho": np.where(np.arange(n) % 3 == 0, 0.0, TABLE1["v_ho"])}
    v0, theta = rng.uniform(4.0, 12.0, n), rng.uniform(-3.0, 3.0, n)
    # basic arithmetic only: numpy's SIMD sin/exp may round a batch and a lone run differently
    policy = lambda t, o: np.where(o.v > 4.0, 0.8, 0.5) + 0.02 * o.x / (10.0 + o.x + t)
    kw = dict(t_end=40.0, dt=0.02, dt_ctrl=0.1, dt_rec=0.5, c_init=0.1)
    batch = simulate(batch_params(TABLE1, n, over), policy, n=n, v0=v0, theta=theta, **kw)
    assert np.isfinite(batch.t_stop).all() and np.ptp(batch.t_stop) > 2.0   # staggered stops
    for i in range(n):
        one = simulate(batch_params(TABLE1, 1, {k: x[i:i + 1] for k, x in over.items()}),
                       policy, n=1, v0=v0[i], theta=theta[i], **kw)
        k = len(one.t)
        assert np.array_equal(batch.t[:k], one.t)
        for name in ("x", "v", "a", "c"):
            # after its stop a run's samples stay final (x = x_stop, v = a = c = 0)
            assert np.array_equal(getattr(batch, name)[:k, i], getattr(one, name)[:, 0]), name
        assert np.array_equal(batch.x_stop[i:i + 1], one.x_stop)
        assert np.array_equal(batch.t_stop[i:i + 1], one.t_stop)
