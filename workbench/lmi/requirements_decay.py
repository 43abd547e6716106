"""The decay rate of a given gain over a delay range, by Bessel-Legendre cells.

With z = e^{alpha t} x, the loop x' = A x + A_d x(t - h) becomes
z' = (A + alpha I) z + e^{alpha h} A_d z(t - h): exponential stability of the
latter at h proves that every solution of the former decays at least like
e^{-alpha t}. The delayed matrix beta A_d, beta = e^{alpha h}, moves with h,
so [0, H] is cut into cells [h_a, h_b] and each cell is certified for every
(h, beta) in the box [h_a, h_b] x [e^{alpha h_a}, e^{alpha h_b}] (which
contains the curve beta = e^{alpha h}) by one Bessel-Legendre certificate
(order N, :class:`~workbench.lmi.analysis.BesselLegendreLMI`) with its
variables shared by the four corners:

* for a fixed beta, h Phi_N(h) = X + h Y + h^2 F'RF with R >= 0 is convex in
  h (:mod:`workbench.lmi.interval`);
* for a fixed h it is convex in beta: X and Y are affine in A_d and
  F = A e_0 + beta A_d e_1 enters through F'RF, R >= 0.

So h Phi_N(h, beta) is below the convex combination of its values at the
corners, and the cell is certified when the four corner blocks are
(h_a = 0: the interval module's limit block at both beta ends). The
argument needs the shared variables to be one functional in one set of
coordinates and one time unit at both beta ends: the analysis LMIs choose
their own balancing, modal coordinates and unit from (A, A_d)
(:mod:`workbench.lmi.coordinates`), so a cell fixes them once, from its
middle beta, and both ends are written and re-checked (on the caller's
loop) in that frame. This is
less conservative than the descriptor/Jensen synthesis LMI of
:mod:`workbench.lmi.requirements` and it is the certificate of the decay of
the returned gain.

References
----------
.. [SG15] Seuret A., Gouaisbaut F., "Hierarchy of LMI conditions for the
   stability analysis of time-delay systems", SCL 81 (2015) 1-7.
.. [Fri14] Fridman E., *Introduction to Time-Delay Systems*, Birkhauser 2014,
   sec. 3.6 (the change of variables z = e^{alpha t} x).
"""
from __future__ import annotations

import copy
import dataclasses
import math
import time
from typing import Sequence

import numpy as np

from .analysis import BesselLegendreLMI
from .coordinates import congruence, original
from .core import (DEFAULT_MARGIN, Block, Bracket, MarginLMI, Outcome, Step, bisect_delay,
                   relative_margins)
from .interval import IntervalLMI
from .scaling import balancing

__all__ = ["CellLMI", "decay_cells", "certified_decay"]

#: Largest alpha (h_b - h_a) of a cell: e^{alpha h} varies by at most 10 %
#: across a cell.
CELL_LOG_SPAN = 0.1
#: Caps (issue 32): cells per point at one rate, and wall-clock seconds of a
#: decay search; beyond either a rate is INCONCLUSIVE with the cap as its reason.
MAX_CELLS, MAX_SECONDS = 400, 600.0


class CellLMI(MarginLMI):
    """One Bessel-Legendre certificate for every (h, beta) of a cell (module
    docstring). ``solve_at(h_b)`` decides the cell [h_a, h_b].

    Parameters
    ----------
    A, Ad : (n, n) arrays
        The shifted system's A + alpha I and the undelayed A_d.
    betas : (float, float)
        e^{alpha h_a} and e^{alpha h_b}.
    h_a : float
        Lower end of the cell (s), 0 allowed.
    N : int
        Bessel-Legendre order.
    """

    def __init__(self, A, Ad, betas: tuple[float, float], h_a: float, N: int = 2, **kw):
        margin = kw.get("margin", DEFAULT_MARGIN)
        # one frame (balancing T, modal coordinates L, time unit) for both ends, fixed at
        # the cell's middle beta: the variables are shared, so they must mean the same
        # functional at every (h, beta) of the cell (the convexity argument above)
        self.frame = BesselLegendreLMI(A, math.sqrt(betas[0] * betas[1]) * np.asarray(Ad, float),
                                       N, margin=margin)
        self.ends = [IntervalLMI(_at_beta(self.frame, Ad, b), from_zero=h_a == 0)
                     for b in betas]
        self.h_a = float(h_a)
        super().__init__(**kw)
        if h_a > 0:
            self.set_parameters(h_a=h_a, iota_a=1.0 / h_a)

    def recheck(self, values, h: float) -> dict[str, float]:
        """Margins re-evaluated with numpy on the caller's loop at both betas
        (:func:`~workbench.lmi.coordinates.recheck_original`, per end)."""
        L = self.frame.L
        if L is None:
            return MarginLMI.recheck(self, values, h)
        twin = copy.copy(self)
        twin.ends = []
        for end in self.ends:
            base = copy.copy(end.base)
            base.A, base.Ad = base.A0, base.Ad0
            twin.ends.append(copy.copy(end))
            twin.ends[-1].base = base
        blocks = MarginLMI.evaluate_blocks(twin, original(self.frame, values), h)
        return relative_margins([Block(b.name, congruence(np.asarray(b.matrix, float), L),
                                       b.sense) for b in blocks])

    def parameters(self):
        return () if self.h_a == 0 else ("h_a", "iota_a")

    def variables(self):
        return self.ends[0].variables()

    def blocks(self, x, p, bmat):
        out = []
        for tag, end in zip(("lo", "hi"), self.ends):
            for b in end.blocks(x, p, bmat):
                if "@" in b.name or tag == "lo":
                    out.append(dataclasses.replace(b, name=f"{b.name}/beta_{tag}"))
        return out


def _at_beta(frame, Ad, beta: float):
    """The criterion ``frame`` for the delayed matrix beta A_d, in ``frame``'s
    balancing, coordinates and time unit (T, L and the unit are not recomputed)."""
    lmi = copy.copy(frame)
    lmi.Ad0 = np.diag(1.0 / np.diag(frame.T)) @ (beta * np.asarray(Ad, float)) @ frame.T
    lmi.Ad = lmi.Ad0 if frame.L is None else np.linalg.solve(frame.L, lmi.Ad0 @ frame.L)
    return lmi


def decay_cells(alpha: float, h_lo: float, H: float) -> list[tuple[float, float]]:
    """Equal cells covering [h_lo, H] with alpha x width <= :data:`CELL_LOG_SPAN`."""
    k = max(1, math.ceil(alpha * (H - h_lo) / CELL_LOG_SPAN))
    edges = np.linspace(h_lo, H, k + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def _decide(points, alpha: float, h_lo: float, H: float, N: int, margin: float,
            deadline: float = math.inf) -> Step:
    """CERTIFIED when every cell of every point is (the last cell's step is
    returned); otherwise the first cell that was not. INCONCLUSIVE past
    :data:`MAX_CELLS` cells or the ``deadline`` (``time.perf_counter()``)."""
    last = None
    seconds = 0.0
    k = math.ceil(alpha * (H - h_lo) / CELL_LOG_SPAN)      # the count of decay_cells
    if not k <= MAX_CELLS:
        return Step(alpha, Outcome.INCONCLUSIVE, f"error: {k:g} delay cells at rate "
                    f"{alpha:.3g} 1/s, above the cap of {MAX_CELLS}", None, {}, None, 0.0)
    cells = decay_cells(alpha, h_lo, H)
    for A, Ad in points:
        Aa = A + alpha * np.eye(A.shape[0])
        for a, b in cells:
            if time.perf_counter() > deadline:
                return Step(alpha, Outcome.INCONCLUSIVE, f"error: wall-clock cap of "
                            f"{MAX_SECONDS:g} s of the decay search reached", None, {}, None,
                            seconds)
            lmi = CellLMI(Aa, Ad, (math.exp(alpha * a), math.exp(alpha * b)), a, N,
                          margin=margin)
            step = lmi.solve_at(b)
            seconds += step.seconds
            if step.outcome is not Outcome.CERTIFIED:
                return dataclasses.replace(step, h=alpha, seconds=seconds)
            last = step
    return dataclasses.replace(last, h=alpha, seconds=seconds)


def certified_decay(points: Sequence[tuple[np.ndarray, np.ndarray]], *, h_lo: float, H: float,
                    alpha_hi: float, N: int = 2, margin: float = DEFAULT_MARGIN,
                    rel_tol: float = 1e-3, guess: float | None = None) -> Bracket:
    """Bracket of the decay rate (1/s) certified for x' = A_i x + A_d,i x(t - h),
    every constant delay in [h_lo, H] (s) and every point (A_i, A_d,i).

    A certified alpha (the bracket's ``h_certified``; the bracket's h is the
    rate) holds for every cell of every point; the bisection is the shared
    :func:`~workbench.lmi.core.bisect_delay` on alpha in
    [1e-5 alpha_hi, alpha_hi]. Coordinates are balanced per point by a
    power-of-two diagonal (exact) from A, and, when that does not certify a
    rate, from |A| + |A_d| (both are similarity transforms of the same loop,
    so either certificate proves the rate; solvers differ on them).
    """
    if not (0 <= h_lo < H < math.inf):
        raise ValueError(f"delay range [{h_lo!r}, {H!r}] s; expected 0 <= h_min < h_max < inf")
    bal: list[list] = [[], []]        # two exact power-of-two scalings of every point
    for A, Ad in points:
        A, Ad = np.asarray(A, float), np.asarray(Ad, float)
        for k, M in enumerate((A, np.abs(A) + np.abs(Ad))):   # A alone may be triangular
            T = balancing(M)
            Tinv = np.diag(1.0 / np.diag(T))
            bal[k].append((Tinv @ A @ T, Tinv @ Ad @ T))

    deadline = time.perf_counter() + MAX_SECONDS

    def decide(a: float) -> Step:
        step = _decide(bal[0], a, h_lo, H, N, margin, deadline)
        if step.outcome is Outcome.CERTIFIED:
            return step
        other = _decide(bal[1], a, h_lo, H, N, margin, deadline)
        return other if other.outcome is Outcome.CERTIFIED else step

    return bisect_delay(decide, h_lo=1e-5 * alpha_hi,
                        h_hi=alpha_hi, rel_tol=rel_tol, guess=guess, max_seconds=MAX_SECONDS)
