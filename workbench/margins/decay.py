"""Exact decay over a delay range and the H-infinity norm of a delayed loop,
computed without any LMI.

:func:`worst_decay`: the rightmost characteristic root of
det(s I - A - A_d e^{-s h}) on a dense grid of [h_min, h_max]
(:func:`~workbench.margins.spectrum.rightmost_roots`); between grid points the
shifted equation det(s I - (A + alpha I) - beta A_d e^{-s h}) = 0, whose
imaginary-axis roots are the delays where a root crosses Re s = -alpha, is
searched for crossings (:func:`~workbench.margins.crossings.phase_crossings`)
with beta = e^{alpha h} frozen at either end of each cell: a cell is *clear*
when neither frozen equation has a crossing delay inside it. (beta varies
across a cell by e^{alpha dh}, at most 1 % with the default grid; the check is
exact at the grid points and for the frozen equations.)

:func:`hinf_norm`: sup over omega of sigma_max(G(j omega)),
G(s) = (C + D e^{-s h}) (s I - A - A_d e^{-s h})^{-1} B_w, on a log grid with
the peak refined by a bounded scalar search (the value is a lower bound of
the supremum that the refinement makes tight to the grid's resolution).

References
----------
.. [GKC03] Gu K., Kharitonov V.L., Chen J., *Stability of Time-Delay
   Systems*, Birkhauser 2003, ch. 2 (crossing directions).
.. [Mic07] Michiels W., Niculescu S.-I., *Stability and Stabilization of
   Time-Delay Systems*, SIAM 2007, ch. 1 (spectral abscissa, H-infinity of
   delay systems).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.optimize import minimize_scalar

from . import _input
from .crossings import phase_crossings
from .spectrum import rightmost_roots

__all__ = ["ExactDecay", "hinf_norm", "worst_decay", "worst_hinf"]

#: Delay grid points of the exact checks.
GRID = 61
#: Frequency grid points (log) of :func:`hinf_norm`.
OMEGA_POINTS = 600


@dataclass(frozen=True)
class ExactDecay:
    """Worst exact decay rate over a delay range.

    Attributes
    ----------
    decay : float
        min over the grid and the points of -max Re s (1/s).
    h : float
        Delay (s) where it is reached.
    point : int
        Operating point where it is reached.
    clear : bool
        Every cell is clear of crossings of Re s = -``alpha`` (module docstring);
        True also when no rate was given.
    alpha : float or None
        The rate the cells were checked at.
    """

    decay: float
    h: float
    point: int
    clear: bool
    alpha: float | None


def _cell_clear(A, Ad, alpha: float, a: float, b: float) -> bool:
    n = A.shape[0]
    for beta in (math.exp(alpha * a), math.exp(alpha * b)):
        cs = phase_crossings(A + alpha * np.eye(n), beta * Ad)
        if cs.zero_root:
            return False
        for c in cs.crossings:
            if c.next_after(a) < b:
                return False
    return True


def worst_decay(points: Sequence[tuple[np.ndarray, np.ndarray]], h_min: float, h_max: float,
                *, alpha: float | None = None, grid: int = GRID) -> ExactDecay:
    """Exact worst decay rate of x' = A_i x + A_d,i x(t - h) over h in
    [h_min, h_max] (s) and the points (module docstring).

    Parameters
    ----------
    points : sequence of (A, A_d)
    h_min, h_max : float
        Delay range (s), 0 <= h_min <= h_max.
    alpha : float, optional
        Certified rate (1/s) whose line Re s = -alpha is checked between grid
        points.
    grid : int
        Delay grid points (>= 2).

    Raises
    ------
    ValueError
        Bad matrices or range.
    """
    h_min, h_max = _input.delay(h_min, "h_min"), _input.delay(h_max, "h_max")
    if h_max < h_min:
        raise ValueError(f"h_max = {h_max!r} < h_min = {h_min!r}; expected h_min <= h_max")
    grid = _input.integer(grid, "grid", lo=2)
    hs = np.linspace(h_min, h_max, grid)
    worst, at, clear = math.inf, (h_min, 0), True
    for i, (A, Ad) in enumerate(points):
        A, Ad = _input.system(A, Ad)
        for h in hs:
            d = -rightmost_roots(A, Ad, float(h)).alpha
            if d < worst:
                worst, at = d, (float(h), i)
        if alpha is not None and clear:
            clear = all(_cell_clear(A, Ad, alpha, float(a), float(b))
                        for a, b in zip(hs[:-1], hs[1:]))
    return ExactDecay(float(worst), at[0], at[1], bool(clear), alpha)


def _sigma(A, Ad, Bw, C, D, h: float, w: float) -> float:
    s = 1j * w
    E = np.exp(-s * h)
    X = np.linalg.solve(s * np.eye(A.shape[0]) - A - Ad * E, Bw)
    return float(np.linalg.norm((C + D * E) @ X, 2))


def hinf_norm(A, Ad, Bw, C, D, h: float, *, points: int = OMEGA_POINTS) -> float:
    """sup_omega sigma_max((C + D e^{-j w h})(j w I - A - A_d e^{-j w h})^{-1} B_w)
    for a stable loop (module docstring); ``inf`` when the loop is not
    asymptotically stable at h."""
    A, Ad = _input.system(A, Ad)
    Bw, C, D = (np.atleast_2d(np.asarray(M, float)) for M in (Bw, C, D))
    h = _input.delay(h)
    if rightmost_roots(A, Ad, h).alpha >= 0:
        return math.inf
    R = float(np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2)) or 1.0
    ws = np.concatenate([[0.0], np.geomspace(1e-4 * R, 1e3 * R, points)])
    vals = np.array([_sigma(A, Ad, Bw, C, D, h, w) for w in ws])
    k = int(np.argmax(vals))
    best = float(vals[k])
    lo, hi = ws[max(k - 1, 0)], ws[min(k + 1, ws.size - 1)]
    if hi > lo:
        r = minimize_scalar(lambda w: -_sigma(A, Ad, Bw, C, D, h, w), bounds=(lo, hi),
                            method="bounded", options={"xatol": 1e-10 * hi})
        best = max(best, float(-r.fun))
    return best


def worst_hinf(points, Bw, C, D, h_min: float, h_max: float, *, grid: int = GRID
               ) -> tuple[float, float, int]:
    """The largest :func:`hinf_norm` over the delay grid and the points:
    (norm, delay (s), point)."""
    out = (-math.inf, h_min, 0)
    for i, (A, Ad) in enumerate(points):
        for h in np.linspace(h_min, h_max, grid):
            v = hinf_norm(A, Ad, Bw, C, D, float(h))
            if v > out[0]:
                out = (v, float(h), i)
    return out
