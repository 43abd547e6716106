"""A basin-of-attraction problem: closed-loop vector field, equilibrium, V.

The vector field is the *delay-free* nonlinear closed loop. For a loop with
an input delay h and a predictor, this is the loop seen under exact
prediction: paper 003's Theorems 2 and 3 argue on it (the predicted state
x(t + h) replaces x(t) in the law, so that the delayed input acts as an
undelayed one). A basin computed here says nothing about a predictor error
or about a delayed term left in the law; the caller states which loop it
built (see :mod:`workbench.papers.p003.antiskid_basin` for paper 003's cruise law).

The Lyapunov function is quadratic, V(x) = (x - x*)' P (x - x*), with P
symmetric positive definite; its derivative along f is
V'(x) = 2 (x - x*)' P f(x), built symbolically once.

References
----------
.. [Khalil] H. K. Khalil, *Nonlinear Systems*, 3rd ed., 2002, section 8.2:
   estimates of the region of attraction by level sets {V <= c} on which
   V' < 0 (a positively invariant set inside the basin).
"""
from __future__ import annotations

import math
from functools import cached_property
from typing import Literal, Sequence

import numpy as np
import sympy as sp

from ..errors import ModelError
from .interval import IntervalFunction, Interval, iadd, imul
from .lyapunov import round_up

PSource = Literal["lyapunov", "modal", "certificate", "given", "optimised"]


def quadratic_enclosure(P: np.ndarray, x_eq: np.ndarray, lo: np.ndarray,
                        hi: np.ndarray) -> Interval:
    """Enclosure of (x - x*)' P (x - x*) on the boxes lo <= x <= hi ((N, n) arrays)."""
    n, N = P.shape[0], len(lo)
    full = lambda v: Interval(np.full(N, v), np.full(N, v))
    d = [iadd(Interval(lo[:, i], hi[:, i]), full(-x_eq[i])) for i in range(n)]
    acc = None
    for i in range(n):
        for j in range(i, n):
            if i == j:
                sq = imul(d[i], d[i])
                term = imul(Interval(np.maximum(sq.lo, 0.0), sq.hi), full(P[i, i]))
            else:
                term = imul(imul(d[i], d[j]), full(2.0 * P[i, j]))   # 2 P_ij: exact
            acc = term if acc is None else iadd(acc, term)
    return Interval(np.maximum(acc.lo, 0.0), acc.hi)


class BasinProblem:
    """f, x*, P of a region-of-attraction estimate.

    Parameters
    ----------
    f : sequence of sympy.Expr
        Closed-loop vector field x' = f(x), in ``states`` only.
    states : sequence of sympy.Symbol
    x_eq : sequence of float
        Equilibrium x* (f(x*) = 0 up to rounding; the residual is carried
        into the certificate, see :func:`workbench.roa.certify.ball_argument`).
    P : (n, n) array_like
        Symmetric positive definite matrix of V.
    P_source : {"lyapunov", "certificate", "given", "optimised"}
        How P was chosen (reported).
    names : sequence of str, optional
        Display names of the state coordinates (default: the symbols).
    derivatives : (jacobian, hessians), optional
        d f_i/d x_j and d^2 f_k/d x_i d x_j as nested lists of sympy
        expressions in ``states`` (a caller that builds many problems from
        one model derives them once); derived with ``sympy.diff`` otherwise.
    """

    def __init__(self, f: Sequence[sp.Expr], states: Sequence[sp.Symbol], x_eq: Sequence[float],
                 P, *, P_source: PSource = "given", names: Sequence[str] | None = None,
                 derivatives: tuple | None = None):
        self.f = tuple(sp.sympify(e) for e in f)
        self._derivs = derivatives
        self.states = tuple(states)
        n = len(self.states)
        if len(self.f) != n:
            raise ModelError(f"vector field has {len(self.f)} components for {n} states")
        self.x_eq = np.asarray(x_eq, float)
        P = np.asarray(P, float)
        if self.x_eq.shape != (n,) or P.shape != (n, n):
            raise ModelError(f"x_eq must have shape ({n},) and P ({n}, {n}); "
                             f"got {self.x_eq.shape} and {P.shape}")
        if not np.all(np.isfinite(P)) or not np.array_equal(P, P.T):
            raise ModelError("P must be a finite symmetric matrix")
        if not np.all(np.linalg.eigvalsh(P) > 0):
            raise ModelError("P must be positive definite")
        self.P = P
        self.P_source = P_source
        self.names = tuple(names) if names is not None else tuple(str(s) for s in self.states)

    # --- whitened coordinates z: x = x* + T z, T = L^-T with P = L L' ------------------
    # The box cover and the Taylor ball work in z, where {V <= c} is (almost) a
    # ball: an axis-aligned cover of a thin tilted ellipse would hold mostly
    # points outside it. T is any float matrix: V(x* + T z) = z' M z with
    # M = T' P T enclosed rigorously (close to I), and every expression in z is
    # the exact composition f(x* + T z), so rounding in T is harmless.
    @cached_property
    def T(self) -> np.ndarray:
        """L^-T rounded to 8 significant digits of its largest entry (any T is
        sound; a rounded one is the same on every CPU, so is the cover)."""
        T = np.linalg.inv(np.linalg.cholesky(self.P).T)
        scale = 10.0 ** (np.floor(np.log10(np.max(np.abs(T)))) - 7)
        return np.round(T / scale) * scale

    @cached_property
    def z(self) -> tuple:
        return tuple(sp.Symbol(f"_z{i}", real=True) for i in range(len(self.states)))

    @cached_property
    def M_interval(self) -> tuple[np.ndarray, np.ndarray]:
        """Rigorous enclosure (lo, hi) of M = T' P T."""
        n, T, P = len(self.states), self.T, self.P
        pt = lambda v: Interval(np.array([v]), np.array([v]))
        lo, hi = np.zeros((n, n)), np.zeros((n, n))
        for i in range(n):
            for j in range(n):
                acc = pt(0.0)
                for k in range(n):
                    for m in range(n):
                        acc = iadd(acc, imul(imul(pt(T[k, i]), pt(P[k, m])), pt(T[m, j])))
                lo[i, j], hi[i, j] = acc.lo[0], acc.hi[0]
        return np.minimum(lo, lo.T), np.maximum(hi, hi.T)

    def M_eig_bounds(self) -> tuple[float, float]:
        """(lower bound of lambda_min, upper bound of lambda_max) over the
        symmetric matrices of the enclosure of M (Rohn: mid +- ||radius||_F;
        1e-12 relative allowance for LAPACK's rounding)."""
        lo, hi = self.M_interval
        mid = 0.5 * (lo + hi)
        rad = float(np.linalg.norm(np.nextafter(np.maximum(hi - mid, mid - lo), np.inf)))
        ev = np.linalg.eigvalsh(mid)
        slack = 1e-12 * len(ev) * float(np.linalg.norm(mid)) + rad * (1 + 1e-12)
        return float(ev[0] - slack), float(ev[-1] + slack)

    @cached_property
    def jacobian(self) -> list:
        """d f_i / d x_j (sympy; given to the constructor or derived once)."""
        if self._derivs is not None:
            return self._derivs[0]
        return [[sp.diff(fi, s) for s in self.states] for fi in self.f]

    @cached_property
    def hessians(self) -> list:
        """d^2 f_k / d x_i d x_j (sympy; given or derived once)."""
        if self._derivs is not None:
            return self._derivs[1]
        return [[[sp.diff(Jki, s) for s in self.states] for Jki in row] for row in self.jacobian]

    # Each interval function in z is a chain of stages (IntervalFunction
    # ``stages``): x = x* + T z; f, J, H at x; e = T z; P e; then small
    # products. Nothing is differentiated or expanded per problem.
    @cached_property
    def _sym(self) -> dict:
        n, mk = len(self.states), lambda name: sp.Symbol(name, real=True)
        return {"F": [mk(f"_F{k}") for k in range(n)],
                "J": [[mk(f"_J{k}_{i}") for i in range(n)] for k in range(n)],
                "H": [[[mk(f"_H{k}_{i}_{j}") for j in range(n)] for i in range(n)]
                      for k in range(n)],
                "E": [mk(f"_E{i}") for i in range(n)], "PE": [mk(f"_PE{i}") for i in range(n)],
                "G": [mk(f"_G{i}") for i in range(n)],
                "PJ": [[mk(f"_PJ{i}_{j}") for j in range(n)] for i in range(n)],
                "HX": [[mk(f"_HX{i}_{j}") for j in range(n)] for i in range(n)]}

    def _stages(self, *, jac: bool = False, hess: bool = False, values: bool = True) -> list:
        n, S = len(self.states), self._sym
        Fl = lambda v: sp.Float(float(v))
        x_st = [(s, Fl(self.x_eq[i]) + sum(Fl(self.T[i, j]) * self.z[j] for j in range(n)))
                for i, s in enumerate(self.states)]
        model = []
        if values:
            model += list(zip(S["F"], self.f))
        if jac:
            model += [(S["J"][k][i], self.jacobian[k][i]) for k in range(n) for i in range(n)]
        if hess:
            model += [(S["H"][k][i][j], self.hessians[k][i][j])
                      for k in range(n) for i in range(n) for j in range(n)]
        e_st = [(S["E"][i], sum(Fl(self.T[i, j]) * self.z[j] for j in range(n))) for i in range(n)]
        pe_st = [(S["PE"][i], sum(Fl(self.P[i, j]) * S["E"][j] for j in range(n)))
                 for i in range(n)]
        return [x_st, model, e_st, pe_st]

    @cached_property
    def vdot_z_interval(self) -> IntervalFunction:
        """V'(x* + T z) = 2 (P e)' f(x* + T z), e = T z."""
        S = self._sym
        out = 2 * sum(pe * F for pe, F in zip(S["PE"], S["F"]))
        return IntervalFunction([out], self.z, self._stages())

    @cached_property
    def vdot_z_grad_interval(self) -> IntervalFunction:
        """d V'/d z = T' g, g_i = 2 (P f)_i + 2 sum_k (P e)_k J_ki (chain rule)."""
        n, S, Fl = len(self.states), self._sym, lambda v: sp.Float(float(v))
        g_st = [(S["G"][i], 2 * sum(Fl(self.P[i, k]) * S["F"][k] for k in range(n))
                 + 2 * sum(S["PE"][k] * S["J"][k][i] for k in range(n))) for i in range(n)]
        outs = [sum(Fl(self.T[i, a]) * S["G"][i] for i in range(n)) for a in range(n)]
        return IntervalFunction(outs, self.z, [*self._stages(jac=True), g_st])

    @cached_property
    def vdot_z_hessian_interval(self) -> IntervalFunction:
        """d^2 V'/d z^2 = T' H T, H = 2 (P J + (P J)' + sum_k (P e)_k H_k)."""
        n, S, Fl = len(self.states), self._sym, lambda v: sp.Float(float(v))
        pj = [(S["PJ"][i][j], sum(Fl(self.P[i, k]) * S["J"][k][j] for k in range(n)))
              for i in range(n) for j in range(n)]
        hx = [(S["HX"][i][j], 2 * (S["PJ"][i][j] + S["PJ"][j][i]
                                   + sum(S["PE"][k] * S["H"][k][i][j] for k in range(n))))
              for i in range(n) for j in range(n)]
        outs = [sum(Fl(self.T[i, a]) * S["HX"][i][j] * Fl(self.T[j, b])
                    for i in range(n) for j in range(n)) for a in range(n) for b in range(n)]
        stages = self._stages(jac=True, hess=True, values=False)
        return IntervalFunction(outs, self.z, [*stages, pj, hx])

    def V_interval_z(self, lo: np.ndarray, hi: np.ndarray) -> Interval:
        """Enclosure of V = z' M z on the z-boxes lo <= z <= hi ((N, n))."""
        n, N = len(self.states), len(lo)
        Mlo, Mhi = self.M_interval
        zs = [Interval(lo[:, i], hi[:, i]) for i in range(n)]
        acc = None
        for i in range(n):
            for j in range(i, n):
                if i == j:
                    sq = imul(zs[i], zs[i])
                    prod = Interval(np.maximum(sq.lo, 0.0), sq.hi)
                    m = Interval(np.full(N, Mlo[i, i]), np.full(N, Mhi[i, i]))
                else:
                    prod = imul(zs[i], zs[j])
                    m = Interval(np.full(N, 2.0 * Mlo[i, j]), np.full(N, 2.0 * Mhi[i, j]))
                term = imul(prod, m)
                acc = term if acc is None else iadd(acc, term)
        return Interval(np.maximum(acc.lo, 0.0), acc.hi)

    def vdot_enclosure(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Interval, np.ndarray]:
        """Enclosure of V' on z-boxes: the natural extension intersected, where
        no Piecewise condition is undetermined, with the mean-value form
        V'(m) + sum_i [d V'/d z_i](box) [z_i - m_i] (m the box centre).

        Returns (enclosure, ambiguous) -- ``ambiguous`` as in
        :class:`~workbench.roa.interval.IntervalFunction`.
        """
        (nat,), amb = self.vdot_z_interval(lo, hi)
        mid = 0.5 * (lo + hi)
        (at_mid,), amb_m = self.vdot_z_interval(mid, mid)
        grads, amb_g = self.vdot_z_grad_interval(lo, hi)
        acc = at_mid
        for i, g in enumerate(grads):
            dx = iadd(Interval(lo[:, i], hi[:, i]), Interval(-mid[:, i], -mid[:, i]))
            acc = iadd(acc, imul(g, dx))
        amb = amb | amb_m | amb_g
        lo_v = np.where(amb, nat.lo, np.maximum(nat.lo, acc.lo))
        hi_v = np.where(amb, nat.hi, np.minimum(nat.hi, acc.hi))
        return Interval(lo_v, hi_v), amb

    def bounding_box_z(self, c: float) -> tuple[np.ndarray, np.ndarray]:
        """A z-box containing {V <= c} = {z' M z <= c}: |z_i| <= sqrt(c /
        lambda_min(M)), enlarged by 1e-6 relative and rounded up to 3
        significant digits (the cover then does not depend on the last bits
        LAPACK returns)."""
        lam_min, _ = self.M_eig_bounds()
        if not lam_min > 0:
            raise ModelError("T' P T is not provably positive definite")
        half = float(round_up(math.sqrt(c / lam_min) * (1 + 1e-6), 3))
        n = len(self.states)
        return np.full(n, -half), np.full(n, half)

    # --- original coordinates x ------------------------------------------------------------
    @cached_property
    def error(self) -> sp.Matrix:
        return sp.Matrix([s - sp.Float(float(x)) for s, x in zip(self.states, self.x_eq)])

    @cached_property
    def Pm(self) -> sp.Matrix:
        return sp.Matrix(self.P.shape[0], self.P.shape[1], lambda i, j: sp.Float(self.P[i, j]))

    @cached_property
    def vdot(self) -> sp.Expr:
        """V'(x) = 2 (x - x*)' P f(x)."""
        return 2 * (self.error.T * self.Pm * sp.Matrix(self.f))[0, 0]

    @cached_property
    def vdot_grad(self) -> list[sp.Expr]:
        """d V'/d x = 2 P f + 2 J' P e (chain rule on the given derivatives)."""
        n = len(self.states)
        e = list(self.error)
        Pe = [sum(sp.Float(self.P[i, j]) * e[j] for j in range(n)) for i in range(n)]
        return [2 * sum(sp.Float(self.P[i, k]) * self.f[k] for k in range(n))
                + 2 * sum(Pe[k] * self.jacobian[k][i] for k in range(n)) for i in range(n)]

    # --- numeric (floats) ------------------------------------------------------------------
    @cached_property
    def vdot_numeric(self):
        """(x: (N, n) array) -> V'(x), floats (for the falsification search)."""
        fn = sp.lambdify(self.states, self.vdot, "numpy", cse=True)
        return lambda X: np.broadcast_to(fn(*np.asarray(X, float).T), (np.atleast_2d(X).shape[0],))

    @cached_property
    def vdot_grad_numeric(self):
        fn = sp.lambdify(self.states, self.vdot_grad, "numpy", cse=True)
        return lambda x: np.array(fn(*np.asarray(x, float)), float)

    def V(self, X) -> np.ndarray:
        """V at points (N, n), floats."""
        E = np.atleast_2d(np.asarray(X, float)) - self.x_eq
        return np.einsum("ni,ij,nj->n", E, self.P, E)

    # --- interval enclosures ---------------------------------------------------------------
    @cached_property
    def vdot_interval(self) -> IntervalFunction:
        return IntervalFunction([self.vdot], self.states)

    def V_interval(self, lo: np.ndarray, hi: np.ndarray) -> Interval:
        """Enclosure of V on the boxes lo <= x <= hi ((N, n) arrays)."""
        return quadratic_enclosure(self.P, self.x_eq, lo, hi)

    def level_of(self, x) -> Interval:
        """Rigorous enclosure of V at one point x."""
        x = np.asarray(x, float)[None, :]
        return self.V_interval(x, x)
