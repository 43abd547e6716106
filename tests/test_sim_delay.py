"""Fixed-step delay simulation: history buffers, step halving against an
exact solution, exact-margin behaviour, stiff creep-ratio step."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.sim.delay import (envelope_ratio, exact_scalar_dde, simulate_closed_loop,
                                 simulate_linear_dde, step_halving)
from workbench.sim.history import BatchDelayLine, DelayLine, split_delay
from workbench.sim.wheel_slip import PARAM_ORDER, ScalarOps, model_functions, plant_step

DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)  # paper 003, Tables 1-2


def test_split_delay():
    assert split_delay(0.0433, 0.01) == (4, pytest.approx(0.33))
    assert split_delay(0.03, 0.01) == (3, 0.0)      # snapped, not 2.9999
    with pytest.raises(ValueError):
        split_delay(0.1, 0.0)


@pytest.mark.parametrize("h", [0.0, 0.004, 0.01, 0.0433])
def test_delay_line_is_exact_zoh_average(h):
    dt, rng = 0.01, np.random.default_rng(0)
    s = rng.normal(size=50)
    line = DelayLine(h, dt, initial=7.0)
    sig = lambda t: 7.0 if t < 0 else s[int(math.floor(t / dt + 1e-12))]
    for n in range(50):
        integral = line.window_integral()
        # integral of s over [t_n - h, t_n) by fine quadrature of the ZOH signal
        fine = np.linspace(n * dt - h, n * dt, 4001)[:-1] + h / 8000
        ref = h * np.mean([sig(t) for t in fine]) if h > 0 else 0.0
        assert integral == pytest.approx(ref, abs=1e-3 * (1 + abs(ref)))
        line.push(s[n])
        fine = np.linspace(n * dt - h, (n + 1) * dt - h, 4001)[:-1] + dt / 8000
        assert line.delayed() == pytest.approx(np.mean([sig(t) for t in fine]), abs=2e-3)


def test_batch_delay_line_matches_single():
    hs, dt = [0.0, 0.013, 0.0433], 0.01
    singles = [DelayLine(h, dt, 1.5) for h in hs]
    batch = BatchDelayLine(hs, dt, 1.5)
    for n in range(30):
        u = np.sin(np.arange(3) + n)
        batch.push(u)
        for i, s in enumerate(singles):
            s.push(float(u[i]))
        np.testing.assert_allclose(batch.delayed(), [s.delayed() for s in singles], atol=1e-15)


def test_step_halving_second_order():
    # x' = -x(t - h), x = 1 on [-h, 0]: exact piecewise polynomial (method of steps)
    rows = step_halving(1.0, 0.7, 10.0, [0.1, 0.05, 0.025, 0.0125])
    for r in rows[1:]:
        assert 1.9 < r.order < 2.1
    assert rows[-1].error < 2e-5


def test_exact_solution_first_pieces():
    h = 1.0
    assert exact_scalar_dde(1.0, h, [0.5])[0] == pytest.approx(0.5)          # 1 - t
    assert exact_scalar_dde(1.0, h, [1.5])[0] == pytest.approx(1 - 1.5 + 0.125)


@pytest.mark.parametrize("factor, grows", [(0.98, False), (1.05, True)])
def test_exact_margin_pi_over_2(factor, grows):
    # x' = -x(t - h) is stable exactly for h < pi/2 (crossing at omega = 1)
    r = simulate_linear_dde([[0.0]], [[-1.0]], factor * math.pi / 2, [1.0], 200.0, 0.01)
    ratio = envelope_ratio(r, 2 * math.pi)
    assert (ratio > 1.0) is grows


def test_closed_loop_delays_input_exactly():
    # x' = u(t - h), u = 1 from t = 0, 0 before: x(t) = max(t - h, 0)
    step = lambda x, u, t, dt: (x[0] + dt * u,)
    r = simulate_closed_loop(step, lambda t, x, line: (1.0, 0), (0.0,), h=0.0433, dt=0.01,
                             t_end=1.0, u_init=0.0)
    assert r.x[0, -1] == pytest.approx(1.0 - 0.0433, abs=1e-12)
    tr = r.to_time_response()
    assert tr.states.shape == r.x.shape and tr.time.shape == r.t.shape


def test_stiff_creep_step_is_stable_at_low_speed():
    # at v = 0.2 m/s the creep time constant is ~0.05 ms; a 10 ms step must not blow up
    fns = model_functions("math")
    p = tuple(DRY[k] for k in PARAM_ORDER)
    x = (0.2, -0.05)
    lams = []
    for _ in range(50):
        x = plant_step(x, -2000.0, p, 0.01, fns, ScalarOps)
        lams.append(x[1])
    assert all(abs(l) < 1 for l in lams)
    assert abs(lams[-1] - lams[-2]) < 1e-6     # settled on the quasi-steady creep ratio
