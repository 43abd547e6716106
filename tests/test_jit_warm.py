"""workbench.sim.jit_warm on a toy warm-up (no kernel of any paper)."""
from __future__ import annotations

import os
import re

import pytest

pytest.importorskip("numba")

from workbench.sim.jit_warm import warm_in_processes  # noqa: E402


def _toy_warm() -> None:
    """A toy warm-up: compiles a one-line numba function; refuses to run in
    the test's own process (every warm-up runs in a worker)."""
    import numba
    assert os.getpid() != PARENT
    assert numba.njit(lambda x: x + 1)(1) == 2


PARENT = os.getpid()


def test_every_warmer_runs_in_a_worker_process_and_is_named():
    line = warm_in_processes({"a": _toy_warm, "bbb": _toy_warm})
    assert line.startswith("compiled kernels ready in the disk cache: ")
    assert re.fullmatch(r".* s wall, a \d+ CPU s, bbb \d+ CPU s", line)
