"""A sweep's results do not depend on where its chunks run (issue 17, item 2):
in-process, a local process pool, a Dask LocalCluster, any chunk size, and
a worker killed mid-sweep (its chunk is run again). Kept small for CI on
two cores: the dry design cut to 12 s (braking from 6 s), v(0) near v_d so
that every phase is visited, 64 samples."""
from __future__ import annotations

import dataclasses
import os
import signal

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.papers.p003.antiskid_montecarlo import start_sweep, sweep

N = 64
distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="module")
def short():
    d = load_design("designs/antiskid-run-dry.toml")
    sp = d.spec
    spec = dataclasses.replace(
        sp, scenario={**sp.scenario, "t_brake": 6.0, "t_end": 12.0},
        montecarlo=dataclasses.replace(sp.montecarlo, v0=(64.0, 68.0)))
    return dataclasses.replace(d, spec=spec)


def assert_identical(a, b) -> None:
    """Every draw, metric and outcome of every run, bit for bit (NaN = NaN)."""
    for part in ("samples", "metrics", "violations"):
        x, y = getattr(a, part), getattr(b, part)
        assert x.keys() == y.keys()
        for k in x:
            np.testing.assert_array_equal(np.asarray(x[k]), np.asarray(y[k]), err_msg=f"{part}.{k}")


@pytest.fixture(scope="module")
def reference(short):
    return {k: sweep(short, N, 3, workers=1, chunk=N, kernel=k, progress=False)
            for k in ("compiled", "numpy")}


def test_the_short_sweep_visits_every_outcome(reference):
    v = reference["numpy"].violations
    assert any(v["above_lambda_opt"]) and any(v["not_stopped"])
    assert np.isfinite(reference["numpy"].metrics["t_cruise"]).sum() > N // 2


def test_compiled_and_numpy_paths_agree_bit_for_bit_here(reference):
    assert_identical(reference["compiled"], reference["numpy"])


@pytest.mark.slow
@pytest.mark.parametrize("kernel, chunks", [("compiled", (16, 23)), ("numpy", (23,))])
def test_process_pool_and_chunk_sizes(short, reference, kernel, chunks):
    for chunk in chunks:
        assert_identical(sweep(short, N, 3, workers=2, chunk=chunk, kernel=kernel,
                               progress=False), reference[kernel])


@pytest.mark.slow
def test_local_dask_cluster(short, reference):
    res = sweep(short, N, 3, workers=2, chunk=20, kernel="numpy", progress=False,
                scheduler="local")
    assert res.workers == 2
    assert_identical(res, reference["numpy"])


@pytest.mark.slow
def test_killed_worker_mid_sweep(short, reference):
    pending = start_sweep(short, N, 3, workers=2, chunk=16, kernel="numpy", scheduler="local")
    pids = pending.client.run(os.getpid)        # worker address -> process id
    futures = pending._futures
    assert not all(f.done() for f in futures)   # mid-sweep
    os.kill(next(iter(pids.values())), signal.SIGKILL)
    res = pending.result(progress=False)
    assert_identical(res, reference["numpy"])


def test_unreachable_scheduler_is_a_cli_error(capsys, monkeypatch):
    """A scheduler address nobody listens on: exit 2 naming --scheduler. The
    connect is retried until its timeout (10 s in the code); the test gives it
    0.5 s, the refusal on a closed local port is the same."""
    import distributed

    class QuickClient(distributed.Client):
        def __init__(self, *args, timeout=None, **kwargs):
            assert timeout is not None  # the code bounds the connect
            super().__init__(*args, timeout="0.5s", **kwargs)

    monkeypatch.setattr(distributed, "Client", QuickClient)
    code = main(["sweep", "designs/antiskid-run-dry.toml", "--samples", "2", "--seed", "1",
                 "--scheduler", "tcp://127.0.0.1:9"])
    err = capsys.readouterr().err
    assert code == 2 and "--scheduler = 'tcp://127.0.0.1:9'" in err
    assert "Traceback" not in err


def test_unknown_kernel_is_a_cli_error(capsys):
    code = main(["sweep", "designs/antiskid-run-dry.toml", "--samples", "2", "--seed", "1",
                 "--kernel", "fortran"])
    err = capsys.readouterr().err
    assert code == 2 and "--kernel = 'fortran'; expected compiled or numpy" in err


def test_default_workers_are_the_cpus_granted(short, monkeypatch):
    """The pool's default size is the CPUs this process may use (cgroup quota,
    affinity; LOKY_MAX_CPU_COUNT caps it), not os.cpu_count(): on a CI runner
    that shows the host's CPUs, a pool that large starved the other processes."""
    from workbench.sim.batch import available_cpus
    monkeypatch.setenv("LOKY_MAX_CPU_COUNT", "1")
    assert available_cpus() == 1
    pending = start_sweep(short, 4, 0, chunk=1)
    assert pending.workers == 1 and pending.result().n == 4
