"""Paper 003's controllers in closed loop (short horizons; the full runs are
the antiskid-run-* designs checked by `workbench verify`)."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.controllers.antiskid003_settings import DIVERGED
from workbench.design import load_design
from workbench.papers.p003 import antiskid_run as R
from workbench.papers.p003 import antiskid_run_spec as S
from workbench.papers.p003.antiskid_scenario import simulate_antiskid
from workbench.sim.wheel_slip import ScalarOps

DRY = Path("designs/antiskid-run-dry.toml")
K_TABLE3 = (-0.0049, 10.5080)   # paper 003, Table 3, eps = 0.35


@pytest.fixture(scope="module")
def spec():
    return load_design(DRY).spec


def _run(spec, case_name, t_end, dt=0.01, **changes):
    case = next(c for c in spec.cases if c.name == case_name)
    cs = dataclasses.replace(S.controller_settings(spec, K_TABLE3, case), **changes)
    rs = dataclasses.replace(S.run_settings(spec, cs), t_end=t_end)
    return cs, rs, simulate_antiskid(rs, dt, record_dt=0.05)


def test_acceleration_tracks_lambda_opt_and_hands_over(spec):
    cs, _, (res, m) = _run(spec, "compensated", 34.0)
    assert m.lam_max_traction <= cs.lambda_opt * 1.001
    assert 30.0 < m.t_cruise < 32.0
    assert math.isfinite(m.t_handover_done) and math.isnan(m.t_diverged)
    assert abs(res.x[1, -1] - cs.lambda_d) < 0.003


def test_printed_switch_to_cruise_spins_the_wheel(spec):
    _, _, (res, m) = _run(spec, "paper", 34.0)
    assert m.t_cruise < m.t_diverged < m.t_cruise + 1.0
    assert res.phase[-1] == DIVERGED


def test_stiff_sampling_converges_and_zoh_does_not(spec):
    t = {}
    for mode in ("stiff", "zoh"):
        t[mode] = [_run(spec, "compensated", 32.0, dt, sampling=mode)[2][1].t_cruise
                   for dt in (0.01, 0.005)]
    assert abs(t["stiff"][0] - t["stiff"][1]) < 0.005
    assert abs(t["zoh"][0] - t["zoh"][1]) > 0.03      # printed law held: first order in dt


def test_stiff_hold_with_mismatch_estimate_converges():
    """Plant mass +5 %: the slow cruise transient is set by where lambda
    settles; without the mismatch estimate the stiff hold scales the mismatch
    by phi1(dt J) and v(120 s) moves at first order in dt."""
    plus5 = load_design(Path("designs/antiskid-run-dry-mass-plus5.toml")).spec
    gap = {}
    for tau in (0.2, 0.0):
        case = next(c for c in plus5.cases if c.name == "compensated")
        cs = dataclasses.replace(S.controller_settings(plus5, K_TABLE3, case), observer_tau=tau)
        rs = dataclasses.replace(S.run_settings(plus5, cs), t_end=120.0)
        v = [simulate_antiskid(rs, dt, record_dt=1.0)[0].x[0, -1] for dt in (0.01, 0.005)]
        gap[tau] = abs(v[0] - v[1])
    assert gap[0.2] < 0.005           # measured 0.0012 m/s
    assert gap[0.0] > 0.04            # measured 0.087 m/s: first order


def test_batch_matches_single_run(spec):
    cs, rs, (_, m1) = _run(spec, "compensated", 33.0)
    plant = tuple(np.full(2, x) for x in rs.plant_params)
    rb = dataclasses.replace(rs, plant_params=plant, h=np.full(2, rs.h))
    _, mb = simulate_antiskid(rb, 0.01, record_dt=None, batch=2)
    for k in ("t_cruise", "lam_max_traction", "v_max"):
        np.testing.assert_allclose(getattr(mb, k), getattr(m1, k), rtol=1e-9)


def test_switch_check_sign(spec):
    cs = S.controller_settings(spec, K_TABLE3, spec.cases[0])
    assert R.switch_check(cs, 70.0, cs.lambda_opt).abscissa > 0      # unstable at the peak
    assert R.switch_check(cs, 70.0, cs.lambda_d).abscissa < 0        # stable at the cruise point


def test_simulate_cli(capsys):
    assert main(["simulate", str(DRY), "--case", "paper"]) == 0
    assert "real time" in capsys.readouterr().out
    assert main(["simulate", str(DRY), "--case", "nope"]) == 2


def test_bad_design_is_exit_2(tmp_path, capsys):
    bad = tmp_path / "antiskid-run-dry.toml"
    bad.write_text(DRY.read_text().replace('cruise_entry = "creep"', 'cruise_entry = "later"', 1))
    assert main(["verify", str(bad)]) == 2
    assert "cruise_entry" in capsys.readouterr().err


@pytest.mark.slow
def test_sweep_is_seeded(tmp_path, capsys):
    short = tmp_path / "antiskid-run-dry.toml"
    text = DRY.read_text().replace('value = 300.0,  unit = "s"', 'value = 31.5,  unit = "s"')
    text = text.replace("dt = 0.005                          # s, step of the sweep's runs",
                        "dt = 0.01                          # s, step of the sweep's runs")
    short.write_text(text.replace('value = 420.0,', 'value = 32.0,'))
    from workbench.papers.p003.antiskid_montecarlo import sweep
    d = load_design(short)
    a = sweep(d, 3, seed=7, workers=1, progress=False)
    b = sweep(d, 3, seed=7, workers=1, progress=False)
    c = sweep(d, 3, seed=8, workers=1, progress=False)
    np.testing.assert_equal(a.samples, b.samples)
    np.testing.assert_equal(a.metrics, b.metrics)
    assert a.samples != c.samples
    assert len(a.metrics["t_cruise"]) == 3
    fig = tmp_path / "hist.png"
    assert main(["sweep", str(short), "--samples", "2", "--seed", "1", "--workers", "1",
                 "--figure", str(fig)]) == 0
    out = capsys.readouterr().out
    assert fig.exists() and "outcome" in out and "Wilson 95 % interval" in out


def test_compiled_metric_updates_match_the_recorded_trajectory(spec):
    """The one metric update (``antiskid_scenario.metric_updates``, compiled,
    shared by the case runs, the numpy batch and the compiled batch) against
    the metrics' definitions evaluated with numpy on the run's trajectory
    recorded at every sample, over traction, the switch to braking, the
    tracking window, omega = 3 rad/s and the stop; and a batch of two runs
    (its row form, on the numpy batch's trajectory, equal to the single run's
    up to the last bits) giving the single run's metrics."""
    from workbench.controllers.antiskid003_settings import BRAKE, BRAKE_IN, STOPPED
    sc = {**spec.scenario, "t_brake": 40.0, "t_end": 140.0}
    short = dataclasses.replace(spec, scenario=sc)
    case = next(c for c in short.cases if c.name == "compensated")
    cs = S.controller_settings(short, K_TABLE3, case)
    rs = S.run_settings(short, cs)
    dt = 0.01
    res, m = simulate_antiskid(rs, dt, record_dt=dt)
    t, (v, lam), ph = res.t, res.x, res.phase
    assert np.allclose(np.diff(t), dt) and ph[-1] == STOPPED
    trac, brk = ph < BRAKE_IN, (ph == BRAKE_IN) | (ph == BRAKE)
    assert m.lam_max_traction == lam[trac].max() and m.v_max == v[trac].max()
    assert m.lam_min_brake == lam[brk].min()
    assert m.t_stop == t[-1] and m.t_lam_negative == t[brk & (lam < 0)][0]
    i = np.flatnonzero(v >= cs.v_d)[0]         # v = v_d, interpolated between samples
    assert m.t_cruise == pytest.approx(t[i] - dt * (v[i] - cs.v_d) / (v[i] - v[i - 1]),
                                       rel=1e-12)
    assert (m.v_at_cruise, m.lam_at_cruise) == (v[i], lam[i])
    k = np.flatnonzero(brk)[0]
    assert (m.lam_at_brake, m.v_err_at_brake) == (lam[k], v[k] - cs.v_d)
    r = rs.plant_params[4]
    omega = np.where(lam >= 0, v / (1.0 - np.minimum(lam, 0.999)), v * (1.0 + lam)) / r
    w = np.flatnonzero(brk & (omega <= cs.profile.omega_switch))[0]
    assert t[w - 1] <= m.t_omega3 <= t[w]
    vs = np.where(lam >= 0, lam * v / (1.0 - np.minimum(lam, 0.999)), lam * v)
    vs_on = np.array([cs.profile(tt, vv, 0.0, math.inf, ScalarOps)[0] for tt, vv in zip(t, v)])
    e = np.abs(vs - np.where(omega > cs.profile.omega_switch, vs_on, 0.0))
    assert m.evs_last == e[brk][-1]        # the last braking sample (the stop ends it)
    window = brk & (t >= sc["t_brake"] + 5.0) & (t < m.t_omega3)
    assert window.sum() > 100 and m.evs_max_tracking >= e[window].max()
    assert m.evs_max_tracking == pytest.approx(max(e[window].max(), np.abs(vs - vs_on)[w]),
                                               rel=0.05)
    plant = tuple(np.full(2, x) for x in rs.plant_params)
    _, mb = simulate_antiskid(dataclasses.replace(rs, plant_params=plant, h=np.full(2, rs.h)),
                              dt, record_dt=None, batch=2)
    for key, a in vars(m).items():
        b = getattr(mb, key)
        assert (math.isnan(a) and np.isnan(b).all()) or b == pytest.approx([a, a], rel=1e-9), key


@pytest.mark.parametrize("case_name", ["paper", "compensated", "uncompensated", "recursive"])
def test_scalar_controller_and_plant_step_are_the_generic_ones_bit_for_bit(
        spec, case_name, monkeypatch):
    """The single-run paths of the controller (its sample, observer and
    predictor rollout: :mod:`workbench.controllers.antiskid003_scalar`) and of
    the plant step (``wheel_slip._scalar_plant_step``), which every case run
    takes, against the generic bodies fed the same floats: every metric and
    the recorded trajectory equal bit for bit, over traction, the cruise
    switch (``paper``: it diverges there), braking and the stop, on the fixed
    step and on the refined mesh (``uncompensated``) (issue 36, item 4)."""
    from workbench.controllers.antiskid003 import Antiskid003 as C
    from workbench.sim import wheel_slip as W
    sc = {**spec.scenario, "t_brake": 40.0, "t_end": 140.0}
    short = dataclasses.replace(spec, scenario=sc)
    case = next(c for c in short.cases if c.name == case_name)
    rs = S.run_settings(short, S.controller_settings(short, K_TABLE3, case))
    mesh = S.case_mesh(short, case)
    fast = simulate_antiskid(rs, 0.01, record_dt=0.05, mesh=mesh)
    used = dict.fromkeys(("call", "observe", "rollout", "plant"), 0)

    def counted(key, fn):
        def run(*a):
            used[key] += 1
            return fn(*a)
        return run
    monkeypatch.setattr(C, "_call_scalar", counted("call", C._call_generic))
    monkeypatch.setattr(C, "_observe_scalar", counted("observe", C._observe_generic))
    monkeypatch.setattr(C, "_rollout_scalar", counted("rollout", C._rollout_generic))
    monkeypatch.setattr(W, "_scalar_plant_step", counted("plant", lambda v, lam, u, dt, p, fns, vf, depth: W.stiff_step_flagged(
        v, lam, u, dt, lambda vv, ll: W.plant_forms(W.ScalarOps.maximum(vv, vf), ll, p, fns,
                                                     W.ScalarOps), W.ScalarOps, True, depth)))
    slow = simulate_antiskid(rs, 0.01, record_dt=0.05, mesh=mesh)
    assert used["call"] > 1000 and used["plant"] >= used["call"] - 1
    assert used["rollout"] > 0 or not case.compensate or case.predictor != "rollout"
    mf, ms = vars(fast[1]), vars(slow[1])
    for k in mf:
        a, b = float(mf[k]), float(ms[k])
        assert (math.isnan(a) and math.isnan(b)) or a == b, k
    for f in ("t", "x", "u", "u_applied", "phase"):
        np.testing.assert_array_equal(getattr(fast[0], f), getattr(slow[0], f), err_msg=f)
    if case_name == "compensated":
        assert math.isfinite(mf["t_stop"]) and math.isfinite(mf["t_handover_done"])
    if case_name == "paper":
        assert math.isfinite(mf["t_diverged"])
