"""Verified level sets: V' < 0 on {c_inner < V <= c}, by interval arithmetic.

Both arguments work in whitened coordinates z, x = x* + T z with P = L L',
T = L^-T (:class:`~workbench.roa.problem.BasinProblem`), where the level sets
are near-balls; V = z' M z with M = T' P T enclosed rigorously.

Two arguments, each sound on its own region:

1. **Ball around the equilibrium** (:func:`ball_argument`). Interval boxes
   cannot prove V' < 0 on tiny boxes at x*, where V' ~ -e'Qe is quadratically
   small; there Taylor's theorem is used instead. With e = x - x*,
   V'(x*) = 0 exactly (V' = 2 e'P f), so

       V'(x) = g'e + 1/2 e' H_bar e,   g = grad V'(x*) = 2 P f(x*)

   (written here in x; the code applies it to V'(x* + T z) in z, with
   |z| and c_inner = lambda_max(M) (2 |g| / mu)^2),

   where H_bar = 2 int_0^1 (1 - s) H(x* + s e) ds lies in the convex hull of
   the Hessian of V' on any convex set holding the segment, here the
   bounding box B of the ellipsoid {V <= c0}. If every symmetric matrix of
   the interval Hessian [H](B) has eigenvalues <= -mu < 0 (bounded by
   lambda_max(mid) + ||radius||_F, Rohn's bound; lambda_max(mid) from LAPACK
   plus a 1e-12 relative allowance for its rounding), then
   V'(x) <= |g| |e| - mu |e|^2 / 2 < 0 whenever |e| > 2 |g| / mu, which holds
   for V > c_inner = lambda_max(P) (2 |g| / mu)^2. g vanishes when
   f(x*) = 0 exactly (then c_inner = 0); otherwise the residual of the
   equilibrium leaves the tiny set {V <= c_inner}, which holds the true
   equilibrium, uncertified. The argument needs V' twice differentiable on
   B: it is refused when a Piecewise condition is undetermined on B. c0 is
   the largest of c, c/4, c/16, ... that passes.

2. **Annulus** (:func:`verify_annulus`): an adaptive box cover of
   {c0 < V <= c}, branch and bound in layers. A box is dropped when V > c
   on it, when V <= c0 on it (the ball), or when the enclosure of V' on it
   (:meth:`~workbench.roa.problem.BasinProblem.vdot_enclosure`) is < 0;
   otherwise it is split in two across its widest side. A box whose width
   is below ``min_width`` times its distance from x* (at least the ball's
   radius) and is still unresolved lowers the
   level to the lower bound of V on it: every point of a lower level lies in
   a box that was proven or discarded, so V' < 0 on {c0 < V <= c_certified}.

References
----------
.. [Rohn] J. Rohn, "Bounds on eigenvalues of interval matrices", ZAMM 78,
   suppl. 3 (1998), S1049-S1050: lambda(A_c + Delta) within
   lambda(A_c) +- rho(Delta) for symmetric interval matrices.
.. [Khalil] H. K. Khalil, *Nonlinear Systems*, 3rd ed., 2002, section 8.2.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .problem import BasinProblem


@dataclass(frozen=True)
class BallResult:
    """Outcome of the Taylor argument at the equilibrium.

    Attributes
    ----------
    c_ball : float
        V' < 0 on {c_inner < V <= c_ball} (0: the argument failed).
    c_inner : float
        Level of the uncertified residual set around x* (0 when f(x*) = 0
        exactly).
    mu : float
        Proven lower bound of -lambda_max of the Hessian of V' on the ball's box.
    """

    c_ball: float
    c_inner: float
    mu: float


def _lambda_max_upper(M: np.ndarray) -> float:
    """Upper bound of lambda_max of a symmetric float matrix (LAPACK result
    plus a 1e-12 relative allowance for its rounding)."""
    lam = float(np.linalg.eigvalsh(M)[-1])
    return lam + 1e-12 * M.shape[0] * float(np.linalg.norm(M)) + 1e-300


def _neg_def_margin(L: np.ndarray, U: np.ndarray) -> float:
    """mu > 0 with z' H z <= -mu |z|^2 for every symmetric H with L <= H <= U
    (0 when not shown). Rohn's bound after a diagonal congruence D H D,
    D = diag(|mid_ii|^-1/2) (exact powers of two), so that a Hessian with very
    different diagonal entries (slow and fast modes) is judged on its
    relative spread: lambda_max(D H D) <= -m gives mu = m min_i d_i^-2."""
    mid = 0.5 * (L + U)
    diag = np.abs(np.diag(mid))
    if not np.all(diag > 0):
        return 0.0
    d = 2.0 ** np.round(-0.5 * np.log2(diag))          # powers of two: scaling is exact
    Ls, Us = L * np.outer(d, d), U * np.outer(d, d)
    ms = 0.5 * (Ls + Us)
    rad = np.nextafter(np.maximum(Us - ms, ms - Ls), np.inf)
    m = -(_lambda_max_upper(ms) + float(np.linalg.norm(rad)) * (1 + 1e-12))
    return float(m * np.min(1.0 / d**2)) if m > 0 else 0.0


def ball_argument(problem: BasinProblem, c_start: float, *, shrinks: int = 40) -> BallResult:
    """Largest c0 in {c_start 4^-k} on which the Hessian argument proves V' < 0
    (module docstring, argument 1).

    Parameters
    ----------
    problem : BasinProblem
    c_start : float
        First level tried (> 0).
    shrinks : int
        Number of divisions by 4 tried before giving up.
    """
    n = len(problem.states)
    z0 = np.zeros((1, n))
    grads, amb0 = problem.vdot_z_grad_interval(z0, z0)
    g_mag = np.array([max(abs(g.lo[0]), abs(g.hi[0])) for g in grads])
    g_norm = float(np.nextafter(np.sqrt(np.sum(g_mag**2)) * (1 + 1e-15), np.inf))
    if not np.isfinite(g_norm) or bool(amb0[0]):
        return BallResult(0.0, 0.0, 0.0)
    _, lam_M = problem.M_eig_bounds()
    c0 = float(c_start)
    for _ in range(shrinks + 1):
        lo, hi = problem.bounding_box_z(c0)
        ents, amb = problem.vdot_z_hessian_interval(lo[None, :], hi[None, :])
        if not amb[0]:
            L = np.array([e.lo[0] for e in ents]).reshape(n, n)
            U = np.array([e.hi[0] for e in ents]).reshape(n, n)
            L, U = np.maximum(L, L.T), np.minimum(U, U.T)     # both enclose the symmetric H
            if np.all(np.isfinite(L)) and np.all(np.isfinite(U)) and np.all(L <= U):
                mu = _neg_def_margin(L, U)
                if mu > 0:
                    rho = 2.0 * g_norm / mu
                    c_inner = 0.0 if g_norm == 0 else lam_M * rho * rho * (1 + 1e-9)
                    if c_inner < c0:
                        return BallResult(c0, c_inner, mu)
        c0 /= 4.0
    return BallResult(0.0, 0.0, 0.0)


def _to_x(problem: BasinProblem, z: np.ndarray) -> tuple:
    return tuple(float(v) for v in problem.x_eq + problem.T @ z)


@dataclass(frozen=True)
class AnnulusResult:
    """Outcome of the box cover of {c0 < V <= c_top}.

    Attributes
    ----------
    c_certified : float
        V' < 0 on {c0 < V <= c_certified} (c_certified == c_top: the whole
        annulus).
    boxes : int
        Boxes evaluated.
    unresolved : int
        Boxes left at the smallest width (or at the box budget) without a sign.
    budget_hit : bool
        The layer size exceeded ``max_boxes``: the remaining boxes count as
        unresolved.
    witness : tuple or None
        Centre of the unresolved box of lowest V (a lead for the falsifier).
    """

    c_certified: float
    boxes: int
    unresolved: int
    budget_hit: bool
    witness: tuple | None


def verify_annulus(problem: BasinProblem, c0: float, c_top: float, *,
                   min_width: float = 2.0**-12, max_boxes: int = 400_000) -> AnnulusResult:
    """Adaptive interval cover of {c0 < V <= c_top} (module docstring, argument 2).

    Parameters
    ----------
    problem : BasinProblem
    c0 : float
        Level below which the ball argument holds (V <= c0 is skipped).
    c_top : float
        Level to verify.
    min_width : float
        Smallest box width, relative to the box's distance from x* (at
        least the radius of the ball {V <= c0}): near x*, where V' is
        quadratically small, boxes may be as small as they need.
    max_boxes : int
        Largest number of boxes in one layer.
    """
    lo0, hi0 = problem.bounding_box_z(c_top)
    _, lam_M = problem.M_eig_bounds()
    r0 = np.sqrt(max(c0, 1e-300) / lam_M)
    lo, hi = lo0[None, :], hi0[None, :]
    c_bound, boxes, unresolved, budget_hit, witness = c_top, 0, 0, False, None
    while len(lo):
        Vi = problem.V_interval_z(lo, hi)
        live = (Vi.lo <= c_bound) & (Vi.hi > c0)
        lo, hi, vlo = lo[live], hi[live], Vi.lo[live]
        if not len(lo):
            break
        boxes += len(lo)
        vd, _ = problem.vdot_enclosure(lo, hi)
        open_ = ~(vd.hi < 0)
        lo, hi, vlo = lo[open_], hi[open_], vlo[open_]
        width = (hi - lo).max(axis=1)
        dist = np.maximum(np.sqrt(vlo / lam_M), r0)       # lower bound of |z| on the box
        small = width <= min_width * dist
        rel = hi - lo
        if small.any():
            k = int(np.argmin(np.where(small, vlo, np.inf)))
            if vlo[k] < c_bound:
                c_bound, witness = float(vlo[k]), _to_x(problem, 0.5 * (lo[k] + hi[k]))
            unresolved += int(small.sum())
        go = ~small & (vlo <= c_bound)
        lo, hi, rel = lo[go], hi[go], rel[go]
        if 2 * len(lo) > max_boxes:
            budget_hit, unresolved = True, unresolved + len(lo)
            vlo_all = problem.V_interval_z(lo, hi).lo
            k = int(np.argmin(vlo_all))
            if vlo_all[k] < c_bound:
                c_bound, witness = float(vlo_all[k]), _to_x(problem, 0.5 * (lo[k] + hi[k]))
            break
        axis = np.argmax(rel, axis=1)
        rows = np.arange(len(lo))
        mid = 0.5 * (lo[rows, axis] + hi[rows, axis])
        lo_b, hi_a = lo.copy(), hi.copy()
        hi_a[rows, axis] = mid
        lo_b[rows, axis] = mid
        lo, hi = np.concatenate([lo, lo_b]), np.concatenate([hi_a, hi])
    c_cert = c_top if c_bound >= c_top else float(np.nextafter(max(c_bound, 0.0), 0.0))
    return AnnulusResult(max(c_cert, c0), boxes, unresolved, budget_hit, witness)
