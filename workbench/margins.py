"""Exact delay margins and the spectral abscissa, independent of any LMI.

For x' = A x + A_d x(t - h) the *exact delay margin* h* is the largest h
such that the system is asymptotically stable for every constant delay in
[0, h*). It is

* ``0`` when A + A_d is not Hurwitz (unstable, or not asymptotically
  stable, without delay);
* ``inf`` when no characteristic root ever reaches the imaginary axis: then
  the loop is stable for *every* constant delay ("delay-independent"), and
  any finite LMI bound is conservatism of the criterion, not a property of
  the loop;
* otherwise the smallest delay at which a root s = j w, w > 0, crosses.

Two independent computations are provided:

:func:`delay_margin_eig`
    Chen, Gu & Nett (1995): j w is a root at delay h iff
    det(j w I - A - A_d z) = 0 with z = e^{-j w h}, |z| = 1. Since A, A_d are
    real, -j w is then an eigenvalue of A + A_d / z, so the Kronecker sum
    (A + z A_d) (+) (A + A_d / z) is singular; multiplying by z gives the
    quadratic eigenvalue problem z^2 (A_d (x) I) + z (A (+) A) + (I (x) A_d)
    of size n^2, solved as a 2 n^2 generalised eigenproblem. Unit-circle z
    give the candidate (w, h).
:func:`delay_margin_siso`
    For A_d = B K with one input: python-control's ``stability_margins``
    (all gain crossovers) of the loop L(s) = -K (sI - A)^{-1} B; each
    crossover w_i with phase margin pm_i gives h_i = pm_i / w_i (pm in
    [0, 2 pi)); h* is the minimum.

References
----------
.. [CGN95] Chen J., Gu G., Nett C.N., "A new method for computing delay
   margins for stability of linear delay systems", Systems & Control
   Letters 26 (1995) 107-117.
.. [GKC03] Gu K., Kharitonov V.L., Chen J., *Stability of Time-Delay
   Systems*, Birkhauser 2003, ch. 2.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

#: Tolerance on |z| = 1 and on Re(s) = 0 when picking crossing candidates.
UNIT_TOL = 1e-6


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
    """

    h: float
    omega: float | None
    reason: str
    method: str


def is_hurwitz(M: np.ndarray) -> bool:
    """True when every eigenvalue of ``M`` has a negative real part."""
    return bool(np.max(np.linalg.eigvals(np.atleast_2d(M)).real) < 0)


def _unstable(method: str) -> DelayMargin:
    return DelayMargin(0.0, None, "unstable-at-zero-delay", method)


def _refine_crossing(A, Ad, w, z, iters: int = 3):
    """Newton polish of (w, theta) with det(j w I - A - A_d e^{-j theta}) = 0
    via the eigenvalue of A + A_d z closest to j w."""
    for _ in range(iters):
        ev = np.linalg.eigvals(A + Ad * z)
        k = int(np.argmin(np.abs(ev - 1j * w)))
        w = float(ev[k].imag)
        if abs(ev[k].real) > 1e-3 * max(1.0, abs(w)):
            break
    return w


def delay_margin_eig(A, Ad) -> DelayMargin:
    """Exact delay margin by the Chen-Gu-Nett eigenvalue method.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices of x' = A x + A_d x(t - h).

    Returns
    -------
    DelayMargin
    """
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    n = A.shape[0]
    method = "Chen-Gu-Nett eigenvalue"
    if not is_hurwitz(A + Ad):
        return _unstable(method)
    I = np.eye(n)
    In2 = np.eye(n * n)
    P2 = np.kron(Ad, I)                   # z^2 coefficient
    P1 = np.kron(A, I) + np.kron(I, A)    # z^1
    P0 = np.kron(I, Ad)                   # z^0
    # companion linearisation: [0 I; -P0 -P1] v = z [I 0; 0 P2] v
    N = n * n
    lhs = np.block([[np.zeros((N, N)), In2], [-P0, -P1]])
    rhs = np.block([[In2, np.zeros((N, N))], [np.zeros((N, N)), P2]])
    with np.errstate(all="ignore"):
        zs = sl.eigvals(lhs, rhs)
    zs = zs[np.isfinite(zs)]
    best_h, best_w = math.inf, None
    for z in zs[np.abs(np.abs(zs) - 1.0) < UNIT_TOL]:
        z = z / abs(z)
        ev = np.linalg.eigvals(A + Ad * z)
        for s in ev[np.abs(ev.real) < UNIT_TOL * max(1.0, np.max(np.abs(ev)))]:
            w = float(s.imag)
            zz = z
            if w < 0:                       # conjugate pair: use w > 0
                w, zz = -w, np.conj(z)
            if w <= UNIT_TOL:
                continue                    # root at s = 0 excluded by Hurwitz test
            w = _refine_crossing(A, Ad, w, zz)
            theta = (-np.angle(zz)) % (2 * math.pi)   # e^{-j w h} = z
            h = theta / w
            if h < best_h:
                best_h, best_w = h, w
    if best_w is None:
        return DelayMargin(math.inf, None, "delay-independent", method)
    return DelayMargin(float(best_h), best_w, "crossing", method)


def delay_margin_siso(A, B, K) -> DelayMargin:
    """Exact delay margin of x' = A x + B K x(t - h), one input, from
    python-control's gain crossovers (see module docstring).

    Parameters
    ----------
    A : (n, n) array_like
    B : (n, 1) array_like
    K : (1, n) array_like
    """
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(-1, 1)
    K = np.asarray(K, float).reshape(1, -1)
    method = "python-control stability_margins"
    if not is_hurwitz(A + B @ K):
        return _unstable(method)
    import control   # (and matplotlib with it): only where the crossovers are needed
    loop = control.ss(A, B, -K, 0.0)   # L(s) = -K (sI - A)^{-1} B, u = -L e
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        gm, pm, sm, wpc, wgc, wms = control.stability_margins(loop, returnall=True)
    best_h, best_w = math.inf, None
    for p, w in zip(np.atleast_1d(pm), np.atleast_1d(wgc)):
        if not (np.isfinite(p) and np.isfinite(w)) or w <= 0:
            continue
        h = math.radians(p % 360.0) / w
        if h < best_h:
            best_h, best_w = h, float(w)
    if best_w is None:
        return DelayMargin(math.inf, None, "delay-independent", method)
    return DelayMargin(float(best_h), best_w, "crossing", method)


def spectral_abscissa(A, Ad, h: float, *, order: int = 40) -> float:
    """Rightmost real part of the characteristic roots of x' = A x + A_d x(t-h).

    Computed by Chebyshev pseudospectral collocation of the solution operator's
    infinitesimal generator on [-h, 0] (Breda, Maset & Vermiglio 2005), whose
    eigenvalues approximate the rightmost roots; each candidate is then polished
    by Newton's method on det(s I - A - A_d e^{-s h}).

    Parameters
    ----------
    A, Ad : (n, n) array_like
    h : float
        Delay (s), >= 0.
    order : int
        Number of Chebyshev intervals.
    """
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    n = A.shape[0]
    if h == 0:
        return float(np.max(np.linalg.eigvals(A + Ad).real))
    N = order
    k = np.arange(N + 1)
    x = np.cos(math.pi * k / N)                   # Chebyshev points on [-1, 1]
    c = np.where((k == 0) | (k == N), 2.0, 1.0) * (-1.0) ** k
    X = np.tile(x, (N + 1, 1)).T
    dX = X - X.T
    D = np.outer(c, 1 / c) / (dX + np.eye(N + 1))
    D = D - np.diag(D.sum(axis=1))
    D = D * (2.0 / h)                              # map to theta in [-h, 0]
    # nodes theta_j = h (x_j - 1)/2: theta_0 = 0 ... theta_N = -h
    G = np.kron(D, np.eye(n))
    G[:n, :] = 0.0
    G[:n, :n] = A
    G[:n, -n:] = Ad
    ev = np.linalg.eigvals(G)
    ev = ev[np.isfinite(ev)]
    cand = ev[np.argsort(-ev.real)][: max(4, 2 * n)]
    best = -math.inf
    for s in cand:
        s = _newton_root(A, Ad, h, complex(s))
        best = max(best, s.real)
    return float(best)


def _newton_root(A, Ad, h, s, iters: int = 20):
    """Newton on det(s I - A - A_d e^{-s h}) via the smallest eigenvalue."""
    n = A.shape[0]
    for _ in range(iters):
        M = s * np.eye(n) - A - Ad * np.exp(-s * h)
        dM = np.eye(n) + h * Ad * np.exp(-s * h)
        try:
            step = np.trace(np.linalg.solve(M, dM))
        except np.linalg.LinAlgError:
            return s
        if step == 0:
            return s
        ds = 1.0 / step                 # det'/det = tr(M^-1 M')
        s = s - ds
        if abs(ds) < 1e-13 * max(1.0, abs(s)):
            break
    return s


def delay_margin_sweep(A, Ad, *, grid: int | None = None) -> DelayMargin:
    """Exact delay margin by a sweep of the delay phase theta (second method).

    j w is a characteristic root at delay h iff j w is an eigenvalue of
    M(theta) = A + A_d e^{-j theta} with theta = w h (mod 2 pi). The phase
    theta in [0, 2 pi] is swept on a grid; at each local minimum of
    g(theta) = min_k |Re lambda_k(M(theta))| the minimum is located by a
    bounded Brent search and polished by Newton's method on
    Re lambda(theta) = 0 with the eigenvalue derivative
    d lambda / d theta = y^H (-j A_d e^{-j theta}) x / (y^H x). A zero gives
    the crossing (theta, w = Im lambda) and the delay theta / w (for w < 0 the
    conjugate crossing at 2 pi - theta, -w); h* is the smallest such delay.

    Independent of :func:`delay_margin_eig` (no Kronecker sums: n x n
    eigenproblems only), for any n and any rank of A_d.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices of x' = A x + A_d x(t - h).
    grid : int, optional
        Number of phase intervals (default max(2048, 128 n)).

    Returns
    -------
    DelayMargin
    """
    from scipy.optimize import minimize_scalar

    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    n = A.shape[0]
    method = "phase sweep of eig(A + A_d e^{-j theta})"
    if not is_hurwitz(A + Ad):
        return _unstable(method)
    M = grid or max(2048, 128 * n)
    thetas = np.linspace(0.0, 2 * math.pi, M + 1)
    stack = A[None] + Ad[None] * np.exp(-1j * thetas)[:, None, None]
    g = np.min(np.abs(np.linalg.eigvals(stack).real), axis=1)
    scale = max(1.0, float(np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2)))

    def g_at(th):
        return float(np.min(np.abs(np.linalg.eigvals(A + Ad * np.exp(-1j * th)).real)))

    best_h, best_w = math.inf, None
    for i in range(1, M):
        if not (g[i] <= g[i - 1] and g[i] <= g[i + 1]):
            continue
        res = minimize_scalar(g_at, bounds=(thetas[i - 1], thetas[i + 1]), method="bounded",
                              options={"xatol": 1e-12})
        th, s = _polish_phase(A, Ad, float(res.x))
        if s is None or abs(s.real) > 1e-9 * scale:
            continue
        w = float(s.imag)
        if abs(w) <= UNIT_TOL:
            continue
        if w < 0:
            th, w = 2 * math.pi - th, -w
        h = (th % (2 * math.pi)) / w
        if h < best_h:
            best_h, best_w = h, w
    if best_w is None:
        return DelayMargin(math.inf, None, "delay-independent", method)
    return DelayMargin(float(best_h), best_w, "crossing", method)


def _polish_phase(A, Ad, th: float, iters: int = 30):
    """Newton on Re lambda(theta) = 0 for the eigenvalue of A + A_d e^{-j theta}
    nearest the imaginary axis; returns (theta, lambda) or (theta, None)."""
    s = None
    for _ in range(iters):
        z = np.exp(-1j * th)
        ev, yl, xr = sl.eig(A + Ad * z, left=True, right=True)
        k = int(np.argmin(np.abs(ev.real)))
        s = ev[k]
        y, x = yl[:, k], xr[:, k]
        den = np.vdot(y, x)
        if abs(den) < 1e-14:
            return th, s
        ds = np.vdot(y, (-1j * z) * (Ad @ x)) / den
        if ds.real == 0:
            return th, s
        step = s.real / ds.real
        th -= step
        if abs(step) < 1e-15:
            break
    z = np.exp(-1j * th)
    ev = np.linalg.eigvals(A + Ad * z)
    return th, ev[int(np.argmin(np.abs(ev.real)))]
