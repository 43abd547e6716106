"""Fixed-step simulation of x' = A x + A_d x(t - h(t)) with a time-varying delay.

The time-domain check of the interval certificates of
:mod:`workbench.lmi.varying`: a delay that moves inside the certified set
(a triangle wave between h1 and h2 with slope mu, or, for an unknown
derivative, a fast switching between h1 and h2) must give a decaying state.

Method: Heun's method (explicit trapezoid) on the grid t_k = k dt, the
delayed state x(t - h(t)) read from the piecewise linear interpolation of the
stored grid values; when t - h(t) falls inside the current step (small
delays) the interpolation uses the predictor value at t_{k+1}. The initial
function is constant, x(theta) = x0 for theta <= 0. Second order for smooth
h(t) where the solution is smooth (first order across switching instants).

References
----------
.. [BZ03] Bellen A., Zennaro M., *Numerical Methods for Delay Differential
   Equations*, Oxford 2003, ch. 3-4 (continuous extensions, time-dependent
   delays).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np


def triangle_delay(h1: float, h2: float, mu: float) -> Callable[[float], float]:
    """h(t) rising from h1 to h2 with slope mu, then falling back with slope
    -mu, periodically: |h'(t)| = mu, h(0) = h1.

    Parameters
    ----------
    h1, h2 : float
        Delay bounds (s), 0 <= h1 < h2.
    mu : float
        Slope (dimensionless), > 0.
    """
    if not (0 <= h1 < h2 and mu > 0):
        raise ValueError(f"h1 = {h1!r}, h2 = {h2!r}, mu = {mu!r}; expected 0 <= h1 < h2 (s) "
                         "and mu > 0")
    rise = (h2 - h1) / mu                      # s

    def h(t: float) -> float:
        u = math.fmod(t, 2 * rise)
        return h1 + mu * (u if u <= rise else 2 * rise - u)
    return h


def switching_delay(h1: float, h2: float, period: float) -> Callable[[float], float]:
    """h(t) = h2 on the first half of each period, h1 on the second half
    (jumps: an unknown, unbounded derivative).

    Parameters
    ----------
    h1, h2 : float
        Delay values (s), 0 <= h1 <= h2.
    period : float
        Switching period (s), > 0.
    """
    if not (0 <= h1 <= h2 and period > 0):
        raise ValueError(f"h1 = {h1!r}, h2 = {h2!r}, period = {period!r}; expected "
                         "0 <= h1 <= h2 (s) and a positive period (s)")

    def h(t: float) -> float:
        return h2 if math.fmod(t, period) < 0.5 * period else h1
    return h


@dataclass(frozen=True)
class VaryingDelayRun:
    """One simulated run.

    Attributes
    ----------
    t : (K,) numpy.ndarray
        Time (s), every ``record_every`` steps.
    x : (n, K) numpy.ndarray
        State.
    h : (K,) numpy.ndarray
        Delay h(t) (s).
    dt : float
        Step (s).
    """

    t: np.ndarray
    x: np.ndarray
    h: np.ndarray
    dt: float

    def decay(self) -> float:
        """|x(T)| / |x(0)| (Euclidean norms)."""
        return float(np.linalg.norm(self.x[:, -1]) / np.linalg.norm(self.x[:, 0]))


def simulate_varying_delay(A, Ad, delay: Callable[[float], float], h_max: float, x0,
                           t_end: float, dt: float, *, record_every: int = 1
                           ) -> VaryingDelayRun:
    """Simulate x' = A x + A_d x(t - h(t)), x(theta) = x0 for theta <= 0.

    Parameters
    ----------
    A, Ad : (n, n) array_like
    delay : callable
        h(t) (s), with 0 <= h(t) <= h_max.
    h_max : float
        Largest delay (s) (sizes the history; a larger h(t) raises).
    x0 : (n,) array_like
        Constant initial function.
    t_end, dt : float
        Horizon and step (s).
    record_every : int
        Keep one step in this many.

    Returns
    -------
    VaryingDelayRun
    """
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    if not (dt > 0 and t_end > 0 and h_max >= 0):
        raise ValueError(f"dt = {dt!r}, t_end = {t_end!r}, h_max = {h_max!r}; expected "
                         "positive step and horizon (s), h_max >= 0 (s)")
    n_steps = int(round(t_end / dt))
    X = np.empty((n_steps + 1, A.shape[0]))
    X[0] = np.asarray(x0, float).reshape(-1)
    H = np.empty(n_steps + 1)

    def delayed(s: float, k: int, pred: np.ndarray | None) -> np.ndarray:
        """x(s) for s <= t_{k+1}: initial function, grid interpolation, or
        the predictor on the current step."""
        if s <= 0:
            return X[0]
        q = s / dt
        i = min(int(q), k)
        f = q - i
        right = X[i + 1] if i + 1 <= k else pred
        if right is None or f <= 0:
            return X[i]
        return (1 - f) * X[i] + f * right

    def rate(t: float, x: np.ndarray, k: int, pred) -> tuple[np.ndarray, float]:
        h = delay(t)
        if not 0 <= h <= h_max + 1e-12:
            raise ValueError(f"h({t!r}) = {h!r}; expected a delay in [0, h_max = {h_max!r}] (s)")
        return A @ x + Ad @ delayed(t - h, k, pred), h

    for k in range(n_steps):
        t = k * dt
        f1, H[k] = rate(t, X[k], k, None)
        pred = X[k] + dt * f1
        f2, _ = rate(t + dt, pred, k, pred)
        X[k + 1] = X[k] + 0.5 * dt * (f1 + f2)
    H[n_steps] = delay(n_steps * dt)
    idx = np.arange(0, n_steps + 1, record_every)
    if idx[-1] != n_steps:
        idx = np.append(idx, n_steps)
    return VaryingDelayRun(idx * dt, X[idx].T, H[idx], dt)
