"""The plant sub-steps of :func:`workbench.sim.tracking.simulate_tracking`, compiled (numba).

Between two control samples the 002 train is stepped ``n_sub`` times at the
plant step ``dt`` with the command held. The numpy path does this with ~15
array operations per sub-step on the whole batch; for a tuning grid (a few
hundred runs, 10-40 sub-steps per sample, 1750 samples) that Python overhead
is most of paper 002's study (issue 36, item 4: ``benchmarks/profile-36h.md``).
:func:`substeps` performs the same operations, in the same order, one run at
a time: every operation is an IEEE addition, multiplication, comparison,
minimum or maximum (no library function: the lag's ``exp`` is taken once per
run outside), so a compiled run is bit-identical to its numpy run
(``tests/test_tracking_jit.py``). The Davis resistance is the
``sympy.lambdify`` of :data:`workbench.plants.train002.DAVIS` handed to
``numba.njit``, not retyped.

Importing this module needs numba; :func:`substeps` compiles at first use
(a few seconds) into the disk cache of :mod:`workbench.sim.jit_cache`.

References
----------
.. [002] ATO target speed curve tracking with MFAC, Nanning Line 1, eqs 1-2
   (the train model of :mod:`workbench.plants.train002`).
"""
from __future__ import annotations

import numba
import sympy as sp

from ..plants import train002 as model
from .jit_cache import cached

__all__ = ["substeps"]

_JIT = dict(nogil=True, error_model="numpy")
_davis = numba.njit(inline="always", **_JIT)(
    sp.lambdify((model.v, model.c0, model.c1, model.c2), model.DAVIS, "math"))


@numba.njit(inline="always", **_JIT)
def _max(x, y):
    """``numpy.maximum`` of two floats (nan propagates, ties keep ``x``)."""
    return x if (x >= y or x != x) else y


@numba.njit(inline="always", **_JIT)
def _min(x, y):
    """``numpy.minimum`` of two floats (nan propagates, ties keep ``x``)."""
    return x if (x <= y or x != x) else y


def _substeps(n_sub, head, fifo, demand, v, s, a, work, stopped, stop_time, stop_pos,
              t, dt, brake_start, first_order, decay, gain_int, lo, hi, c0, c1, c2,
              edges, grade_acc):
    """``n_sub`` plant steps of every run from time ``t`` (state arrays updated
    in place); returns the FIFO's new head. Arguments as in
    :func:`workbench.sim.tracking.simulate_tracking`'s loop: ``fifo`` (D + 1, N),
    per-run ``decay``, ``gain_int``, ``lo``, ``hi`` (the acceleration limits
    times ``dt``), ``c0``, ``c1``, ``c2`` and ``grade_acc`` (N, sections)."""
    n = v.size
    size = fifo.shape[0]
    for i in range(n):
        h = head
        vi, si, ai, wi = v[i], s[i], a[i], work[i]
        st = stopped[i]
        for j in range(n_sub):
            fifo[h, i] = demand[i]
            h += 1
            if h == size:      # (h + 1) % size without a division
                h = 0
            A = fifo[h, i]
            if first_order:
                a_int = _min(_max((A - vi) * (1.0 - decay[i]), lo[i]), hi[i])
            else:
                a_int = A * dt + (ai - A) * gain_int[i]
                ai = A + (ai - A) * decay[i]
            sec = 0
            while sec < edges.size and edges[sec] <= si:   # searchsorted, side="right"
                sec += 1
            acc_ext = _davis(vi, c0[i], c1[i], c2[i]) + grade_acc[i, sec]
            v_new = _max(vi + a_int - acc_ext * dt, 0.0)
            wi += 0.0 if st else _max(a_int, 0.0) * vi
            si = si + (0.0 if st else 0.5 * (vi + v_new) * dt)
            vi = 0.0 if st else v_new
            t_now = t + (j + 1) * dt
            if not st and vi <= 0.0 and t_now >= brake_start:
                stop_time[i] = t_now
                stop_pos[i] = si
                st = True
        v[i], s[i], a[i], work[i] = vi, si, ai, wi
        stopped[i] = st
    return (head + n_sub) % size


#: :func:`_substeps`, compiled and kept in the disk cache.
substeps = cached(numba.njit(**_JIT)(_substeps), "tracking_substeps")
