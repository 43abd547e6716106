"""An independent check of a sampled loop's plant mesh: the input the plant
received in a window (piecewise constant: held commands) replayed open loop
into :func:`scipy.integrate.solve_ivp` (``method="Radau"``, an implicit,
stiffly accurate Runge-Kutta method of order 5), restarted at each change
of the input from its own previous end point, and compared with the mesh at
every mesh point (issue 20, made general in issue 35).

A record is an array with rows (t, x_1, ..., x_n, u): the state at the end
of a sub-step and the input held over the sub-step ending at t; its first
row is the initial state. :func:`replay_windows` cuts windows out of the
records of one or more runs (one record per run, spanning its windows) and
replays each; :func:`sample_windows` places windows of a given length at
events of the runs, :func:`reusing` takes a record a run made anyway. Test on a system of no paper: ``tests/test_rate_sweep.py``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

__all__ = ["replay", "window", "WindowReplay", "WindowCheck", "replay_windows", "sample_windows",
           "reusing", "largest"]


@dataclass(frozen=True)
class WindowReplay:
    """One window replayed: its name, its rows of the record and
    :func:`replay`'s per-state differences and pieces."""

    name: str
    rec: np.ndarray
    d_abs: tuple
    d_rel: tuple
    pieces: int

    def check(self, key, span: int = 0) -> "WindowCheck":
        """The window in numbers (:class:`WindowCheck`), ``key`` the run's
        (a rate, say), the range of state ``span`` (0: the first)."""
        rec, x = self.rec, self.rec[:, 1 + span]
        return WindowCheck(key, self.name, float(rec[0, 0]), float(rec[-1, 0]),
                           float(x.min()), float(x.max()), self.pieces, len(rec), self.d_abs,
                           self.d_rel)


@dataclass(frozen=True)
class WindowCheck:
    """A replayed window without its record: the run's ``key``, the window's
    name, its first and last times, the range [lo, hi] of one state over it,
    the input pieces and mesh points replayed, and per state the largest
    absolute and relative differences (:meth:`WindowReplay.check`)."""

    key: object
    name: str
    t0: float
    t1: float
    lo: float
    hi: float
    pieces: int
    points: int
    d_abs: tuple
    d_rel: tuple


def largest(checks) -> tuple:
    """(abs, rel): per state, the largest absolute and relative differences
    of the :class:`WindowCheck` ``checks`` (at least one)."""
    return tuple(tuple(map(max, zip(*(getattr(c, k) for c in checks))))
                 for k in ("d_abs", "d_rel"))


def window(rec: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """The rows of a mesh record with t0 <= t <= t1: what a run recording
    only that window records (when the mesh does not depend on where the
    record ends)."""
    return rec[(rec[:, 0] >= t0) & (rec[:, 0] <= t1)]


def sample_windows(names, starts, runs, length: float, shift: float = 0.0) -> tuple:
    """((name, t0 - shift, t0 + length - shift, run), ...): windows of
    ``length`` s of run ``runs[i]`` from ``starts[i]`` (one per name; a start
    of NaN, an event not reached, is left out), for :func:`replay_windows`.

    ``shift``: every window starts and ends this much earlier. Half a mesh
    step keeps a window whose ends fall on mesh points (sample times, say)
    from holding those points or not by the last bit of its start."""
    return tuple((name, t0 - shift, t0 + length - shift, run)
                 for name, t0, run in zip(names, starts, runs) if not math.isnan(t0))


def reusing(have: Mapping, record: Callable, margin: float = 0.0) -> Callable:
    """A ``record`` callback for :func:`replay_windows` that takes a record
    made already (``have``: run -> record or None) when it holds [a, b +
    ``margin``] (the rows up to b no longer depend on where the run ended)
    and calls ``record(run, a, b)`` otherwise."""
    def rec(run, a, b):
        got = have.get(run)
        if got is not None and len(got) and got[0, 0] <= a and b + margin <= got[-1, 0]:
            return got
        return record(run, a, b)
    return rec


def replay_windows(rhs: Callable, windows, record: Callable, rtol: float, atol) -> tuple:
    """Replay windows of runs against Radau.

    Parameters
    ----------
    rhs : callable
        As for :func:`replay`.
    windows : iterable
        ((name, t0, t1, run), ...): a window of run ``run`` (any key).
    record : callable
        ``record(run, a, b)`` -> a mesh record of ``run`` holding every row
        with a <= t <= b (one call per run, [a, b] spanning its windows).
    rtol, atol
        As for :func:`replay`.

    Returns
    -------
    tuple of WindowReplay
        In the order of ``windows``; a window with fewer than two rows is
        left out.
    """
    windows = list(windows)
    recs = {}
    for run in dict.fromkeys(w[3] for w in windows):
        mine = [(a, b) for _, a, b, r in windows if r == run]
        recs[run] = record(run, min(a for a, _ in mine), max(b for _, b in mine))
    out = []
    for name, a, b, run in windows:
        rec = window(recs[run], a, b)
        if len(rec) >= 2:
            out.append(WindowReplay(name, rec, *replay(rhs, rec, rtol, atol)))
    return tuple(out)


def replay(rhs: Callable, rec: np.ndarray, rtol: float, atol) -> tuple:
    """Replay the mesh record ``rec`` against Radau from its first row.

    Parameters
    ----------
    rhs : callable
        ``rhs(u)`` -> ``f(t, x)``, the right-hand side under the constant
        input u.
    rec : ndarray
        Rows (t, x_1, ..., x_n, u).
    rtol, atol
        The tolerances of :func:`scipy.integrate.solve_ivp`.

    Returns
    -------
    (abs, rel, pieces)
        Per state, the largest |x_mesh - x_Radau| and |x_mesh - x_Radau| /
        x_mesh (tuples; NaN when Radau fails), and the input pieces replayed.
    """
    from scipy.integrate import solve_ivp
    n_x = rec.shape[1] - 2
    x = rec[0, 1:1 + n_x].copy()
    d_abs, d_rel = [0.0] * n_x, [0.0] * n_x
    i, n, pieces = 1, len(rec), 0
    while i < n:
        j = i
        while j + 1 < n and rec[j + 1, -1] == rec[i, -1]:
            j += 1
        ts = rec[i:j + 1, 0]
        sol = solve_ivp(rhs(rec[i, -1]), (rec[i - 1, 0], ts[-1]), x, method="Radau",
                        t_eval=ts, rtol=rtol, atol=atol)
        if not sol.success:
            return (np.nan,) * n_x, (np.nan,) * n_x, pieces
        for k in range(n_x):
            diff = np.abs(sol.y[k] - rec[i:j + 1, 1 + k])
            d_abs[k] = max(d_abs[k], float(np.max(diff)))
            with np.errstate(divide="ignore", invalid="ignore"):    # a state through 0
                d_rel[k] = max(d_rel[k], float(np.max(diff / rec[i:j + 1, 1 + k])))
        x = sol.y[:, -1]
        i, pieces = j + 1, pieces + 1
    return tuple(d_abs), tuple(d_rel), pieces
