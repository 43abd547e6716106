"""The sampled perturbations of the antiskid sweep (issue 17, item 6):
measurement noise on v and omega, a gradient profile, a time-varying delay.

The counter-based generator gives the same bits in numpy and numba and the
stated moments; the varying delay stays inside its range; a zero gradient
reproduces the ungraded plant bit for bit; the compiled kernel and the
batched numpy path agree with every perturbation on (to 1e-9 relative, as
``tests/test_compiled_kernel.py``) on a shortened scenario.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from workbench.design import load_design
from workbench.papers.p003.antiskid_montecarlo import chunk_payload, chunk_worker, sweep_inputs
from workbench.papers.p003.antiskid_run_spec import SweepPerturbations, gain_for
from workbench.sim import counter_rng as R
from workbench.sim.perturb import delay_at, split_delays

RTOL = 1e-9


@pytest.fixture(scope="module")
def dry():
    return load_design("designs/antiskid-run-dry.toml")


def _with(design, perturb, **scenario):
    spec = design.spec
    ms = dataclasses.replace(spec.montecarlo, perturb=perturb)
    spec = dataclasses.replace(spec, montecarlo=ms, scenario={**spec.scenario, **scenario})
    return dataclasses.replace(design, spec=spec)


def _payload(design, n, dt=None, kernel="numpy", v0=None):
    spec = design.spec
    inp = sweep_inputs(design, n, spec.montecarlo.seed, gain_for(spec)[0])
    pl = chunk_payload(inp, 0, n, dt or inp["dt"], kernel)
    if v0 is not None:
        pl["v0"] = [v0] * n
    return pl


#: every perturbation on; short segments so that a short run crosses several
ALL_ON = SweepPerturbations(noise_v=0.05, noise_omega=0.5, gradient=(-20.0, 20.0), segment=100.0,
                            delay_period=(1.0, 5.0))


def test_noise_generator_numpy_equals_numba_and_has_unit_variance():
    numba = pytest.importorskip("numba")
    run_key, uniform, normal4 = R.jit_functions()

    @numba.njit
    def draws(key, n):
        out = np.empty(n)
        for k in range(n):
            out[k] = normal4(key, np.uint64(k))
        return out

    keys = R.run_key(7, R.NOISE_V, np.arange(3))
    assert run_key(np.uint64(7), np.uint64(R.NOISE_V), np.uint64(2)) == keys[2]
    a = draws(keys[2], 100_000)
    b = R.normal4(keys[2], np.arange(100_000))
    np.testing.assert_array_equal(a, b)
    # mean 0, variance 1: 5 standard errors (sd of the variance estimate ~ sqrt(2 / n))
    assert abs(b.mean()) < 5 / np.sqrt(1e5)
    assert abs(b.var() - 1.0) < 5 * np.sqrt(2 / 1e5)
    assert np.abs(b).max() <= 2 * np.sqrt(3)
    assert uniform(keys[0], np.uint64(5)) == R.uniform(keys[0], 5)
    # another run's stream is another stream
    assert not np.array_equal(b[:100], R.normal4(keys[1], np.arange(100)))


def test_varying_delay_stays_inside_its_range():
    t = np.arange(0.0, 60.0, 0.005)
    for period, phase in ((1.0, 0.0), (7.3, 0.42), (20.0, 0.999)):
        h = np.array([delay_at(x, 0.0, 0.0433, period, phase) for x in t])
        assert h.min() >= 0.0 and h.max() <= 0.0433
        assert h.max() - h.min() > 0.99 * 0.0433      # it sweeps the range
        N, f = split_delays(h, 0.005)
        np.testing.assert_allclose((N + f) * 0.005, h, rtol=0, atol=1e-15)
        assert (f >= 0).all() and (f < 1).all()


@pytest.mark.slow
def test_zero_gradient_reproduces_the_ungraded_plant(dry):
    base = _with(dry, None, t_brake=5.0, t_end=8.0)
    zero = _with(dry, SweepPerturbations(gradient=(0.0, 0.0)), t_brake=5.0, t_end=8.0)
    for kernel in ("numpy", "compiled"):
        if kernel == "compiled":
            pytest.importorskip("numba")
        a = chunk_worker(_payload(base, 2, kernel=kernel, v0=66.0))["metrics"]
        b = chunk_worker(_payload(zero, 2, kernel=kernel, v0=66.0))["metrics"]
        for k in a:
            np.testing.assert_array_equal(a[k], b[k], err_msg=f"{kernel}: {k}")


@pytest.mark.slow
def test_compiled_and_numpy_agree_with_every_perturbation_on(dry):
    """8 runs, noise + gradient + varying delay, every phase visited."""
    pytest.importorskip("numba")
    from tests.test_compiled_kernel import assert_close
    from workbench.papers.p003.antiskid_kernel import METRIC_FIELDS
    d = _with(dry, ALL_ON, t_brake=5.0, t_end=8.0)
    a = chunk_worker(_payload(d, 8, kernel="compiled", v0=66.0))["metrics"]
    b = chunk_worker(_payload(d, 8, kernel="numpy", v0=66.0))["metrics"]
    assert_close(a, b, METRIC_FIELDS)
    assert np.isfinite(b["t_cruise"]).any() and np.isfinite(b["lam_at_brake"]).any()
    base = chunk_worker(_payload(_with(dry, None, t_brake=5.0, t_end=8.0), 8, v0=66.0))
    # the perturbations change the runs
    assert not np.array_equal(np.asarray(b["lam_at_brake"]),
                              np.asarray(base["metrics"]["lam_at_brake"]))


def test_a_run_does_not_depend_on_its_chunk(dry):
    d = _with(dry, ALL_ON, t_brake=2.0, t_end=3.0)
    spec = d.spec
    inp = sweep_inputs(d, 6, spec.montecarlo.seed, gain_for(spec)[0])
    whole = chunk_worker(chunk_payload(inp, 0, 6, inp["dt"]))["metrics"]
    part = chunk_worker(chunk_payload(sweep_inputs(d, 6, spec.montecarlo.seed,
                                                   gain_for(spec)[0], start=4), 0, 2,
                                      inp["dt"]))["metrics"]
    for k in whole:
        np.testing.assert_array_equal(np.asarray(whole[k])[4:], part[k], err_msg=k)
