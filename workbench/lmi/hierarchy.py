"""The Bessel-Legendre hierarchy with an automatic order (Seuret & Gouaisbaut 2015).

Point certificates (see :mod:`workbench.lmi.analysis`): each order's bound is
the largest delay at which it certifies stability.

References
----------
.. [SG15] Seuret A., Gouaisbaut F., "Hierarchy of LMI conditions for the
   stability analysis of time-delay systems", Systems & Control Letters 81,
   1-7, 2015 (Theorem 4: the bound is non-decreasing in N).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from .analysis import BesselLegendreLMI, DelayBound, certified_delay
from .core import DEFAULT_MARGIN


@dataclass(frozen=True)
class AutoOrder:
    """Result of :func:`bessel_legendre_auto`: one bound per order tried.

    ``N_reached`` is the first order whose gap to the exact margin is below
    the tolerance (None when the cap was reached first).
    """

    bounds: tuple[DelayBound, ...]
    N_reached: int | None

    @property
    def best(self) -> DelayBound:
        """The bound at ``N_reached`` (or the largest bound when not reached)."""
        if self.N_reached is not None:
            return next(b for b in self.bounds if b.N == self.N_reached)
        return max(self.bounds, key=lambda b: b.h_certified)


def bessel_legendre_auto(A, Ad, exact: float, *, gap_tol: float = 1e-4, N_max: int = 6,
                         N_through: int = 0, rel_tol: float = 1e-5,
                         margin: float = DEFAULT_MARGIN, h_hi: float | None = None,
                         guess: float | None = None, make=None) -> AutoOrder:
    """Raise the Bessel-Legendre order N = 0, 1, ... until
    ``1 - h_N / exact < gap_tol`` or N = ``N_max``.

    Orders up to ``N_through`` are computed in any case (for tables). Order 0
    starts from ``guess`` (s, optional; e.g. inside a stability window that
    does not start at 0). Each
    order's bisection starts from the previous order's bound (the hierarchy
    is non-decreasing in N). ``exact`` is the exact margin (s) from
    :mod:`workbench.margins`; with ``exact = inf`` the gap never closes.
    The hierarchy never goes backwards: when order N's own search certifies
    less than order N - 1 (an inaccurate solve there), order N reports the
    lower order's certificate (``certified_by``), which proves order N
    feasible at that delay. ``make(N)``, optional, gives order N's criterion
    (default: a new :class:`BesselLegendreLMI`; e.g. one kept for reuse).
    """
    out: list[DelayBound] = []
    reached = None
    for N in range(0, max(N_max, N_through) + 1):
        if N > N_through and (reached is not None or N > N_max):
            break
        lmi = make(N) if make else BesselLegendreLMI(A, Ad, N, margin=margin)
        b = certified_delay(lmi, rel_tol=rel_tol,
                            guess=guess, h_hi=h_hi)
        if out and b.h_certified < out[-1].h_certified:
            prev = out[-1]
            b = DelayBound(b.method, N, prev.bracket,
                           prev.certified_by if prev.certified_by is not None else prev.N)
        out.append(b)
        if b.h_certified > 0:
            guess = b.h_certified
        if (reached is None and math.isfinite(exact) and exact > 0
                and 1 - b.h_certified / exact < gap_tol):
            reached = N
    return AutoOrder(tuple(out), reached)
