"""LMI certificates next to exact answers: the layer that calls both.

:mod:`workbench.lmi` proves bounds; :mod:`workbench.margins` computes exact
delay margins without any LMI. Neither imports the other, and no LMI search
is steered by an exact answer. This module runs both on the same loop and
returns them side by side for the studies to compare and report.

- :func:`check_gain`: a given K at every operating point — stable at h = 0?,
  the exact margin of x' = A x + B K x(t - h), and the Bessel-Legendre
  certified bound (a point certificate at that delay).
- :func:`check_tight`: the same for a Wirtinger-synthesised gain, plus
  python-control's single-input margin.
- :func:`decay_rate_bound`: the decay-rate certificate and the spectral
  abscissa at the certified delay.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .lmi.core import DEFAULT_MARGIN, Bracket, Outcome
from .lmi.robust import decay_rate_bracket, gain_delay_bound
from .margins import DelayMargin, delay_margin_eig, delay_margin_siso, spectral_abscissa


@dataclass(frozen=True)
class PointCheck:
    """A gain checked at one operating point.

    Attributes
    ----------
    stable_at_zero : bool
        A + B K Hurwitz (False: the loop is unstable without delay — loud).
    exact : DelayMargin
        Exact margin of x' = A x + B K x(t-h).
    h_certified : float
        Bessel-Legendre (order N) certified bound with this K (s); 0 when
        the loop is unstable at h = 0.
    N : int
    """

    stable_at_zero: bool
    exact: DelayMargin
    h_certified: float
    N: int


def check_gain(points, K, *, N: int = 2, margin: float = DEFAULT_MARGIN,
               rel_tol: float = 1e-4, h_hi: float | None = None) -> tuple[PointCheck, ...]:
    """Check a given K at every point: exact margin and certified BL bound.

    Parameters
    ----------
    points : sequence of (A, B)
        Operating points (linearisations).
    K : array_like
        State-feedback gain, u = K x(t - h).
    N : int
        Bessel-Legendre order.
    margin : float
        Relative LMI margin.
    rel_tol, h_hi : float
        Bisection tolerance and cap (s).

    Returns
    -------
    tuple of PointCheck
        One per point, in order.
    """
    K = np.atleast_2d(np.asarray(K, float))
    out = []
    for A, B in points:
        exact = delay_margin_eig(A, np.asarray(B, float) @ K)
        stable = exact.reason != "unstable-at-zero-delay"
        h = 0.0
        if stable:
            h = gain_delay_bound(A, B, K, N=N, margin=margin, rel_tol=rel_tol,
                                 h_hi=h_hi).h_certified
        out.append(PointCheck(stable, exact, h, N))
    return tuple(out)


@dataclass(frozen=True)
class TightCheck:
    """Independent checks of a synthesised gain (see :func:`check_tight`).

    Attributes
    ----------
    check : PointCheck
        Bessel-Legendre analysis bound and exact margin with K.
    exact_siso : DelayMargin or None
        Exact margin from python-control's crossovers (single input only).
    """

    check: PointCheck
    exact_siso: DelayMargin | None


def check_tight(A, B, K, *, N: int = 2, margin: float = DEFAULT_MARGIN,
                h_hi: float | None = None) -> TightCheck:
    """:func:`check_gain` at one point plus the single-input exact margin."""
    B = np.asarray(B, float).reshape(np.shape(A)[0], -1)
    (check,) = check_gain([(A, B)], K, N=N, margin=margin, h_hi=h_hi)
    siso = delay_margin_siso(A, B, K) if B.shape[1] == 1 else None
    return TightCheck(check, siso)


@dataclass(frozen=True)
class DecayRate:
    """Largest h with exponential stability of rate alpha certified.

    ``abscissa`` is the spectral abscissa of the delay system at
    ``bracket.h_certified`` (must be <= -alpha for the certificate to agree).
    """

    alpha: float
    N: int
    bracket: Bracket
    abscissa: float | None


def decay_rate_bound(A, Ad, alpha: float, *, N: int = 2, margin: float = DEFAULT_MARGIN,
                     rel_tol: float = 1e-4, h_hi: float | None = None) -> DecayRate:
    """Decay-rate certificate (:func:`~workbench.lmi.robust.decay_rate_bracket`)
    and the spectral abscissa of x' = A x + A_d x(t - h) at its delay."""
    br = decay_rate_bracket(A, Ad, alpha, N=N, margin=margin, rel_tol=rel_tol, h_hi=h_hi)
    sa = spectral_abscissa(A, Ad, br.h_certified) if br.outcome is Outcome.CERTIFIED else None
    return DecayRate(alpha, N, br, sa)
