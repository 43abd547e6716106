"""Numerics of the antiskid runs: the variable-step history, the refined
mesh, per-run sub-stepping in batches, and the divergence tests."""
from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from workbench.controllers.antiskid003_settings import DIVERGED_HOW
from workbench.design import load_design
from workbench.papers.p003 import antiskid_run_spec as S
from workbench.papers.p003.antiskid_scenario import Mesh, RunSettings, simulate_antiskid
from workbench.sim.history import DelayLine, TimedDelayLine
from workbench.sim.wheel_slip import PARAM_ORDER

K_TABLE3 = (-0.0049, 10.5080)   # paper 003, Table 3, eps = 0.35


@pytest.fixture(scope="module")
def spec():
    return load_design(Path("designs/antiskid-run-dry.toml")).spec


@pytest.fixture(scope="module")
def minus5():
    return load_design(Path("designs/antiskid-run-dry-mass-minus5.toml")).spec


def _settings(spec, case_name, t_end, **scenario):
    case = next(c for c in spec.cases if c.name == case_name)
    if scenario:
        spec = dataclasses.replace(spec, scenario={**spec.scenario, **scenario})
    cs = S.controller_settings(spec, K_TABLE3, case)
    return spec, cs, dataclasses.replace(S.run_settings(spec, cs), t_end=t_end)


def _zoh_integral(segs, initial, a, b, n=100_000):
    """Midpoint-rule integral of a ZOH signal given as (start, end, value)."""
    x = a + (np.arange(n) + 0.5) * (b - a) / n
    val = np.full(n, initial)
    for s0, s1, v in segs:
        val[(x >= s0) & (x < s1)] = v
    return val.mean() * (b - a)


def test_timed_delay_line_matches_the_zoh_signal():
    rng = np.random.default_rng(3)
    H, line, segs, T = 37.3, TimedDelayLine(37.3, 1.0, 5.0), [], 0
    for _ in range(120):
        n = int(2 ** rng.integers(0, 4))
        value = float(rng.normal())
        assert line.window_integral() == pytest.approx(_zoh_integral(segs, 5.0, T - H, T),
                                                       abs=2e-3)
        pieces = line.pieces(4)
        assert sum(d for _, d in pieces) == pytest.approx(H)
        assert sum(u * d for u, d in pieces) == pytest.approx(line.window_integral())
        line.push(value, n)
        segs.append((T, T + n, value))
        T += n
        assert line.delayed() == pytest.approx(
            _zoh_integral(segs, 5.0, T - n - H, T - H) / n, abs=1e-3)


def test_timed_delay_line_on_a_uniform_grid_is_the_delay_line():
    h, dt = 0.0433, 0.01
    fixed, timed = DelayLine(h, dt, 100.0), TimedDelayLine(h / dt, dt, 100.0)
    for k in range(40):
        value = math.sin(0.7 * k) * 1e3
        assert timed.window_integral() == pytest.approx(fixed.window_integral(), rel=1e-12)
        assert np.ravel(timed.pieces(1)) == pytest.approx(np.ravel(fixed.pieces()), rel=1e-12)
        fixed.push(value)
        timed.push(value, 1)
        assert timed.delayed() == pytest.approx(fixed.delayed(), rel=1e-12)


@pytest.mark.parametrize("case_name", ["compensated", "uncompensated", "recursive"])
def test_mesh_with_no_refinement_is_the_fixed_step(spec, case_name):
    _, _, rs = _settings(spec, case_name, 6.0)
    _, a = simulate_antiskid(rs, 0.01, record_dt=None)
    _, b = simulate_antiskid(rs, 0.01, record_dt=None, mesh=Mesh(0.01, 1.0, 0))
    assert b.lam_max_traction == pytest.approx(a.lam_max_traction, rel=1e-12)
    assert b.v_max == pytest.approx(a.v_max, rel=1e-12)


def test_mesh_refined_everywhere_is_the_fine_fixed_step(minus5):
    _, _, rs = _settings(minus5, "uncompensated", 2.0)
    fine, _ = simulate_antiskid(rs, 0.01 / 8, record_dt=0.25)
    mesh, _ = simulate_antiskid(rs, 0.01, record_dt=0.25, mesh=Mesh(0.01, 1e-9, 3))
    assert mesh.t == pytest.approx(fine.t)
    assert mesh.x == pytest.approx(fine.x, rel=1e-9, abs=1e-12)


def test_mesh_makes_the_uncompensated_start_converge(minus5):
    """Mass -5 %, no predictor: the max creep ratio of the start (peak near
    4 m/s) converges only at first order on the fixed step (0.216 / 0.205
    at dt = 10 / 5 ms); on the mesh dt and dt/2 agree within 1 %."""
    _, _, rs = _settings(minus5, "uncompensated", 3.0)
    fixed = [simulate_antiskid(rs, dt, record_dt=None)[1].lam_max_traction
             for dt in (0.01, 0.005)]
    mesh = [simulate_antiskid(rs, dt, record_dt=None, mesh=Mesh(0.01, 1.0, 4))[1]
            .lam_max_traction for dt in (0.01, 0.005)]
    assert abs(fixed[0] - fixed[1]) > 0.04 * fixed[1]
    assert abs(mesh[0] - mesh[1]) < 0.01 * mesh[1]
    assert mesh[1] < fixed[1]


def test_batch_runs_follow_their_single_run_trajectories(spec):
    """Sub-steps are taken per run: a run's metrics do not depend on its
    batch mates (here a fast-slipping wet run next to dry ones)."""
    _, cs, rs = _settings(spec, "compensated", 4.0)
    base = dict(zip(PARAM_ORDER, rs.plant_params))
    plants = [dict(base), dict(base, m=base["m"] * 0.95),
              dict(base, a=0.2478, b=22.87, c=5.396)]
    batch = RunSettings(tuple(np.array([p[k] for p in plants]) for k in PARAM_ORDER), cs,
                        np.array([rs.h, 0.02, 0.0]),
                        (np.array([3.0, 2.5, 4.0]), rs.x0[1]), rs.u_init, rs.t_end)
    _, mb = simulate_antiskid(batch, 0.01, record_dt=None, batch=3)
    for i, p in enumerate(plants):
        single = dataclasses.replace(rs, plant_params=tuple(p[k] for k in PARAM_ORDER),
                                     h=float(batch.h[i]), x0=(float(batch.x0[0][i]), rs.x0[1]))
        _, ms = simulate_antiskid(single, 0.01, record_dt=None)
        assert mb.lam_max_traction[i] == pytest.approx(ms.lam_max_traction, rel=1e-9)
        assert mb.v_max[i] == pytest.approx(ms.v_max, rel=1e-9)


def test_braking_law_on_the_traction_side_diverges_by_torque(spec):
    """Without the predictor, law (69) starts at lambda_d > 0, where its
    e^{b lambda} terms blow up: the run is declared diverged when the
    commanded torque leaves the physical range, 0.1 s into braking, at every
    step size, and the min creep ratio of braking is not reported."""
    sp, cs, rs = _settings(spec, "uncompensated", 40.5, t_brake=40.0)
    case = next(c for c in sp.cases if c.name == "uncompensated")
    out = []
    for dt in (0.01, 0.005):
        _, m = simulate_antiskid(rs, dt, record_dt=None, mesh=S.case_mesh(sp, case))
        met = S.case_metrics(m, cs, 40.0)
        assert DIVERGED_HOW[int(met["diverged_how"])] == "torque out of range"
        assert math.isnan(met["lam_min_brake"])
        out.append(met["t_diverged"])
    assert 40.0 < out[0] < 40.3 and abs(out[0] - out[1]) < 0.02
