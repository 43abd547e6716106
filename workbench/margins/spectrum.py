"""Rightmost characteristic roots of x' = A x + A_d x(t - h) at one delay.

Chebyshev collocation of the infinitesimal generator of the solution operator
on [-h, 0] [BMV05] gives approximations of the rightmost roots; each is polished
by Newton's method on det(s I - A - A_d e^{-s h}) = 0, with
d/ds log det = tr(Delta(s)^{-1} (I + h A_d e^{-s h})). The order N is raised
(x 1.5) until two successive orders give the same rightmost polished roots and
the collocation itself resolves the rightmost one; otherwise
:class:`SpectrumNotConverged` is raised (an error, never a number).

The first order is N = max(order, ceil(R h / 3)) with R = ||A||_2 + ||A_d||_2: a
root with Re s >= 0 has |s| <= R, and Chebyshev interpolation of e^{s theta} on
[-h, 0] converges once N exceeds |s| h / 2 [Tre13, ch. 8], so the second order
tried (>= R h / 2) resolves every root that decides stability.

References
----------
.. [BMV05] Breda D., Maset S., Vermiglio R., "Pseudospectral differencing
   methods for characteristic roots of delay differential equations", SIAM J.
   Sci. Comput. 27 (2005) 482-495.
.. [Tre13] Trefethen L.N., *Approximation Theory and Approximation Practice*,
   SIAM 2013, ch. 8 (convergence for analytic functions).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _input
from .crossings import EPS, scale

#: Two orders agree when their rightmost real parts differ by at most this times R.
ORDER_RTOL = 1e-9
#: The collocation resolves the rightmost root when an eigenvalue lies this close (x R).
RESOLVED_RTOL = 1e-5
#: Largest collocation matrix n (N + 1) tried.
MAX_SIZE = 2400


class SpectrumNotConverged(ArithmeticError):
    """The rightmost roots did not converge in the collocation order."""


@dataclass(frozen=True)
class Spectrum:
    """Rightmost roots at one delay.

    Attributes
    ----------
    h : float
        Delay (s).
    alpha : float
        Spectral abscissa max Re s (1/s); < 0 iff asymptotically stable.
    roots : tuple[complex, ...]
        Polished rightmost roots (1/s), by decreasing real part.
    order : int
        Chebyshev order N of the accepted collocation (0 at h = 0).
    """

    h: float
    alpha: float
    roots: tuple[complex, ...]
    order: int


def _generator(A, Ad, h: float, N: int) -> np.ndarray:
    n = A.shape[0]
    k = np.arange(N + 1)
    x = np.cos(math.pi * k / N)                   # Chebyshev points on [-1, 1]
    c = np.where((k == 0) | (k == N), 2.0, 1.0) * (-1.0) ** k
    dX = x[:, None] - x[None, :]
    D = np.outer(c, 1 / c) / (dX + np.eye(N + 1))
    D = (D - np.diag(D.sum(axis=1))) * (2.0 / h)  # nodes h (x - 1)/2: 0 ... -h
    G = np.kron(D, np.eye(n))
    G[:n, :] = 0.0
    G[:n, :n] = A
    G[:n, -n:] = Ad
    return G


def newton_root(A, Ad, h: float, s: complex, R: float, iters: int = 40) -> complex | None:
    """Newton on det(s I - A - A_d e^{-s h}) = 0 from ``s``; None if it does not
    converge (step below 4 eps (|s| + R))."""
    n = A.shape[0]
    I = np.eye(n)
    for _ in range(iters):
        E = Ad * np.exp(-s * h)
        try:
            step = np.trace(np.linalg.solve(s * I - A - E, I + h * E))
        except np.linalg.LinAlgError:
            return s                              # exactly singular: a root
        if not np.isfinite(step):
            return None
        if step == 0:
            return None
        ds = 1.0 / step
        s = s - ds
        if abs(ds) <= 4 * EPS * (abs(s) + R):
            return s
    return None


def _polished(A, Ad, h, cand, R) -> list[complex]:
    roots: list[complex] = []
    for s0 in cand:
        s = newton_root(A, Ad, h, complex(s0), R)
        if s is not None and all(abs(s - r) > 1e-8 * R for r in roots):
            roots.append(s)
    return sorted(roots, key=lambda r: -r.real)


def rightmost_roots(A, Ad, h: float, *, order: int = 16, max_size: int = MAX_SIZE) -> Spectrum:
    """Rightmost characteristic roots and spectral abscissa at delay ``h``.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices (1/s).
    h : float
        Delay (s), >= 0.
    order : int
        Smallest Chebyshev order tried (>= 4).
    max_size : int
        Largest collocation matrix n (N + 1) tried.

    Returns
    -------
    Spectrum

    Raises
    ------
    ValueError
        Bad matrices, h < 0 or not finite, bad order.
    SpectrumNotConverged
        No two successive orders agreed within ``max_size``.
    """
    A, Ad = _input.system(A, Ad)
    h = _input.delay(h)
    order = _input.integer(order, "order", lo=4)
    max_size = _input.integer(max_size, "max_size", lo=1)
    if h == 0:
        ev = np.linalg.eigvals(A + Ad)
        ev = ev[np.argsort(-ev.real)]
        return Spectrum(0.0, float(ev[0].real), tuple(complex(v) for v in ev), 0)
    n = A.shape[0]
    R = scale(A, Ad)
    if R == 0:
        return Spectrum(h, 0.0, (0j,), 0)
    N = max(order, math.ceil(R * h / 3))
    if not math.isfinite(2.0 * N * N / h):   # h = 5e-324: the differentiation matrix overflows
        raise SpectrumNotConverged(f"h = {h!r} s: the collocation matrix overflows; "
                                   "expected a delay above about 1e-300 s")
    prev = None
    while n * (N + 1) <= max_size:
        ev = np.linalg.eigvals(_generator(A, Ad, h, N))
        ev = ev[np.isfinite(ev)]
        ev = ev[np.argsort(-ev.real)]
        roots = _polished(A, Ad, h, ev[: max(6, 2 * n)], R)
        if roots:
            resolved = np.min(np.abs(ev - roots[0])) <= RESOLVED_RTOL * R
            if (prev is not None and resolved
                    and abs(prev[0].real - roots[0].real) <= ORDER_RTOL * R):
                return Spectrum(h, float(roots[0].real), tuple(roots), N)
            prev = roots
        N = math.ceil(1.5 * N)
    raise SpectrumNotConverged(
        f"rightmost roots at h = {h!r} s not converged up to collocation size {max_size} "
        f"(n = {n}, order {N}); expected agreement of two successive orders")


def spectral_abscissa(A, Ad, h: float, *, order: int = 16) -> float:
    """Rightmost real part of the characteristic roots of x' = A x + A_d x(t - h)
    (1/s); the order is chosen adaptively (:func:`rightmost_roots`).

    Parameters
    ----------
    A, Ad : (n, n) array_like
        System matrices (1/s).
    h : float
        Delay (s), >= 0.
    order : int
        Smallest Chebyshev order tried.

    Raises
    ------
    ValueError
        Bad input (h < 0, NaN, shapes, complex).
    SpectrumNotConverged
        The rightmost roots did not converge.
    """
    return rightmost_roots(A, Ad, h, order=order).alpha
