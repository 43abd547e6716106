"""Compile several compiled (numba) kernels into the disk cache at once, each in its own process.

A kernel kept in the disk cache of :mod:`workbench.sim.jit_cache` compiles
once per machine and source; that once belongs to the install, not to the
first study that runs it. :func:`warm_in_processes` runs a package's
warm-up functions, one per kernel, every one in a process of its own, all
at once (the compilations are single-threaded), and returns one line of
figures: each one's CPU seconds. The warm-up functions know the kernels;
this module knows none.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from concurrent.futures import ProcessPoolExecutor
from importlib.util import find_spec

__all__ = ["warm_in_processes"]


def _cpu_seconds(warm: Callable[[], object]) -> float:
    """CPU seconds this process spends in ``warm()``."""
    c0 = time.process_time()
    warm()
    return time.process_time() - c0


def warm_in_processes(warmers: Mapping[str, Callable[[], object]]) -> str:
    """Call every warm-up function (module-level functions: they are pickled
    to the workers), each in its own process, all at once.

    Parameters
    ----------
    warmers : mapping of str to callable
        Kernel name -> a function that compiles (or loads from the disk
        cache) that kernel in the calling process.

    Returns
    -------
    str
        One line: the wall seconds of the whole and each kernel's CPU
        seconds; without numba, a line saying that nothing was compiled.
    """
    if find_spec("numba") is None:
        return "compiled kernels: numba not installed, nothing to compile"
    w0 = time.perf_counter()
    with ProcessPoolExecutor(len(warmers)) as ex:
        cpu = list(ex.map(_cpu_seconds, warmers.values()))
    return (f"compiled kernels ready in the disk cache: {time.perf_counter() - w0:.0f} s wall, "
            + ", ".join(f"{k} {c:.0f} CPU s" for k, c in zip(warmers, cpu)))
