"""Shifted Legendre polynomials l_k(u) = P_k(2u - 1) on [0, 1]: the constants of
the Bessel-Legendre criterion (Seuret & Gouaisbaut, SCL 81 (2015), eq. 4)."""
from __future__ import annotations

import numpy as np


def legendre_derivative_coefficients(N: int) -> np.ndarray:
    """c[k, j] with l_k'(u) = sum_{j<k} c[k, j] l_j(u) on [0, 1].

    For l_k(u) = P_k(2u - 1): c[k, j] = (2j + 1)(1 - (-1)^(k+j)) (SG15, eq. 4).
    """
    c = np.zeros((N + 1, N + 1), dtype=int)
    for k in range(N + 1):
        for j in range(k):
            c[k, j] = (2 * j + 1) * (1 - (-1) ** (k + j))
    return c


def blockdiag_S(S, N: int, n: int, bmat):
    """diag(0, S, 3S, ..., (2N-1)S) as a cvxpy or numpy block matrix."""
    Z = np.zeros((n, n), dtype=int)
    rows = []
    for i in range(N + 1):
        rows.append([(2 * i - 1) * S if (i == j and i > 0) else Z for j in range(N + 1)])
    return bmat(rows)
