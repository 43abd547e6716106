"""workbench.sim.jit_warm on a toy warm-up (no kernel of any paper)."""
from __future__ import annotations

import os

import pytest

pytest.importorskip("numba")

from workbench.sim.jit_warm import warm_in_processes  # noqa: E402


def _toy_warm(name: str) -> float:
    """A toy warm-up: compiles a one-line numba function; 'CPU seconds' =
    a value the test can read back (the name's length) when it ran in
    another process than the test's."""
    import numba
    assert numba.njit(lambda x: x + 1)(1) == 2
    return float(len(name)) if os.getpid() != PARENT else -1.0


PARENT = os.getpid()


def test_every_name_is_warmed_in_a_worker_process():
    line = warm_in_processes(_toy_warm, ("a", "bbb"))
    assert line.startswith("compiled kernels ready in the disk cache: ")
    assert line.endswith("a 1 CPU s, bbb 3 CPU s")
