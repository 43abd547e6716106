"""Compile several compiled (numba) kernels into the disk cache at once, each in its own process.

A kernel kept in the disk cache of :mod:`workbench.sim.jit_cache` compiles
once per machine and source; that once belongs to the install, not to the
first study that runs it. :func:`warm_in_processes` runs a package's
warm-up function once per kernel name, every name in a process of its own,
all at once (the compilations are single-threaded), and returns one line of
figures. The warm-up function knows the kernels; this module knows none.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from importlib.util import find_spec

__all__ = ["warm_in_processes"]


def warm_in_processes(warm: Callable[[str], float], names: Sequence[str]) -> str:
    """Call ``warm(name)`` (a module-level function: it is pickled to the
    workers) for every name, each in its own process, all at once.

    Parameters
    ----------
    warm : callable
        Compiles (or loads from the disk cache) the kernel ``name`` in the
        calling process; returns the CPU seconds it spent.
    names : sequence of str

    Returns
    -------
    str
        One line: the wall seconds of the whole and each kernel's CPU
        seconds; without numba, a line saying that nothing was compiled.
    """
    if find_spec("numba") is None:
        return "compiled kernels: numba not installed, nothing to compile"
    w0 = time.perf_counter()
    with ProcessPoolExecutor(len(names)) as ex:
        cpu = list(ex.map(warm, names))
    return (f"compiled kernels ready in the disk cache: {time.perf_counter() - w0:.0f} s wall, "
            + ", ".join(f"{k} {c:.0f} CPU s" for k, c in zip(names, cpu)))
