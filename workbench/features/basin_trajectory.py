"""Trajectories of a closed loop around its basin estimate, and their fates.

General: the loop is a numeric vector field ``fn(*x) -> x'`` (any state
dimension), the certified set a predicate on states, the escape a set of
terminal events (leaving a domain box, a state reaching a limit). Used by the
delay-feedback basin (:mod:`workbench.features.basin`) and by every basin whose
closed loop is given as a vector field.

A trajectory's *fate*: "converges" when a solver step lies in the certified
set (from which the loop converges), the *escaped* word (e.g. "leaves the
domain", "diverges") when a terminal event fired, the step failed or the state
went non-finite, else "undecided" within the horizon.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Trajectory:
    """A trajectory of the closed loop: start, drawn path (N, n) and fate."""

    x0: tuple
    path: np.ndarray = field(repr=False)
    fate: str


def integrate(fn, x0, T: float, *, events=(), rtol: float = 1e-8, max_step: float = math.inf,
              dense: bool = False, t0: float | None = None):
    """``solve_ivp`` (Radau, atol 1e-10) of x' = fn(*x) from x0 over [0, T], or of
    the time-varying x' = fn(t, *x) over [t0, t0 + T] when ``t0`` is given.

    An evaluation of ``fn`` that overflows or divides by zero gives NaN, which
    ends the step as failed (status != 0). Raises ValueError or LinAlgError
    when Radau's Jacobian is not finite at the start (see :func:`trajectory`).
    """
    from scipy.integrate import solve_ivp

    def rhs(t, x):
        try:
            return list(fn(*x) if t0 is None else fn(t, *x))
        except (OverflowError, ValueError, ZeroDivisionError):
            return [math.nan] * len(x)

    kw = {} if max_step == math.inf else {"max_step": max_step}
    span = (0.0, T) if t0 is None else (t0, t0 + T)
    with np.errstate(all="ignore"):
        return solve_ivp(rhs, span, np.asarray(x0, float), method="Radau", rtol=rtol,
                         atol=1e-10, events=list(events) or None, dense_output=dense, **kw)


def escaped(sol) -> bool:
    """A terminal event fired (status 1), the step failed (-1) or a state is not finite."""
    return bool(sol.status != 0 or not np.all(np.isfinite(sol.y)))


def drawn_path(sol, inside, dt: float) -> np.ndarray:
    """The dense output of ``sol`` at multiples of ``dt`` up to its end time (plus
    the end point), cut after the first grid point where ``inside`` holds when
    it is given. The adaptive steps themselves move with the last bits of the
    inputs, and a polyline with other vertices antialiases differently; the
    dense output at fixed times moves far less (tests/test_basin_perturb.py)."""
    t_end = float(sol.t[-1])
    ts = np.arange(0.0, t_end, dt)
    path = np.vstack([sol.sol(ts).T, sol.y[:, -1]]) if len(ts) else sol.y.T[-1:]
    if inside is not None:
        hit = inside(path[:-1]) if len(path) > 1 else np.zeros(0, bool)
        if hit.any():
            path = path[:int(np.argmax(hit)) + 1]
    return path


def trajectory(fn, x0, T: float, inside, *, events=(), escape: str = "leaves the domain",
               rtol: float = 1e-8, max_step: float = math.inf, path_dt: float | None = None
               ) -> Trajectory:
    """One trajectory of x' = fn(*x) from x0 over [0, T] (Radau, rtol 1e-8) and its fate.

    Parameters
    ----------
    fn : callable
        The closed loop's numeric vector field.
    x0 : sequence of float
    T : float
        Horizon (s).
    inside : callable
        (N, n) states -> (N,) bool: in the certified set.
    events : sequence of callable
        ``solve_ivp`` events (terminal ones end the trajectory: the escape).
    escape : str
        Fate word of an escaped trajectory (:func:`escaped`).
    rtol, max_step : float
        Radau's relative tolerance and largest step.
    path_dt : float, optional
        Draw the dense output every ``path_dt`` (:func:`drawn_path`, cut at the
        certified set for "converges") instead of the solver's own steps.

    A start where Radau's Jacobian is not finite (the vector field overflows
    near x0) is "undecided", its path the start alone.
    """
    try:
        sol = integrate(fn, x0, T, events=events, rtol=rtol, max_step=max_step,
                        dense=path_dt is not None)
    except (ValueError, np.linalg.LinAlgError):
        return Trajectory(tuple(float(v) for v in x0), np.asarray([x0], float), "undecided")
    path = sol.y.T
    if inside(path).any():
        fate, cut = "converges", inside
    else:
        fate, cut = (escape if escaped(sol) else "undecided"), None
    drawn = path if path_dt is None else drawn_path(sol, cut, path_dt)
    return Trajectory(tuple(float(v) for v in x0), drawn, fate)


def decays(path, V) -> bool:
    """V never rose along the path (1e-6 relative) and ends below 1 % of its start."""
    v = V(path)
    return bool(np.all(np.isfinite(v)) and np.all(np.diff(v) <= 1e-6 * v[0])
                and v[-1] <= 0.01 * v[0])


def limit_event(index: int, limit: float, offset: float = 0.0):
    """Terminal ``solve_ivp`` event: |x[index] + offset| reaches ``limit`` (e.g.
    a state leaving the range its model holds on, in shifted coordinates)."""
    def reached(t, x):
        return limit - abs(x[index] + offset)
    reached.terminal = True
    return reached


def time_varying_fate(fn, x0, t0: float, T: float, settled, *, events=(), rtol: float = 1e-8,
                      max_step: float = math.inf, escape: str = "diverges",
                      settled_word: str = "tracks") -> tuple[str, float | None]:
    """Fate of the time-varying loop x' = fn(t, *x) from x0 at t0 over [t0, t0 + T]
    (Radau) and when it escaped (time after t0): the ``escape`` word when a
    terminal event fired or the step failed, ``settled_word`` when
    ``settled(t, x)`` holds at the end, else "undecided" (no time)."""
    sol = integrate(fn, x0, T, events=events, rtol=rtol, max_step=max_step, t0=t0)
    if escaped(sol):
        return escape, float(sol.t[-1] - t0)
    return (settled_word if settled(sol.t[-1], sol.y[:, -1]) else "undecided"), None
