"""The general refined mesh (:class:`workbench.sim.rate_mesh.RateMesh`) on a
toy plant, and the compiled loops' perturbation arrays
(:func:`workbench.sim.perturb.perturbation_arrays`) and noisy measurement
(:func:`workbench.sim.perturb.noisy_measure`), away from any paper."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.sim.delay import simulate_closed_loop
from workbench.sim.counter_rng import normal4
from workbench.sim.history import BatchDelayLine
from workbench.sim.perturb import (PERT, Perturbations, VaryingDelayLine, batch_delay_line,
                                   measured_state, noisy_measure, perturbation_arrays)
from workbench.sim.rate_mesh import RateMesh


def test_level_is_the_smallest_halving_below_the_rate_bound():
    m = RateMesh(dt_ref=0.01, courant=1.0, k_max=4)
    assert m.level(10.0, 50.0) == 0                 # 0.01 * 5 <= 1
    assert m.level(1.0, 300.0) == 2                 # 0.01 * 300 = 3 -> 2**2 >= 3
    assert m.level(0.0, 300.0) == 4                 # the floor x_floor: capped at k_max
    for x, S in ((0.5, 700.0), (2.0, 1234.0), (0.01, 99.0)):
        k = m.level(x, S)
        assert (0.01 / 2**k) * S / max(x, 1e-3) <= 1.0 or k == m.k_max
        assert k == 0 or (0.01 / 2**(k - 1)) * S / x > 1.0


def test_toy_decay_on_the_rate_mesh_refines_where_the_rate_is_fast():
    """x' = -S (a stiff drain whose rate S / x grows as x falls) from x = 1:
    the mesh halves the step as x falls, the run ends at x = 0 at t = 1 / S
    within the finest step, and the fixed grid (k_max = 0) does not refine."""
    S = 2.0
    steps = []

    def step(x, u, t, dt):
        steps.append(dt)
        return (max(x[0] - S * dt, 0.0),)
    mesh = RateMesh(dt_ref=0.05, courant=2.0, k_max=3)
    r = simulate_closed_loop(step, lambda t, x, line: (0.0, 0), (1.0,), h=0.0, dt=0.05,
                             t_end=1.0, u_init=0.0, level=mesh.of_state(S),
                             k_max=mesh.k_max, done=lambda t, x, ph: x[0] <= 0.0)
    assert steps[0] == 0.05 and min(steps) == 0.05 / 8
    assert math.isclose(r.t[-1], 1.0 / S, abs_tol=0.05 / 8)
    assert mesh.level(1.0, S) == 0 and RateMesh(0.05, 2.0, 0).level(1e-3, S) == 0


def test_perturbation_arrays_name_every_entry():
    keys, pert, period, phase = perturbation_arrays(None, 3)
    assert keys.shape == (3, 3) and len(pert) == len(PERT) and not keys.any()
    pt = Perturbations(run=(0, 1), keys={"v": (5, 6), "grade": (7, 8)}, noise_v=0.1,
                       noise_every=4, grade=(-0.01, 0.02), segment=50.0, delay=(0.1, 0.3),
                       period=(2.0, 3.0), phase=(0.0, 0.5))
    keys, pert, period, phase = perturbation_arrays(pt, 2)
    got = dict(zip(PERT, pert))
    assert got == {"noise_v": 0.1, "noise_omega": 0.0, "noise_every": 4.0, "graded": 1.0,
                   "grade_lo": -0.01, "grade_hi": 0.02, "segment": 50.0, "varying": 1.0,
                   "h_lo": 0.1, "h_hi": 0.3}
    np.testing.assert_array_equal(keys, np.array([[5, 0, 7], [6, 0, 8]], np.uint64))
    np.testing.assert_array_equal(period, [2.0, 3.0])
    np.testing.assert_array_equal(phase, [0.0, 0.5])


def test_noisy_measure_holds_each_noise_value_for_noise_every_samples():
    pt = Perturbations(run=(0, 1), keys={"v": (11, 12), "omega": (21, 22)}, noise_v=0.2,
                       noise_omega=0.5, noise_every=2)
    v, lam = np.array([10.0, 20.0]), np.array([0.01, -0.02])
    measure = noisy_measure(pt, 0.5, 0.52, 0.1)
    a, b, c = (measure(v, lam) for _ in range(3))
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert not np.array_equal(a[0], c[0])
    kv, kw = np.array([11, 12], np.uint64), np.array([21, 22], np.uint64)
    for k, got in ((0, a), (1, c)):
        want = measured_state(v, lam, normal4(kv, k), normal4(kw, k), 0.2, 0.5, 0.5, 0.52, 0.1)
        for x, y in zip(got, want):
            np.testing.assert_array_equal(x, y)


def test_tuple_readers_read_vectors_and_rows_into_padded_tuples():
    numba = pytest.importorskip("numba")
    from workbench.sim.jit_tuples import tuple_readers
    jit = numba.njit(nogil=True)
    vector, row = tuple_readers(jit, 3, 1)
    a = np.arange(8.0).reshape(2, 4)

    @jit
    def total(p, a, j):         # a loop reading the tuples, as a kernel does
        s = 0.0
        for _ in range(3):
            x, y = vector(p), row(a, j)
            s += x[0] + x[1] + x[2] + x[3] + y[3]
        return s
    assert vector(np.array([1.0, 2.0, 3.0])) == (1.0, 2.0, 3.0, 0.0)
    assert row(a, 1) == (4.0, 5.0, 6.0, 7.0)
    assert total(np.array([1.0, 2.0, 3.0]), a, 1) == 3 * (6.0 + 7.0)
    assert tuple_readers(jit, 2)[0](np.array([5.0, 6.0, 7.0])) == (5.0, 6.0)


def test_batch_delay_line_is_per_run_or_varying_and_none_for_a_single_run():
    assert batch_delay_line(None, 0.1, None, 0.01, 5.0) is None
    line = batch_delay_line(None, np.array([0.02, 0.035]), 2, 0.01, 5.0)
    assert isinstance(line, BatchDelayLine)
    for k in range(5):
        line.push(np.array([k, 10.0 * k]))
    # the last input (4, 40) was pushed at step 4: the inputs 2 and 3.5 steps back
    np.testing.assert_allclose(line.delayed(), [4.0 - 2.0, 10.0 * (4.0 - 3.5)])
    pt = Perturbations(run=(0, 1), keys={}, delay=(0.01, 0.03), period=(1.0, 2.0),
                       phase=(0.0, 0.5))
    assert isinstance(batch_delay_line(pt, 0.02, 2, 0.01, 5.0), VaryingDelayLine)
