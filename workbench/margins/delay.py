"""Exact delay margin, stability windows and the cross-check of two methods.

See the package docstring of :mod:`workbench.margins` for definitions and
references; crossings come from :mod:`workbench.margins.crossings`.
"""
from __future__ import annotations

import enum
import math
import warnings
from dataclasses import dataclass
from typing import Literal

import numpy as np

from . import _input
from .crossings import Crossing, CrossingSet, kronecker_crossings, phase_crossings

#: Default relative tolerance within which the two exact methods must agree.
AGREEMENT_RTOL = 1e-8
#: Largest n for which :func:`exact_margin` runs the O(n^6) Kronecker cross-check
#: by default.
KRONECKER_MAX_N = 14
#: Two crossing delays closer than this fraction are one event.
EVENT_RTOL = 1e-10
#: Largest number of crossing delays below the horizon of :func:`stability_windows`.
MAX_EVENTS = 1_000_000


@dataclass(frozen=True)
class DelayMargin:
    """Exact delay margin with the reason for its value.

    Attributes
    ----------
    h : float
        Exact margin (s); ``math.inf`` or ``0.0`` in the special cases.
    omega : float or None
        Crossing frequency (rad/s) at h.
    reason : str
        ``"crossing"``, ``"delay-independent"`` (no crossing: stable for every
        delay) or ``"unstable-at-zero-delay"``.
    method : str
    crossings : tuple[Crossing, ...]
        Every imaginary-axis crossing found (empty for the single-input method).
    """

    h: float
    omega: float | None
    reason: str
    method: str
    crossings: tuple[Crossing, ...] = ()


def is_hurwitz(M) -> bool:
    """True when every eigenvalue of the square matrix ``M`` has a negative real part."""
    M = _input.square(M, "M")
    return bool(np.max(np.linalg.eigvals(M).real) < 0)


def _margin(A, Ad, cs: CrossingSet, method: str) -> DelayMargin:
    if cs.zero_root or not np.max(np.linalg.eigvals(A + Ad).real) < 0:
        return DelayMargin(0.0, None, "unstable-at-zero-delay", method, cs.crossings)
    if not cs.crossings:
        return DelayMargin(math.inf, None, "delay-independent", method, ())
    first = min(cs.crossings, key=lambda c: c.h0)
    return DelayMargin(float(first.h0), first.omega, "crossing", method, cs.crossings)


def delay_margin_eig(A, Ad) -> DelayMargin:
    """Exact delay margin by the Chen-Gu-Nett eigenvalue method [CGN95].

    j w is a root at delay h iff det(j w I - A - A_d z) = 0 with z = e^{-j w h};
    the unit-circle eigenvalues z of the 2 n^2 pencil
    z^2 (A_d (x) I) + z (A (+) A) + (I (x) A_d) give every candidate, each
    polished by Newton's method on Re lambda(A + A_d e^{-j theta}) = 0.
    Cost O(n^6): use for n < 15, or :func:`delay_margin_sweep`.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices of x' = A x + A_d x(t - h) (1/s).

    Returns
    -------
    DelayMargin
        h* (s) and the crossing frequency (rad/s).

    Raises
    ------
    ValueError
        Non-square, mismatched, empty, complex or non-finite matrices.
    """
    A, Ad = _input.system(A, Ad)
    return _margin(A, Ad, kronecker_crossings(A, Ad), "Chen-Gu-Nett eigenvalue")


def delay_margin_sweep(A, Ad, *, grid: int | None = None) -> DelayMargin:
    """Exact delay margin by a phase sweep following every eigenvalue branch.

    The phase theta in [0, pi] is swept; every eigenvalue branch of
    A + A_d e^{-j theta} is followed from grid point to grid point by its
    first-order prediction, intervals are halved until each branch is clear of
    the imaginary axis or crosses it once, and each crossing is polished by
    safeguarded Newton on Re lambda(theta) = 0 with
    d lambda / d theta = y^H (-j A_d e^{-j theta}) x / (y^H x) [GKC03, sec. 2.3].
    Independent of :func:`delay_margin_eig` (n x n eigenproblems only), cost
    O(n^3) per grid point.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices of x' = A x + A_d x(t - h) (1/s).
    grid : int, optional
        Initial number of phase intervals on [0, pi] (default 32 + 4 n; >= 4).

    Returns
    -------
    DelayMargin

    Raises
    ------
    ValueError
        Bad matrices (see :func:`delay_margin_eig`) or ``grid`` < 4.
    """
    A, Ad = _input.system(A, Ad)
    if grid is not None:
        grid = _input.integer(grid, "grid", lo=4)
    return _margin(A, Ad, phase_crossings(A, Ad, grid=grid),
                   "phase sweep of eig(A + A_d e^{-j theta})")


def delay_margin_siso(A, B, K) -> DelayMargin:
    """Exact delay margin of x' = A x + B K x(t - h), one input, from
    python-control's gain crossovers.

    Each gain crossover w_i of L(s) = -K (s I - A)^{-1} B with phase margin
    pm_i gives h_i = pm_i / w_i (pm in [0, 2 pi)); h* is the smallest
    [GKC03, sec. 2.2].

    Parameters
    ----------
    A : (n, n) array_like
        Open-loop state matrix (1/s).
    B : (n, 1) or (n,) array_like
        Input matrix.
    K : (1, n) or (n,) array_like
        Delayed state feedback gain.

    Returns
    -------
    DelayMargin

    Raises
    ------
    ValueError
        Bad shapes, complex or non-finite entries.
    """
    A = _input.square(A, "A")
    n = A.shape[0]
    B = np.asarray(B)
    K = np.asarray(K)
    B = _input.real_matrix(B.reshape(-1, 1) if B.ndim == 1 else B, "B")
    K = _input.real_matrix(K.reshape(1, -1) if K.ndim == 1 else K, "K")
    if B.shape != (n, 1):
        raise ValueError(f"B has shape {B.shape}; expected ({n}, 1) (one input)")
    if K.shape != (1, n):
        raise ValueError(f"K has shape {K.shape}; expected (1, {n}) (one input)")
    method = "python-control stability_margins"
    if not np.max(np.linalg.eigvals(A + B @ K).real) < 0:
        return DelayMargin(0.0, None, "unstable-at-zero-delay", method)
    import control   # (and matplotlib with it): only where the crossovers are needed
    loop = control.ss(A, B, -K, 0.0)   # L(s) = -K (sI - A)^{-1} B, u = -L e
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gm, pm, sm, wpc, wgc, wms = control.stability_margins(loop, returnall=True)
    best_h, best_w = math.inf, None
    for p, w in zip(np.atleast_1d(pm), np.atleast_1d(wgc)):
        if not (np.isfinite(p) and np.isfinite(w)) or not w > 0:
            continue
        h = math.radians(p % 360.0) / w
        if h < best_h:
            best_h, best_w = h, float(w)
    if best_w is None:
        return DelayMargin(math.inf, None, "delay-independent", method)
    return DelayMargin(float(best_h), best_w, "crossing", method)


# -- stability windows -------------------------------------------------------------------
def windows_from_crossings(A, Ad, cs: CrossingSet, h_max: float) -> tuple[tuple[float, float], ...]:
    """Stability set in the delay from the crossings (inputs already checked).

    The number of right-half-plane roots is that of A + A_d just after h = 0
    (roots of a retarded equation enter from Re s = -inf, never from infinity
    on the right) and changes by 2 m d at each crossing delay h_k of a crossing
    of multiplicity m and direction d [GKC03, sec. 2.4]; the system is stable
    where that count is zero.
    """
    if cs.zero_root:
        return ()
    total = sum(max(0.0, (h_max * c.omega - c.theta) / (2 * math.pi)) for c in cs.crossings)
    if not total <= MAX_EVENTS:
        raise ValueError(f"h_max = {h_max!r}; expected a horizon with at most {MAX_EVENTS} "
                         f"crossing delays (found about {total:.3g})")
    ev = np.linalg.eigvals(A + Ad)
    count = int(np.sum(ev.real > 0))
    events: dict[float, int] = {}
    for c in cs.crossings:
        if c.direction == 0:
            continue
        for h in c.delays(h_max):
            if h == 0:          # an axis eigenvalue of A + A_d: where it goes for h > 0
                count += 2 * c.multiplicity * (c.direction > 0)
                continue
            events[h] = events.get(h, 0) + 2 * c.multiplicity * c.direction
    merged: list[list[float]] = []           # [h, change], nearby delays summed
    for h in sorted(events):
        if merged and h - merged[-1][0] <= EVENT_RTOL * h:
            merged[-1][1] += events[h]
        else:
            merged.append([h, events[h]])
    out, start = [], 0.0 if count == 0 else None
    for h, change in merged:
        count += int(change)
        if count < 0:
            raise ArithmeticError(f"root count {count} < 0 after the crossing at h = {h!r} s: "
                                  "the crossing directions are inconsistent")
        if start is not None and count > 0:
            if h > start:
                out.append((start, h))
            start = None
        elif start is None and count == 0:
            start = h
    if start is not None:
        ends = [c.next_after(h_max) for c in cs.crossings if c.direction > 0]
        out.append((start, min(ends) if ends else math.inf))
    return tuple((float(a), float(b)) for a, b in out)


def stability_windows(A, Ad, h_max: float, *,
                      method: Literal["sweep", "kronecker"] = "sweep"
                      ) -> tuple[tuple[float, float], ...]:
    """Exact set of constant delays in [0, h_max] for which x' = A x + A_d x(t - h)
    is asymptotically stable.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices (1/s).
    h_max : float
        Horizon (s), > 0: every window that starts at or below it is returned.
    method : {"sweep", "kronecker"}
        Crossing finder (:func:`delay_margin_sweep` or :func:`delay_margin_eig`).

    Returns
    -------
    tuple of (a, b)
        Disjoint windows in increasing order: stable for every a < h < b, and at
        h = 0 when a = 0 and A + A_d is Hurwitz. Each a > 0 and each finite b is
        a crossing delay (s); the last b may exceed h_max (the next
        destabilising crossing) or be ``inf`` (stable for every larger delay).
        The first window is [0, h*) when h* > 0. Empty: unstable on [0, h_max].

    Raises
    ------
    ValueError
        Bad matrices, h_max not a positive finite number (or beyond 10^6
        crossing delays), or an unknown method.
    ArithmeticError
        Crossing directions that would make the root count negative.

    References
    ----------
    Gu, Kharitonov & Chen (2003), sec. 2.4 (root counting across crossings);
    Cooke & Grossman, "Discrete delay, distributed delay and stability
    switches", J. Math. Anal. Appl. 86 (1982) 592-627.
    """
    A, Ad = _input.system(A, Ad)
    h_max = _input.delay(h_max, "h_max", positive=True)
    if method == "sweep":
        cs = phase_crossings(A, Ad)
    elif method == "kronecker":
        cs = kronecker_crossings(A, Ad)
    else:
        raise ValueError(f'method = {method!r}; expected "sweep" or "kronecker"')
    return windows_from_crossings(A, Ad, cs, h_max)


# -- both methods ---------------------------------------------------------------------
class Agreement(str, enum.Enum):
    """Closed set of outcomes of the cross-check of the two exact methods."""

    AGREE = "agree"
    DISAGREE = "disagree"
    SINGLE = "single-method"


def relative_difference(a: float, b: float) -> float:
    """|a - b| / max(|a|, |b|); 0 when a == b (both inf or both 0), inf when
    only one is infinite. Scale-free: no absolute floor."""
    if a == b:
        return 0.0
    if math.isinf(a) or math.isinf(b):
        return math.inf
    return abs(a - b) / max(abs(a), abs(b))


@dataclass(frozen=True)
class ExactMargin:
    """The exact delay margin by the sweep, cross-checked by Chen-Gu-Nett.

    Attributes
    ----------
    h, omega, reason :
        Those of ``sweep`` (s, rad/s).
    sweep : DelayMargin
        :func:`delay_margin_sweep`.
    kronecker : DelayMargin or None
        :func:`delay_margin_eig` (None when not run).
    outcome : Agreement
        AGREE (relative difference <= rtol and same reason), DISAGREE, or
        SINGLE (only the sweep ran).
    rel_diff : float or None
        Relative difference of the two margins.
    rtol : float
    """

    sweep: DelayMargin
    kronecker: DelayMargin | None
    outcome: Agreement
    rel_diff: float | None
    rtol: float

    @property
    def h(self) -> float:
        return self.sweep.h

    @property
    def omega(self) -> float | None:
        return self.sweep.omega

    @property
    def reason(self) -> str:
        return self.sweep.reason

    @property
    def ok(self) -> bool:
        """False only when the two methods disagree."""
        return self.outcome is not Agreement.DISAGREE


def compare_margins(a: DelayMargin, b: DelayMargin | None, rtol: float = AGREEMENT_RTOL
                    ) -> tuple[Agreement, float | None]:
    """Agreement of two exact margins within the relative tolerance ``rtol``."""
    if b is None:
        return Agreement.SINGLE, None
    d = relative_difference(a.h, b.h)
    ok = d <= rtol and a.reason == b.reason
    return (Agreement.AGREE if ok else Agreement.DISAGREE), d


def exact_margin(A, Ad, *, rtol: float = AGREEMENT_RTOL,
                 cross_check: Literal["auto", "always", "never"] = "auto") -> ExactMargin:
    """Exact delay margin by two independent methods, with their agreement.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices of x' = A x + A_d x(t - h) (1/s).
    rtol : float
        Relative tolerance of the agreement, in (0, 1).
    cross_check : {"auto", "always", "never"}
        Run :func:`delay_margin_eig` too: for n <= 14 (``"auto"``), always or never.

    Returns
    -------
    ExactMargin
        ``outcome`` DISAGREE is a failure of one of the methods.
    """
    A, Ad = _input.system(A, Ad)
    rtol = _input.fraction(rtol, "rtol")
    if cross_check not in ("auto", "always", "never"):
        raise ValueError(f'cross_check = {cross_check!r}; expected "auto", "always" or "never"')
    sweep = delay_margin_sweep(A, Ad)
    run = cross_check == "always" or (cross_check == "auto" and A.shape[0] <= KRONECKER_MAX_N)
    kron = delay_margin_eig(A, Ad) if run else None
    outcome, d = compare_margins(sweep, kron, rtol)
    return ExactMargin(sweep, kron, outcome, d, rtol)


