"""Issue 20, fair stopping baselines (papers 000 and 004): design keys, seeded
Monte Carlo draws, the damped PID, known-delay compensation, the retuned
004 loop and its sensor faults."""
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.controllers.stop_predictor import NominalBrakeModel
from workbench.design import load_design
from workbench.features.montecarlo import (Distribution, MonteCarloSpec, draw, percentile,
                                           stop_statistics, within_rate)
from workbench.papers.p000.station_stopping_run import loop_dead_time, run_station_stops
from workbench.papers.p000.station_stopping_spec import gains
from workbench.sim.stopping import batch_params, simulate
from workbench.tuning.pid import damping, speed_loop, tune_pid

D000 = "designs/stopping-line5.toml"
D004 = "designs/closed-loop-brake-004.toml"


# -- design keys: one line naming file, key, value, expected; exit 2 --------------------
@pytest.mark.parametrize("design, old, new, key", [
    (D000, 'delay      = { dist = "lognormal"', 'delay      = { dist = "gamma"',
     "montecarlo.distributions.delay.dist"),
    (D000, 'mass_ratio = { dist = "normal", mean = 1.0, sd = 0.033, lo = 0.9, hi = 1.1',
     'mass_ratio = { dist = "normal", mean = 1.0, sd = 0.033, hi = 1.1',
     "montecarlo.distributions.mass_ratio.lo"),
    (D000, "samples = 200", "samples = 1", "montecarlo.samples"),
    (D000, "[montecarlo.distributions]\n", "[montecarlo.distributions]\nwind = { dist = \"uniform\", lo = 0.0, hi = 1.0, source = \"x\" }\n",
     "montecarlo.distributions.wind"),
    (D000, "d_terminal = { value = 40.0", "d_terminal = { value = -40.0",
     "compensation.d_terminal"),
    (D000, "gain_bounds = [0.5, 1.5]", "gain_bounds = [1.2, 1.5]", "compensation.gain_bounds"),
    (D000, "zeta_min = { value = 0.7", "zeta_min = { value = 1.5", "constants.zeta_min"),
    (D000, 'tolerance = { value = 0.3, unit = "m"', 'tolerance = { value = 0.3, unit = "cm"',
     "target.tolerance.unit"),
    (D004, "high       = { value = 1.1", "high       = { value = 0.9",
     "deceleration_loop.high_ratio"),
    (D004, "t_predict_sweep = [0.0,", "t_predict_sweep = [-1.0,", "retuning.t_predict_sweep"),
    (D004, 'force_error = { dist = "normal", mean = 0.0, sd = 0.05, lo = -0.15, hi = 0.15',
     'force_error = { dist = "normal", mean = 0.0, sd = 0.05, lo = 0.15, hi = 0.15',
     "montecarlo.distributions.force_error.lo"),
])
def test_bad_new_key_is_one_line_exit_2(tmp_path, capsys, design, old, new, key):
    text = Path(design).read_text()
    assert old in text
    bad = tmp_path / Path(design).name
    bad.write_text(text.replace(old, new, 1))
    assert main(["verify", str(bad)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(bad) in err and key in err and "expected" in err


# -- Monte Carlo draws and statistics -------------------------------------------------------
def test_draws_are_seeded_and_per_factor():
    spec = load_design(D000).spec
    mc = spec.montecarlo
    order = tuple(f.name for f in spec.factors)
    NOMINAL = {f.name: f.nominal for f in spec.factors}
    a, b = draw(mc, order, NOMINAL), draw(mc, order, NOMINAL)
    assert all(np.array_equal(a[k], b[k]) for k in order)            # same seed, same draws
    other = draw(replace(mc, seed=mc.seed + 1), order, NOMINAL)
    assert not np.array_equal(a["delay"], other["delay"])
    only = draw(replace(mc, distributions={"delay": mc.distributions["delay"]}), order, NOMINAL)
    assert np.array_equal(only["delay"], a["delay"])              # independent of the others
    assert np.all(only["gradient"] == 0.0) and np.all(only["mass_ratio"] == 1.0)


def test_distributions_inverse_cdf():
    u = np.array([1e-9, 0.5, 1 - 1e-9])
    tn = Distribution("normal", 1.0, 0.05, 0.85, 1.15, "")
    x = tn.ppf(u)
    assert x[1] == pytest.approx(1.0) and 0.85 <= x[0] < 0.851 and 1.149 < x[2] <= 1.15
    assert Distribution("lognormal", 2.0, 0.1, 0.0, np.inf, "").ppf(0.5) == pytest.approx(2.0)
    assert Distribution("uniform", -3.0, 3.0, -3.0, 3.0, "").ppf(0.25) == pytest.approx(-1.5)


def test_stop_statistics_reuse_wilson_and_count_no_stop_as_outside():
    st = stop_statistics([0.1, -0.2, 0.5, np.nan], 0.3)
    assert (st.k, st.n) == (2, 4) and (st.lo, st.hi) == within_rate([0.1, -0.2, 0.5, np.inf],
                                                                    0.3)[3:]
    assert st.p95 == np.inf and st.overshoot == 0.75 and np.isnan(st.mean)   # no stop: beyond
    e = np.linspace(-1.0, 2.0, 41)
    assert stop_statistics(e, 0.3).p95 == pytest.approx(np.percentile(np.abs(e), 95))
    assert percentile([1.0, 2.0, np.inf], 50) == 2.0


# -- PID: no oscillation -------------------------------------------------------------------
@pytest.fixture(scope="module")
def spec000():
    return load_design(D000).spec


def test_damped_pid_meets_the_criterion_and_paper_gains_do_not(spec000):
    p = {k: q.value for k, q in spec000.params.items()}
    h = p["T1"] + spec000.dt_ctrl / 2
    loop = lambda g: damping(*speed_loop(**g, P1=p["P1"], T2=p["T2"]), h)
    assert loop(gains(spec000, "pid-damped")).zeta >= spec000.paper.zeta_min
    ringing = loop(gains(spec000, "pid"))
    assert ringing.zeta < 0.1 and 7.0 < ringing.period < 10.0      # the 8-9 s ringing


@pytest.mark.parametrize("variant", ["pid-damped", "pid-comp"])
def test_tuner_reproduces_the_design_gains(spec000, variant):
    """tune_pid as the design file states it (default grid, kd = 0), on the loop
    each PID runs in (with the dead time, or behind the predictor), gives the
    design's gains to their 2 printed digits, and the rounded gains still meet
    the criterion; deterministic."""
    p = {k: q.value for k, q in spec000.params.items()}
    loop = lambda a, b: speed_loop(a, b, 0.0, P1=p["P1"], T2=p["T2"])
    h = loop_dead_time(spec000, variant)
    kp, ki, _ = tune_pid(loop, h, zeta_min=spec000.paper.zeta_min)
    g = gains(spec000, variant)
    assert (float(f"{kp:.2g}"), float(f"{ki:.2g}"), g["kd"]) == (g["kp"], g["ki"], 0.0)
    assert damping(*loop(g["kp"], g["ki"]), h).zeta >= spec000.paper.zeta_min


# -- the controller's brake model ------------------------------------------------------------
def test_model_predicts_the_held_command_stop(spec000):
    base = {k: q.value for k, q in spec000.params.items()}
    for c in (0.5, 0.8):
        tr = simulate(batch_params(base, 1), lambda t, o: np.full(1, c), n=1, t_end=80.0,
                      v0=22.0, dt_ctrl=spec000.dt_ctrl)
        m = NominalBrakeModel(base, 1, dt_ctrl=spec000.dt_ctrl, gain_tau=0.0)
        m.update(np.array([22.0]), np.zeros(1))
        xs = m.stop_positions(np.zeros(1), np.array([22.0]), np.array([[c]]), np.arange(1),
                              t_max=80.0)
        assert xs[0, 0] == pytest.approx(tr.x_stop[0], abs=0.1)      # 0.1 s model step


# -- compensation: nominal row, bias, determinism ---------------------------------------------
@pytest.fixture(scope="module")
def small(spec000):
    rp = replace(spec000.sections, count=2, sections=spec000.sections.sections[:1])
    spec = replace(spec000, sections=rp, montecarlo=replace(spec000.montecarlo, samples=24))
    return spec, run_station_stops(spec)


def test_compensation_removes_the_overshoot_bias(small):
    _, res = small
    for plain, comp in (("pid-damped", "pid-comp"), ("smc", "smc-comp"),
                        ("smarc", "smarc-comp")):
        assert res.nominal[plain].error > 0.1 and abs(res.nominal[comp].error) < 0.01
        assert res.mc[plain].overshoot > 0.9 and 0.2 < res.mc[comp].overshoot < 0.8
        assert abs(res.mc[comp].mean) < 0.1 * abs(res.mc[plain].mean)
        assert res.mc[comp].p >= res.mc[plain].p


def test_damped_pid_does_not_ring_in_the_nominal_stop(small):
    _, res = small
    assert res.nominal["pid-damped"].sign_changes <= 1 < 3 <= res.nominal["pid"].sign_changes


def test_study_is_deterministic(small):
    spec, res = small
    again = run_station_stops(spec)
    assert {k: v.errors for k, v in again.mc.items()} == {k: v.errors for k, v in res.mc.items()}
    assert {k: v.error for k, v in again.nominal.items()} == \
        {k: v.error for k, v in res.nominal.items()}


def test_predictor_loop_dead_time(spec000):
    assert loop_dead_time(spec000, "pid-comp") == spec000.dt_ctrl / 2
    assert loop_dead_time(spec000, "pid") == spec000.params["T1"].value + spec000.dt_ctrl / 2


# -- 004: retuned nominal corner, sensor faults, Monte Carlo determinism ----------------------
@pytest.fixture(scope="module")
def res004():
    from workbench.papers.p004.closed_loop_brake import NOMINAL, run_grid
    spec = load_design(D004).spec
    corner = dict(zip(("force_error", "gradient", "friction"), NOMINAL))
    nominal = replace(spec, grid=tuple((k, (corner[k],)) for k, _ in spec.grid))
    return spec, run_grid(nominal, montecarlo=False)


def test_004_horizon_is_dead_time_plus_lag(res004):
    spec, _ = res004
    assert spec.constants["t_p"].value == pytest.approx(spec.params["T1"].value + spec.params["T2"].value,
                                           abs=0.005)


@pytest.mark.parametrize("speed", [50.0, 80.0])
def test_004_retuned_nominal_corner_within_0_3_m(res004, speed):
    spec, res = res004
    assert abs(res.stop(speed)) <= spec.tolerance


def test_004_sensor_reading_high_wins_max_of_4_and_stuck_one_defeats_it(res004):
    _, res = res004
    pick = lambda f: res.stop(50.0, fault=f)
    healthy, high, stuck = pick("healthy"), pick("1 reading high"), pick("1 stuck")
    assert high != healthy and abs(high - healthy) < 0.05
    assert stuck < -10.0                      # full service from a frozen speed: far short


def test_004_montecarlo_is_seeded():
    from workbench.papers.p004.closed_loop_brake_run import run_montecarlo
    spec = load_design(D004).spec
    spec = replace(spec, speeds_kmh=(50.0,), montecarlo=MonteCarloSpec(
        6, spec.montecarlo.seed, spec.montecarlo.distributions))
    a, b = run_montecarlo(spec, {50.0: 152.74}), run_montecarlo(spec, {50.0: 152.74})
    assert {k: v.errors for k, v in a.items()} == {k: v.errors for k, v in b.items()}
