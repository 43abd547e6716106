"""Exact power-of-two state scaling for the LMIs.

Every synthesis and analysis LMI is solved in balanced coordinates
x = T x~, with T = diag(2^k) from LAPACK's balancing of A: the scaling is
exact in floating point, so a certificate in x~ is one in x, and a gain
K~ maps back as K = K~ T^{-1} without rounding.
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import scipy.linalg as sl


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
