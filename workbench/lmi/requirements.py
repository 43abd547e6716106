"""Design to requirements: decay rate, L2 gain and input limit over a delay range.

For x' = A_i x + B_i u(t - h) + B_w w, u = K x (operating points i, one gain),
z = C_z x + D_z u(t - h), the exponentially weighted Lyapunov-Krasovskii
functional of Fridman's descriptor method,

    V = x'Px + int_{t-h}^t e^{2 alpha (s-t)} x'S x ds
        + h int_{-h}^0 int_{t+theta}^t e^{2 alpha (s-t)} x''R x' ds dtheta,

with the descriptor zero term 2 (x'P2' + x''P3')(-x' + A x + B K x_d + B_w w)
and Jensen's inequality gives, with xi = [x; x'; x_d] and rho = e^{-2 alpha H},

    V' + 2 alpha V + z'z / gamma - gamma w'w <= xi_e' Psi xi_e,
    Psi = [[2 alpha P + S - rho R + He(P2'A), P - P2' + A'P3, rho R + P2'BK, P2'B_w, C'],
           [*, -P3 - P3' + H^2 R, P3'BK, P3'B_w, 0],
           [*, *, -rho (S + R), 0, K'D_z'],
           [*, *, *, -gamma I, 0], [*, *, *, *, -gamma I]]   (Schur form of z'z/gamma)

for every constant delay h in [0, H] at once: the only h-dependent terms are
bounded by their value at H (``h^2 x''Rx' <= H^2 x''Rx'``,
``-e^{-2 alpha h} x_d'Sx_d <= -rho x_d'Sx_d`` and
``-h int e^{2 alpha (s-t)} x''Rx' <= -rho (x - x_d)'R(x - x_d)`` by Jensen, as
R, S >= 0 and e^{-2 alpha h} >= rho). So one solve at H certifies the whole
range [0, H], h = 0 included (a range [h_min, H] is certified through
[0, H], which contains it). Here rho_s = rho for constant delays.
Psi <= 0 (w = 0) gives V(t) <= e^{-2 alpha t}
V(0): every solution decays at least like e^{-alpha t}; with zero initial
history it gives ||z||_2 <= gamma ||w||_2 (alpha >= 0).

Time-varying delay (``mu``): for every delay function h(t) in [0, H] with
|h'(t)| <= mu < 1 the same functional, its S integral taken over
[t - h(t), t], has the derivative term -(1 - h'(t)) e^{-2 alpha h(t)}
x_d'Sx_d <= -(1 - mu) rho x_d'Sx_d, and the R term (fixed window H, Jensen on
[t - h(t), t] with h(t) <= H) is bounded as above; so the LMI with
rho_s = (1 - mu) rho certifies every such delay function (Fridman 2014,
sec. 3.6.2 and 4.x: the (1 - mu) factor of the descriptor method). mu = 0
gives the constant-delay LMI exactly; a larger mu only shrinks the feasible
set (S >= 0), so a certified value never grows with mu. Constant delays are
the special case h' = 0.

Synthesis (:class:`RequirementSynthesis`): P3 = eps P2, Y = P2^{-1}, V = K Y
and the congruence diag(Y, Y, Y, I, I) (Fridman & Shaked 2002), decision
variables Y, V common and P~, S~, R~ per point (R written as H R~ so that the
blocks are H R~ and R~ / H). Analysis of a given K
(:class:`RequirementAnalysis`): the same inequality in the original
variables with P2, P3 free (no eps): less conservative, and the certificate
of the returned, rounded gain.

Input limit (w = 0, constant initial history x(s) = x0 on [-h, 0] with x0 in
the box |x0_j| <= b_j): V(0) <= x0'(P + H S)x0 <= sigma at the box's vertices
(convexity) and V non-increasing give x(t)'P x(t) <= sigma for t >= 0, so
|u_k(t)| = |K_k x(t - h)| <= u_max_k when K_k (P / sigma)^{-1} K_k' <= u_max_k^2:
``[[P, sigma K_k'], [sigma K_k, sigma u_max_k^2]] >= 0``. In the synthesis
variables P + H S = Y^{-T} M Y^{-1} (M = P~ + H S~) is bounded through
Y'W^{-1}Y >= Y + Y' - W: ``M + W <= Y + Y'`` and ``[[sigma, sigma v'],
[sigma v, W]] >= 0`` at each box vertex v (every block homogeneous, sigma a
variable, so the relative margins of :mod:`workbench.lmi.core` apply).

References
----------
.. [FS02] Fridman E., Shaked U., "An improved stabilization method for linear
   time-delay systems", IEEE TAC 47(11), 1931-1937, 2002.
.. [Fri14] Fridman E., *Introduction to Time-Delay Systems*, Birkhauser 2014,
   sec. 3.6 (exponential stability by weighted functionals) and sec. 6.2
   (L2-gain by the descriptor method).
.. [TGS11] Tarbouriech S., Garcia G., Gomes da Silva J.M., Queinnec I.,
   *Stability and Stabilization of Linear Systems with Saturating Actuators*,
   Springer 2011, ch. 7 (invariant ellipsoids of delay systems).
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import cvxpy as cp
import numpy as np

from .analysis import RETRY_SETTINGS
from .core import Block, MarginLMI

__all__ = ["Loop", "RequirementAnalysis", "RequirementSynthesis", "box_vertices"]


@dataclass(frozen=True)
class Loop:
    """The data of a requirements LMI (balanced coordinates, see the caller).

    Attributes
    ----------
    points : tuple of (A, B)
        Operating points (n x n, n x m).
    Bw : (n, q) array or None
        Disturbance input (None: no L2 requirement).
    Cz, Dz : (p, n), (p, m) arrays or None
        Performance output z = Cz x + Dz u(t - h).
    box : (n,) array or None
        Half-widths of the initial-deviation box (None: no input limit).
    u_max : (m,) array or None
        Input limits.
    """

    points: tuple
    Bw: np.ndarray | None = None
    Cz: np.ndarray | None = None
    Dz: np.ndarray | None = None
    box: np.ndarray | None = None
    u_max: np.ndarray | None = None

    @property
    def n(self) -> int:
        return self.points[0][0].shape[0]

    @property
    def m(self) -> int:
        return self.points[0][1].shape[1]

    @property
    def l2(self) -> bool:
        return self.Bw is not None

    @property
    def limited(self) -> bool:
        return self.box is not None


def box_vertices(box: np.ndarray) -> list[np.ndarray]:
    """The vertices of the box |x_j| <= b_j, one of each pair +-v (the
    conditions are even in v); zero half-widths add no vertex."""
    box = np.asarray(box, float)
    free = [j for j in range(box.size) if box[j] > 0]
    out = []
    for signs in itertools.product((1.0, -1.0), repeat=max(len(free) - 1, 0)):
        v = np.zeros(box.size)
        if free:
            v[free[0]] = box[free[0]]
            for j, s in zip(free[1:], signs):
                v[j] = s * box[j]
        out.append(v)
    return out


def _times(c, M):
    """The 1 x 1 ``c`` (variable or array) times the constant matrix ``M``."""
    return c[0, 0] * M


class _Requirement(MarginLMI):
    """Shared parameters: the cap H (``h``), ``two_alpha``, ``rho``
    (e^{-2 alpha H}), ``rho_iota`` (rho / H) and ``gamma``."""

    canonical_retry_settings = RETRY_SETTINGS

    def __init__(self, loop: Loop, *, mu: float | None = None, **kw):
        if mu is not None and not (0 <= mu < 1):
            raise ValueError(f"mu = {mu!r}; expected a delay-derivative bound 0 <= mu < 1")
        self.loop = loop
        #: |h'(t)| <= mu (None: constant delays, the same LMI as mu = 0)
        self.mu = mu
        super().__init__(**kw)
        self.set_rate(0.0)

    def parameters(self):
        return ("two_alpha", "rho", "rho_s", "rho_iota", "gamma") + self.extra_parameters()

    def extra_parameters(self) -> tuple[str, ...]:
        return ()

    def set_rate(self, alpha: float, gamma: float = 1.0) -> None:
        """The decay rate alpha (1/s, >= 0) and the L2 gain gamma of the next
        solves; the delay cap H is the ``h`` of :meth:`solve_at`."""
        if not (alpha >= 0 and gamma > 0):
            raise ValueError(f"alpha = {alpha!r}, gamma = {gamma!r}; expected alpha >= 0 "
                             "(1/s) and gamma > 0")
        self._alpha = float(alpha)
        self.set_parameters(two_alpha=2.0 * alpha, gamma=gamma)

    def set_delay(self, h: float) -> None:
        super().set_delay(h)
        rho = math.exp(-2.0 * self._alpha * h)
        self.set_parameters(rho=rho, rho_s=(1.0 - (self.mu or 0.0)) * rho, rho_iota=rho / h)

    def _psi(self, rows, wcol, zrow, p, bmat):
        """The block from its 3 x 3 core ``rows`` (lists), extended by the
        disturbance column ``wcol`` and the output row ``zrow`` (Schur form)."""
        lp = self.loop
        if not lp.l2:
            return bmat(rows)
        q, pz = lp.Bw.shape[1], lp.Cz.shape[0]
        full = [r + [w, z.T] for r, w, z in zip(rows, wcol, zrow)]
        full.append([w.T for w in wcol] + [-p["gamma"] * _times(self._c, np.eye(q)),
                                           np.zeros((q, pz))])
        full.append(zrow + [np.zeros((pz, q)), -p["gamma"] * _times(self._c, np.eye(pz))])
        return bmat(full)

    def _limit_blocks(self, x, bmat, i, Pi, gain_rows) -> list[Block]:
        lp, out = self.loop, []
        sig = x["sigma"]
        for k in range(lp.m):
            out.append(Block(f"u{k}@{i}", bmat([[Pi, gain_rows[k].T],
                                                 [gain_rows[k], sig * lp.u_max[k] ** 2]]), "psd"))
        return out


class RequirementSynthesis(_Requirement):
    """Synthesis LMI of the module docstring (eps a DPP parameter).

    Decision variables: Y (n x n), V (m x n) common; P~_i, S~_i, R~_i
    (symmetric) per operating point; with an input limit W (symmetric) and
    sigma (1 x 1). A CERTIFIED point at cap H proves, for K = V Y^{-1} and
    every constant delay in [0, H] at every point: decay rate alpha, L2 gain
    <= gamma (when a disturbance is declared) and |u_k| <= u_max_k from the
    box (when declared).
    """

    def extra_parameters(self):
        return ("eps",)

    def set_eps(self, eps: float) -> None:
        if not eps > 0:
            raise ValueError(f"eps = {eps!r}; expected a positive number (s)")
        self.eps = float(eps)
        self.set_parameters(eps=eps)

    def variables(self):
        n, m, lp = self.loop.n, self.loop.m, self.loop
        v = {"Y": cp.Variable((n, n), name="Y"), "V": cp.Variable((m, n), name="V")}
        for i in range(len(lp.points)):
            for k in "PSR":
                v[f"{k}{i}"] = cp.Variable((n, n), symmetric=True, name=f"{k}{i}")
        if lp.l2:
            v["c"] = cp.Variable((1, 1), symmetric=True, name="c")
        if lp.limited:
            v["W"] = cp.Variable((n, n), symmetric=True, name="W")
            v["sigma"] = cp.Variable((1, 1), symmetric=True, name="sigma")
        return v

    def blocks(self, x, p, bmat):
        lp = self.loop
        Y, V, eps = x["Y"], x["V"], p["eps"]
        out = []
        for i, (A, B) in enumerate(lp.points):
            P, S, R = x[f"P{i}"], x[f"S{i}"], x[f"R{i}"]
            AY, BV = A @ Y, B @ V
            rows = [[AY + AY.T + p["two_alpha"] * P + S - p["rho_iota"] * R,
                     P - Y + eps * AY.T, BV + p["rho_iota"] * R],
                    [P - Y.T + eps * AY, -eps * (Y + Y.T) + p["h"] * R, eps * BV],
                    [BV.T + p["rho_iota"] * R, eps * BV.T, -p["rho_s"] * S - p["rho_iota"] * R]]
            if lp.l2:
                self._c = x["c"]
                out.append(Block(f"c_pos{i}", x["c"], "psd"))
                cBw = _times(x["c"], lp.Bw)
            wz = ((cBw, p["eps"] * cBw, np.zeros_like(lp.Bw)),
                  [lp.Cz @ Y, np.zeros(lp.Cz.shape), lp.Dz @ V]) if lp.l2 else ((), ())
            out += [Block(f"lmi{i}", self._psi(rows, *wz, p, bmat), "nsd"),
                    Block(f"P{i}_pos", P, "psd"), Block(f"S{i}_pos", S, "psd"),
                    Block(f"R{i}_pos", R, "psd")]
            if lp.limited:
                out.append(Block(f"ellipsoid{i}", P + p["h"] * S + x["W"] - Y - Y.T, "nsd"))
                out += self._limit_blocks(x, bmat, i, P, [V[k:k + 1, :] for k in range(lp.m)])
        if lp.limited:
            sig, W = x["sigma"], x["W"]
            out.append(Block("sigma_pos", sig, "psd"))
            for j, v in enumerate(box_vertices(lp.box)):
                col = v.reshape(-1, 1)
                out.append(Block(f"box{j}", bmat([[sig, sig @ col.T], [col @ sig, W]]), "psd"))
        return out

    def gain(self, values) -> np.ndarray:
        """K = V Y^{-1} from a certificate."""
        return np.linalg.solve(values["Y"].T, values["V"].T).T


class RequirementAnalysis(_Requirement):
    """The inequality of the module docstring for a given gain K (original
    variables, P2 and P3 free matrices).

    Decision variables per operating point: P, S, R (symmetric), P2, P3
    (n x n); with an input limit sigma (1 x 1). A CERTIFIED point at cap H
    proves the requirements it was built with for K and every constant
    delay in [0, H].
    """

    def __init__(self, loop: Loop, K, **kw):
        self.K = np.atleast_2d(np.asarray(K, float))
        super().__init__(loop, **kw)

    def variables(self):
        n = self.loop.n
        v = {}
        for i in range(len(self.loop.points)):
            for k in "PSR":
                v[f"{k}{i}"] = cp.Variable((n, n), symmetric=True, name=f"{k}{i}")
            for k in ("P2_", "P3_"):
                v[f"{k}{i}"] = cp.Variable((n, n), name=f"{k}{i}")
        if self.loop.l2:
            v["c"] = cp.Variable((1, 1), symmetric=True, name="c")
        if self.loop.limited:
            v["sigma"] = cp.Variable((1, 1), symmetric=True, name="sigma")
        return v

    def blocks(self, x, p, bmat):
        lp, K = self.loop, self.K
        out = []
        for i, (A, B) in enumerate(lp.points):
            P, S, R = x[f"P{i}"], x[f"S{i}"], x[f"R{i}"]
            P2, P3 = x[f"P2_{i}"], x[f"P3_{i}"]
            Ad = B @ K
            rows = [[P2.T @ A + A.T @ P2 + p["two_alpha"] * P + S - p["rho_iota"] * R,
                     P - P2.T + A.T @ P3, P2.T @ Ad + p["rho_iota"] * R],
                    [P.T - P2 + P3.T @ A, -P3 - P3.T + p["h"] * R, P3.T @ Ad],
                    [Ad.T @ P2 + p["rho_iota"] * R, Ad.T @ P3, -p["rho_s"] * S - p["rho_iota"] * R]]
            if lp.l2:
                self._c = c = x["c"]
                out.append(Block(f"c_pos{i}", c, "psd"))
            wz = ((P2.T @ lp.Bw, P3.T @ lp.Bw, np.zeros_like(lp.Bw)),
                  [_times(c, lp.Cz), np.zeros(lp.Cz.shape), _times(c, lp.Dz @ K)]
                  ) if lp.l2 else ((), ())
            out += [Block(f"lmi{i}", self._psi(rows, *wz, p, bmat), "nsd"),
                    Block(f"P{i}_pos", P, "psd"), Block(f"S{i}_pos", S, "psd"),
                    Block(f"R{i}_pos", R, "psd")]
            if lp.limited:
                sig = x["sigma"]
                for j, v in enumerate(box_vertices(lp.box)):
                    col = v.reshape(-1, 1)
                    out.append(Block(f"box{j}@{i}", sig - col.T @ (P + p["h"] * S) @ col,
                                     "psd"))
                out += self._limit_blocks(x, bmat, i, P,
                                          [sig @ K[k:k + 1, :] for k in range(lp.m)])
        return out
