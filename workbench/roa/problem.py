"""A basin-of-attraction problem: closed-loop vector field, equilibrium, V.

The vector field is the *delay-free* nonlinear closed loop. For a loop with
an input delay h and a predictor, this is the loop seen under exact
prediction: paper 003's Theorems 2 and 3 argue on it (the predicted state
x(t + h) replaces x(t) in the law, so that the delayed input acts as an
undelayed one). A basin computed here says nothing about a predictor error
or about a delayed term left in the law; the caller states which loop it
built (see :mod:`workbench.studies.antiskid_basin` for paper 003's cruise law).

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

from dataclasses import dataclass
from functools import cached_property
from typing import Literal, Sequence

import numpy as np
import scipy.linalg as sla
import sympy as sp

from ..errors import ModelError
from .interval import IntervalFunction, Interval, iadd, imul

PSource = Literal["lyapunov", "certificate", "given", "optimised"]


def round_up(x, digits: int) -> np.ndarray:
    """x >= 0 rounded up to ``digits`` significant digits (elementwise)."""
    x = np.asarray(x, float)
    e = np.floor(np.log10(np.where(x > 0, x, 1.0))) - (digits - 1)
    return np.where(x > 0, np.ceil(x / 10.0**e) * 10.0**e, 0.0)


def lyapunov_P(A_cl, Q=None, *, digits: int = 10) -> np.ndarray:
    """P of the Lyapunov equation A_cl' P + P A_cl = -Q (Q = I by default).

    Parameters
    ----------
    A_cl : (n, n) array_like
        Closed-loop linearisation A + B K at the equilibrium (Hurwitz).
    Q : (n, n) array_like, optional
        Symmetric positive definite weight.
    digits : int
        P is rounded to this many significant digits (relative to its
        largest entry): V is then the same function on every CPU, whatever
        the last bits LAPACK returns.

    Raises
    ------
    ModelError
        When A_cl is not Hurwitz or P is not positive definite.
    """
    A = np.asarray(A_cl, float)
    Q = np.eye(A.shape[0]) if Q is None else np.asarray(Q, float)
    eig = np.linalg.eigvals(A)
    if not np.all(eig.real < 0):
        raise ModelError(f"closed-loop linearisation is not Hurwitz: eigenvalues {eig}")
    P = sla.solve_continuous_lyapunov(A.T, -Q)
    P = 0.5 * (P + P.T)
    scale = 10.0 ** (np.floor(np.log10(np.max(np.abs(P)))) - digits + 1)
    P = np.round(P / scale) * scale
    if not np.all(np.linalg.eigvalsh(P) > 0):
        raise ModelError("Lyapunov equation gave a P that is not positive definite")
    return P


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
    """

    def __init__(self, f: Sequence[sp.Expr], states: Sequence[sp.Symbol], x_eq: Sequence[float],
                 P, *, P_source: PSource = "given", names: Sequence[str] | None = None):
        self.f = tuple(sp.sympify(e) for e in f)
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

    # --- symbolic --------------------------------------------------------------------------
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
        return [sp.diff(self.vdot, s) for s in self.states]

    @cached_property
    def vdot_hessian(self) -> list[list[sp.Expr]]:
        return [[sp.diff(g, s) for s in self.states] for g in self.vdot_grad]

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

    @cached_property
    def f_numeric(self):
        """(x: (N, n)) -> f(x) as (N, n), floats (trajectory sampling)."""
        fn = sp.lambdify(self.states, list(self.f), "numpy", cse=True)

        def run(X):
            X = np.atleast_2d(np.asarray(X, float))
            out = fn(*X.T)
            return np.stack([np.broadcast_to(np.asarray(o, float), (X.shape[0],)) for o in out], 1)
        return run

    def V(self, X) -> np.ndarray:
        """V at points (N, n), floats."""
        E = np.atleast_2d(np.asarray(X, float)) - self.x_eq
        return np.einsum("ni,ij,nj->n", E, self.P, E)

    # --- interval enclosures ---------------------------------------------------------------
    @cached_property
    def vdot_interval(self) -> IntervalFunction:
        return IntervalFunction([self.vdot], self.states)

    @cached_property
    def vdot_grad_interval(self) -> IntervalFunction:
        return IntervalFunction(self.vdot_grad, self.states)

    @cached_property
    def vdot_hessian_interval(self) -> IntervalFunction:
        return IntervalFunction([h for row in self.vdot_hessian for h in row], self.states)

    @cached_property
    def f_interval(self) -> IntervalFunction:
        return IntervalFunction(list(self.f), self.states)

    def V_interval(self, lo: np.ndarray, hi: np.ndarray) -> Interval:
        """Enclosure of V on the boxes lo <= x <= hi ((N, n) arrays)."""
        return quadratic_enclosure(self.P, self.x_eq, lo, hi)

    def vdot_enclosure(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Interval, np.ndarray]:
        """Enclosure of V' on boxes: the natural extension intersected, where
        no Piecewise condition is undetermined, with the mean-value form
        V'(m) + sum_i [d V'/d x_i](box) [x_i - m_i] (m the box centre).

        Returns (enclosure, ambiguous) -- ``ambiguous`` as in
        :class:`~workbench.roa.interval.IntervalFunction`.
        """
        (nat,), amb = self.vdot_interval(lo, hi)
        mid = 0.5 * (lo + hi)
        (at_mid,), amb_m = self.vdot_interval(mid, mid)
        grads, amb_g = self.vdot_grad_interval(lo, hi)
        acc = at_mid
        for i, g in enumerate(grads):
            dx = iadd(Interval(lo[:, i], hi[:, i]), Interval(-mid[:, i], -mid[:, i]))
            acc = iadd(acc, imul(g, dx))
        amb = amb | amb_m | amb_g
        lo_v = np.where(amb, nat.lo, np.maximum(nat.lo, acc.lo))
        hi_v = np.where(amb, nat.hi, np.minimum(nat.hi, acc.hi))
        return Interval(lo_v, hi_v), amb

    def level_of(self, x) -> Interval:
        """Rigorous enclosure of V at one point x."""
        x = np.asarray(x, float)[None, :]
        return self.V_interval(x, x)

    def bounding_box(self, c: float) -> tuple[np.ndarray, np.ndarray]:
        """A box containing the ellipsoid {V <= c} (half-widths
        sqrt(c (P^-1)_ii), enlarged by 1e-6 relative for rounding, then rounded
        up to 3 significant digits so that the cover does not depend on the
        last bits LAPACK returns)."""
        half = round_up(np.sqrt(c * np.diag(np.linalg.inv(self.P))) * (1 + 1e-6), 3)
        return self.x_eq - half, self.x_eq + half
