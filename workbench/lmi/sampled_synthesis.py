"""Synthesis of a state-feedback gain K for aperiodic sampling up to T_max.

For the lifted maps Ad(s) = e^{As} + Psi(s) B K of :mod:`workbench.lmi.sampled`,
Ad' P Ad - P <= -s t P^2 with P = Q^{-1} is, by a Schur complement and the
congruence diag(Q, I), the LMI in (Q, Y = K Q)

    [[Q - s t I,               Q e^{As}' + Y' B' Psi(s)'],
     [e^{As} Q + Psi(s) B Y,   Q                        ]] >= 0

(the standard convexification of the discrete-time Lyapunov inequality;
Hetel et al. 2017, sec. 5; Fujioka 2009, sec. 4). It is imposed on a grid of
s in [T_max / GRID, T_max] with ``trace Q <= 1`` and t maximised; K = Y Q^{-1}
is rounded to ``digits`` significant digits. The grid is not a proof: the
**rounded** gain is then certified by the analysis of
:mod:`workbench.lmi.sampled` over the continuum (0, T_max] — the gain printed
is the gain certified.

References
----------
Fujioka, H. (2009). Stability analysis of systems with aperiodic
sample-and-hold devices. Automatica 45(3), 771-775.
Hetel, L. et al. (2017). Recent developments on the stability of systems with
aperiodic sampling: an overview. Automatica 76, 309-335.
"""
from __future__ import annotations

import math

import cvxpy as cp
import numpy as np
import scipy.linalg as sl

from ..printed_grid import sig_round
from .core import guarded_solve

__all__ = ["synthesize_sampled_gain"]

#: Grid points of the synthesis LMI on [T_max / GRID, T_max].
GRID = 40


def _round(K: np.ndarray, digits: int) -> np.ndarray:
    out = np.zeros_like(K)
    for idx, k in np.ndenumerate(K):
        if k != 0 and math.isfinite(k):
            out[idx] = sig_round(k, digits, round)
    return out


def synthesize_sampled_gain(A, B, T_max: float, *, digits: int = 4,
                            bound: float = 1e4) -> tuple[np.ndarray | None, str, float | None]:
    """A gain K for every sampling interval in (0, T_max] (to be certified).

    Parameters
    ----------
    A, B : array_like
        Plant (n x n, n x m).
    T_max : float
        Largest sampling interval (s).
    digits : int
        Significant digits of the returned gain.
    bound : float
        Bound on the entries of Y = K Q (keeps the gain finite).

    Returns
    -------
    (K, status, t)
        The rounded gain (None when the solve is not optimal or t <= 0), the
        solver status and the optimal margin t.
    """
    A, B = np.asarray(A, float), np.asarray(B, float)
    n, m = B.shape
    if not (T_max > 0 and math.isfinite(T_max)):
        raise ValueError(f"T_max = {T_max!r} s; expected a positive finite interval")
    Q = cp.Variable((n, n), symmetric=True)
    Y = cp.Variable((m, n))
    t = cp.Variable()
    cons = [cp.trace(Q) <= 1, cp.abs(Y) <= bound, Q >> t * np.eye(n)]
    for s in np.linspace(T_max / GRID, T_max, GRID):
        M = np.zeros((n + m, n + m))
        M[:n, :n], M[:n, n:] = A * s, B * s
        E = sl.expm(M)
        AdQ = E[:n, :n] @ Q + E[:n, n:] @ Y
        blk = cp.bmat([[Q - s * t * np.eye(n), AdQ.T], [AdQ, Q]])
        cons.append((blk + blk.T) / 2 >> 0)
    prob = cp.Problem(cp.Maximize(t), cons)
    status, _ = guarded_solve(prob)
    if status.startswith("error"):
        return None, status, None
    if status != cp.OPTIMAL or not t.value > 0:
        return None, status, None if t.value is None else float(t.value)
    K = np.asarray(Y.value) @ np.linalg.inv(np.asarray(Q.value))
    return _round(K, digits), status, float(t.value)
