"""Exact power-of-two state scaling for the LMIs.

Every synthesis and analysis LMI is solved in balanced coordinates
x = T x~, with T = diag(2^k) from LAPACK's balancing of A: the scaling is
exact in floating point, so a certificate in x~ is one in x, and a gain
K~ maps back as K = K~ T^{-1} without rounding.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import scipy.linalg as sl


#: A time-varying-delay synthesis LMI's blocks are written in the time unit
#: that makes its delay cap about this many units (the power of two nearest
#: h_cap / CAP_IN_UNITS).
CAP_IN_UNITS = 10.0
#: The same for the constant-delay syntheses (Wirtinger and descriptor,
#: :mod:`workbench.lmi.tight_synthesis`, :mod:`workbench.lmi.robust`): the cap is
#: about 4 units (2.8 to 5.7). Their canonical gain (the minimum-norm
#: certificate, :mod:`workbench.lmi.gain`) depends on the unit, and this is the
#: ratio that suits every shipped design (issue 21, measured): about 10 units
#: fail the canonical point of train-brake-lag (cap 1.5 s, unit 1/8 s: relative
#: margin 4.5e-8 < 1e-7; 1/4 s: solver error), about 1.4 to 2.8 units leave the
#: antiskid-cruise gains (cap 10 s, unit 4 or 8 s) with an entry 2e-5 of the
#: other, whose fourth digit then depends on the BLAS kernels; at 4 units
#: (train 1/2 s, wheel-slip 1/4 s, antiskid 2 s) every shipped synthesis
#: certifies its cap or more, canonical gain included (default and
#: Sandybridge OpenBLAS kernels give the same reports).
SYNTHESIS_CAP_IN_UNITS = 4.0


def time_unit(h_cap: float, cap_in_units: float = CAP_IN_UNITS) -> float:
    """Time unit (s) of a synthesis LMI's blocks: the power of two nearest
    ``h_cap / cap_in_units`` (default :data:`CAP_IN_UNITS`; the constant-delay
    syntheses pass :data:`SYNTHESIS_CAP_IN_UNITS`).

    The blocks are written for (u A, u B) at delay h / u and descriptor
    scalar eps / u: the same system in the unit u, so a certificate there is
    one in seconds, and the change is exact (u is a power of two). The
    solver then sees the same numbers whatever unit the caller's model uses
    (time scaling (c A, c B) with cap h_cap / c changes u by at most a factor
    sqrt 2), and relative margins do not depend on the unit. Caps within
    sqrt 2 of ``cap_in_units`` s give u = 1.
    """
    if not (isinstance(h_cap, (int, float, np.floating)) and 0 < h_cap < math.inf):
        raise ValueError(f"h_max = {h_cap!r}; expected a positive finite delay cap (s)")
    return 2.0 ** round(math.log2(h_cap / cap_in_units))


def check_unit(unit: float) -> float:
    """``unit`` if it is a power of two (so scaling by it is exact), else ValueError."""
    if not (isinstance(unit, (int, float, np.floating)) and 0 < unit < math.inf
            and math.frexp(unit)[0] == 0.5):
        raise ValueError(f"unit = {unit!r}; expected a power of two (s)")
    return float(unit)


def balancing(A) -> np.ndarray:
    """Diagonal power-of-two T with T^{-1} A T balanced (exact in floating point).

    Parameters
    ----------
    A : (n, n) array_like

    Returns
    -------
    numpy.ndarray
        T, diagonal, entries powers of two.
    """
    _, (scale, _) = sl.matrix_balance(np.asarray(A, float), permute=False, separate=True)
    return np.diag(scale)


def balance_points(points: Sequence[tuple[np.ndarray, np.ndarray]]):
    """Common scaling of several (A_i, B_i) from the first point's A.

    Returns
    -------
    T, Tinv : numpy.ndarray
        T and its (exact) inverse.
    balanced : list of (A~, B~)
        A~ = T^{-1} A T, B~ = T^{-1} B per point.
    """
    T = balancing(points[0][0])
    Tinv = np.diag(1 / np.diag(T))
    return T, Tinv, [(Tinv @ A @ T, Tinv @ B) for A, B in points]


def balance_loop(A, Ad):
    """Common power-of-two balancing of the delayed loop x' = A x + A_d x(t - h).

    Osborne balancing (LAPACK's, :func:`balancing`) of ``|A| + |A_d|``: the
    diagonal similarity that equalises row and column norms of both matrices
    at once, so a loop whose coupling is only in A_d (e.g. A_d = B K) is
    balanced too. Exact in floating point (powers of two).

    Returns
    -------
    T, Tinv : numpy.ndarray
        x = T x~ and T^{-1}.
    At, Adt : numpy.ndarray
        T^{-1} A T and T^{-1} A_d T.

    References
    ----------
    .. [OSB60] Osborne E. E., "On pre-conditioning of matrices", J. ACM 7(4),
       338-345, 1960.
    """
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    T = balancing(np.abs(A) + np.abs(Ad))
    Tinv = np.diag(1 / np.diag(T))
    return T, Tinv, Tinv @ A @ T, Tinv @ Ad @ T


def gramian_scaling(points: Sequence[tuple[np.ndarray, np.ndarray]], horizon: float,
                    balance: bool = True) -> np.ndarray:
    """Diagonal state scaling of a *synthesis* (K unknown) that follows every
    diagonal similarity of the plant: T = diag(sqrt(W_jj)) with W the
    finite-horizon controllability Gramian int_0^tau e^{At} B B' e^{A't} dt
    summed over the points (tau = ``horizon``), then Osborne balancing
    (:func:`balancing`) of the normalised A of the first point.

    Under x = D x^ (A^ = D^{-1} A D, B^ = D^{-1} B) the Gramian becomes
    D^{-1} W D^{-1}, so T^ = D^{-1} T and T^^{-1} A^ T^ = T^{-1} A T: the
    synthesis LMI, hence its gain in the original coordinates, does not see
    D (up to rounding). A state with W_jj = 0 (no input reaches it within
    tau) keeps scale 1. T is not a power of two: the synthesis only proposes
    a gain, which is then rounded and certified in exact coordinates.

    Parameters
    ----------
    points : sequence of (A, B)
    horizon : float
        tau (s), > 0: the problem's time scale (the delay cap).
    balance : bool
        False: the Gramian normalisation alone, without the final balancing
        (it also follows every diagonal similarity). The balancing can blow a
        nearly decoupled state up by 2^12 when a diagonal entry of A is near
        0 (a triangular A at an adhesion peak), and the synthesis then fails;
        :func:`~workbench.lmi.requirements_synthesis.synthesize_requirements`
        retries without it.

    Returns
    -------
    numpy.ndarray
        T, diagonal, positive.

    References
    ----------
    .. [VL78] Van Loan C. F., "Computing integrals involving the matrix
       exponential", IEEE TAC 23(3), 395-404, 1978 (the Gramian by one
       exponential of a block matrix).
    """
    n = points[0][0].shape[0]
    W = np.zeros((n, n))
    for A, B in points:
        A, B = np.asarray(A, float), np.atleast_2d(np.asarray(B, float))
        M = np.zeros((2 * n, 2 * n))
        M[:n, :n], M[:n, n:], M[n:, n:] = -A, B @ B.T, A.T
        E = sl.expm(M * horizon)
        W += E[n:, n:].T @ E[:n, n:]
    d = np.sqrt(np.clip(np.diag(W), 0.0, None))
    ok = np.isfinite(d) & (d > 0)
    d = np.where(ok, d, 1.0)
    T = np.diag(d)
    if not balance:
        return T
    A0 = np.diag(1.0 / d) @ np.asarray(points[0][0], float) @ T
    return T @ balancing(A0)


def osborne_continuous(M, *, sweeps: int = 100, tol: float = 1e-12) -> np.ndarray:
    """Diagonal D > 0 (geometric mean 1) with D^{-1} |M| D balanced: every
    state's off-diagonal row and column 2-norms equal (Osborne's iteration
    without rounding to powers of two [OSB60]_).

    For an irreducible |M| the balanced form is unique up to a scalar, so
    under M^ = E^{-1} M E (E diagonal, positive) the result is E^{-1} D up
    to that scalar, which the normalisation fixes: the scaling follows the
    similarity exactly (up to rounding). A state without off-diagonal
    coupling keeps scale 1; the iteration stops after ``sweeps`` sweeps.
    """
    M = np.abs(np.atleast_2d(np.asarray(M, float)))
    n = M.shape[0]
    off = M - np.diag(np.diag(M))
    d = np.ones(n)
    for _ in range(sweeps):
        moved = 0.0
        for i in range(n):
            c = np.linalg.norm(off[:, i] * d[i] / d)     # column i of D^-1 M D
            r = np.linalg.norm(off[i, :] * d / d[i])     # row i
            if not (c > 0 and r > 0 and math.isfinite(c) and math.isfinite(r)):
                continue
            f = math.sqrt(r / c)
            d[i] *= f
            moved = max(moved, abs(math.log(f)))
        if moved < tol:
            break
    d = d / math.exp(float(np.mean(np.log(d))))
    return np.diag(d)


def closed_loop_scaling(points: Sequence[tuple[np.ndarray, np.ndarray]], K: np.ndarray,
                        T: np.ndarray) -> np.ndarray:
    """Synthesis coordinates re-balanced from a first gain: T D with D from
    :func:`osborne_continuous` of T^{-1} (sum_i |A_i| + |B_i K|) T.

    ``T`` is a covariant scaling (:func:`gramian_scaling`) and ``K`` a gain in
    original coordinates (K^ = K E under x = E x^), so the result follows a
    diagonal similarity as ``T`` does. Used by the requirement synthesis for
    its second pass: the synthesis LMI's optimum depends on the coordinates
    (wheel-slip: decay optimum 3.12 1/s in Gramian coordinates, 8.41 1/s
    re-balanced from the first gain's closed loop).
    """
    Ti = np.diag(1.0 / np.diag(T))
    M = sum(np.abs(Ti @ np.asarray(A, float) @ T) + np.abs(Ti @ np.asarray(B, float) @ K @ T)
            for A, B in points)
    return T @ osborne_continuous(M)
