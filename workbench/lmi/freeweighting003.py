"""Theorem 1 with Remark 3 of paper 003: the free-weighting synthesis LMI.

For E' = A E + B K E(t-h), 0 <= h <= h_m, with R = eps L (Remark 3), the
generalised-eigenvalue problem (60) is

    min iota = 1/h_m  s.t.  (54), (58), (59),

over L = L^T > 0, V, W >= 0, M1, M2, Y11, Y22 >= 0 (Y12 = 0) and
Y1, Y2, Y3 >= 0; the gain is K = V L^{-1}. A feasible point at iota proves,
through the Lyapunov-Krasovskii functional of eq (38), that the closed loop is
asymptotically stable for every constant delay h in [0, 1/iota].

Note on eq (55): the congruence diag(I, I, 1/h_m) of eq (53) gives the
(3,3) block -iota eps L, not the printed -eps L; eq (59) is nevertheless
right because (58) bounds Y1 < iota L. This module implements (54), (58),
(59) as printed (checked in ``proofs/``).

References
----------
.. [003] Cai, Yue, Huang, CTA 43(3), 2026: Theorem 1 (eqs 33-35), proof
   (eqs 36-52), Remark 3 (eqs 53-60).
.. [HE04] He Y., Wang Q.-G., Lin C., Wu M., "Augmented Lyapunov functional
   and delay-dependent stability criteria for neutral systems", 2004 (the
   free-weighting-matrix technique).
"""
from __future__ import annotations

from typing import Mapping

import cvxpy as cp
import numpy as np

from .core import Block, MarginLMI
from .gain import FixedGain


class FreeWeighting003(MarginLMI):
    """Problem (60) of paper 003 at fixed eps, in the delay parameter.

    Decision variables: L, W, Y11, Y22, Y1, Y2, Y3 (symmetric n x n),
    M1, M2 (n x n), V (m x n). Blocks: ``eq59`` (<= 0), ``eq54`` (>= 0),
    ``eq58_1..3`` (<= 0), and L, W, Y's positive.

    Parameters
    ----------
    A : (n, n) array
        Error-system matrix (eq 32).
    B : (n, m) array
        Input matrix (eq 32).
    eps : float
        Scalar of Remark 3, R = eps L (> 0).
    """


    def __init__(self, A, B, eps: float, **kw):
        self.A, self.B = np.asarray(A, float), np.asarray(B, float)
        super().__init__(**kw)
        self.set_eps(eps)

    def parameters(self) -> tuple[str, ...]:
        return ("eps", "inv_eps")

    def set_eps(self, eps: float) -> None:
        """Change eps without rebuilding the problem (DPP parameter)."""
        if not eps > 0:
            raise ValueError(f"eps = {eps!r}; expected a positive number")
        self.eps = float(eps)
        self.set_parameters(eps=eps, inv_eps=1.0 / eps)

    def variables(self) -> dict[str, cp.Variable]:
        n, m = self.B.shape
        v = {k: cp.Variable((n, n), symmetric=True, name=k)
             for k in ("L", "W", "Y11", "Y22", "Y1", "Y2", "Y3")}
        v["M1"] = cp.Variable((n, n), name="M1")
        v["M2"] = cp.Variable((n, n), name="M2")
        v["V"] = cp.Variable((m, n), name="V")
        return v

    def blocks(self, x: Mapping[str, object], p, bmat) -> list[Block]:
        A, B = self.A, self.B
        eps, inv_eps, iota = p["eps"], p["inv_eps"], p["iota"]
        n = A.shape[0]
        Z = np.zeros((n, n))
        L, W, M1, M2, V = x["L"], x["W"], x["M1"], x["M2"], x["V"]
        Y11, Y22, Y1, Y2, Y3 = x["Y11"], x["Y22"], x["Y1"], x["Y2"], x["Y3"]
        P11 = A @ L + L @ A.T + M1 + M1.T + W          # eq (56)
        P12 = B @ V - M1 + M2.T
        P22 = -M2 - M2.T - W
        eq59 = bmat([[P11, P12, L @ A.T, Y11, Z],
                     [P12.T, P22, V.T @ B.T, Z, Y22],
                     [A @ L, B @ V, -eps * Y1, Z, Z],
                     [Y11, Z, Z, -Y2, Z],
                     [Z, Y22, Z, Z, -Y3]])
        eq54 = bmat([[Y11, Z, M1], [Z, Y22, M2], [M1.T, M2.T, inv_eps * L]])
        out = [Block("eq59", eq59, "nsd"), Block("eq54", eq54, "psd"),
               Block("eq58_1", Y1 - iota * L, "nsd"),
               Block("eq58_2", Y2 - iota * Y11, "nsd"),
               Block("eq58_3", Y3 - iota * Y22, "nsd")]
        out += [Block(f"{k}_pos", x[k], "psd") for k in ("L", "W", "Y11", "Y22", "Y1", "Y2", "Y3")]
        return out

    def gain(self, values: Mapping[str, np.ndarray]) -> np.ndarray:
        """K = V L^{-1} (eq 47) from a certificate."""
        return np.linalg.solve(values["L"].T, values["V"].T).T


class FreeWeighting003FixedK(FixedGain, FreeWeighting003):
    """The same LMI with the gain fixed (V = K L): analysis of a given K.

    Used to ask what a printed gain certifies under the paper's own
    criterion.
    """

    gain_basis = "L"
