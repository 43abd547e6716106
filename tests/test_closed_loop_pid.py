"""Paper 004: the deceleration loops' PIDs stepped as one batch (MaskedBatchPID) equal one PID per run."""
import numpy as np

from workbench.controllers.pid import PID
from workbench.controllers.pid import MaskedBatchPID


def test_batched_pids_equal_one_pid_per_run_bit_for_bit():
    rng = np.random.default_rng(3)
    n, gains, dt = 9, {"kp": 0.7, "ki": 0.35, "kd": 0.05}, 0.1
    closed = rng.uniform(size=n) > 0.3
    batch = MaskedBatchPID(gains, dt, closed)
    pids = [PID(**gains, dt=dt) for _ in range(n)]
    in_pid = np.zeros(n, bool)
    for _ in range(60):
        e = rng.normal(0.0, 0.2, n)
        base = rng.normal(0.0, 0.1, n)
        small = np.abs(e) <= 0.15
        enter = small & ~in_pid
        batch.reset(enter)
        got = batch.step(small, e, base)
        want = base.copy()
        for j in np.flatnonzero(closed):
            if enter[j]:
                pids[j].reset()
            if small[j]:
                want[j] += pids[j].step(float(e[j]))
        assert np.array_equal(got, want)
        in_pid = small
    assert closed.any() and not closed.all()
