"""Certified stability under aperiodic sampling: one quadratic Lyapunov function
for every lifted map, proved over the continuum of sampling intervals.

For x' = A x + B u, u(t) = K x(t_k) on [t_k, t_{k+1}) (zero-order hold, no
delay) with ANY sequence of intervals T_k = t_{k+1} - t_k in [T_min, T_max]
(T_min >= 0; t_k -> inf), the samples obey x_{k+1} = Ad(T_k) x_k with

    Ad(s) = e^{As} + Psi(s) B K = I + s D(s) Acl,    Acl = A + B K,
    D(s) = int_0^1 e^{A s v} dv   (D(0) = I).

**Theorem** (the discrete-time / convex-embedding approach of Fujioka 2009
and Oishi & Fujioka 2010, written per unit time so that T_k -> 0 is
covered; Hetel et al. 2017, sec. 5). If P = P' > 0 and, for every s in
[T_min, T_max],

    M(s) := (Ad(s)' P Ad(s) - P) / s + 2 alpha P
          = Acl' D' P + P D Acl + s Acl' D' P D Acl + 2 alpha P  <= -eps I,

then V(x) = x' P x obeys V(x_{k+1}) <= (1 - 2 alpha T_k) V(x_k) - eps T_k |x_k|^2
<= e^{-2 alpha T_k} V(x_k) for every interval sequence in the range: the
samples decay at least like e^{-alpha t} (and strictly), and between samples
|x(t)| <= (||e^{As}|| + ||Psi(s) B K||) |x_k| with s <= T_max, so the loop is
uniformly exponentially stable for every such sequence (rate alpha where one is
required). At s = 0 the condition is the continuous Lyapunov inequality of
Acl.

How the continuum of s is decided (no strict LMIs, no gridding gap):

1. **LMI on a grid.** Maximise t over P with ``P >= t I, trace P <= 1`` and
   ``tau0 M(s_i) <= -t I, trace(-tau0 M(s_i)) <= 1`` at grid points s_i,
   tau0 = 1 / (||A|| + ||B K||) the loop's time scale (so the margin is
   scale-free, as in :mod:`workbench.lmi.core`). The grid points are a
   subset of the range, so ``t* < margin`` (solver optimal) refutes the
   criterion for the whole range: REFUTED.
2. **Continuum re-check with numpy** (:func:`continuum_margin`). On each cell
   [c - delta, c + delta] of the range, with M and M' evaluated at the centre
   (one 3n-by-3n matrix exponential), Taylor's theorem gives
   M(s) = M(c) + (s - c) M'(c) + R, ||R|| <= L2 delta^2 / 2 with
   L2 >= sup ||M''|| from the bounds ||D|| <= g, ||D'|| <= ||A|| g / 2,
   ||D''|| <= ||A||^2 g / 3, g = e^{max(mu(A), 0) s} (mu the 2-norm
   logarithmic norm). lambda_max of an affine matrix function is convex, so
   sup_cell lambda_max(M) <= max_{+/-} lambda_max(M(c) +/- delta M'(c)) + L2 delta^2 / 2.
   Cells are halved until that bound is below ``-margin`` (relative to the
   largest block's nuclear norm); a centre where M itself fails is added to
   the grid and the LMI is solved again (cutting planes, a few rounds).
3. CERTIFIED only when the solver says optimal and the numpy re-check of P,
   of every grid block and of the continuum bound all hold with the margin.

References
----------
Fujioka, H. (2009). Stability analysis of systems with aperiodic
sample-and-hold devices. Automatica 45(3), 771-775.
Oishi, Y., Fujioka, H. (2010). Stability and stabilization of aperiodic
sampled-data control systems using robust linear matrix inequalities.
Automatica 46(8), 1327-1333.
Hetel, L., Fiter, C., Omran, H., Seuret, A., Fridman, E., Richard, J.-P.,
Niculescu, S.-I. (2017). Recent developments on the stability of systems with
aperiodic sampling: an overview. Automatica 76, 309-335.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import cvxpy as cp
import numpy as np
import scipy.linalg as sl

from .core import DEFAULT_MARGIN, Bracket, Outcome, Step, bisect_delay, guarded_solve
from .scaling import balancing

__all__ = ["LiftedFamily", "continuum_margin", "decide_lifted", "certified_sampling_bound",
           "SamplingBound"]

#: Wall-clock cap (s) of a sampling-bound search (issue 32): past it the bracket so far
#: is returned, INCONCLUSIVE without a certified point, with the cap as a step's reason.
MAX_SECONDS = 600.0
#: Grid points of the first LMI solve on [T_min, T_max].
INITIAL_GRID = 12
#: Cutting-plane rounds (LMI solve + continuum re-check) per sampling bound.
ROUNDS = 12
#: Budget of cell evaluations of one continuum re-check.
CELL_BUDGET = 40000


class LiftedFamily:
    """The maps s -> (M(s), M'(s)) of the module docstring for one loop.

    The loop is first balanced: z = S^{-1} x with S the diagonal power-of-two
    balancing of A + B K (:func:`workbench.lmi.scaling.balancing`; exact in
    floating point, stability unchanged), so A, B, K and the certificate's P
    below are those of the balanced coordinates (P_x = S^{-T} P S^{-1}).

    Parameters
    ----------
    A, B, K : array_like
        Plant (n x n, n x m) and gain (m x n).
    """

    def __init__(self, A, B, K):
        A, B, K = (np.asarray(M, dtype=float) for M in (A, B, K))
        S = balancing(A + B @ K)
        Sinv = np.diag(1.0 / np.diag(S))
        self.S = S
        self.A, self.B, self.K = Sinv @ A @ S, Sinv @ B, K @ S
        n = self.A.shape[0]
        self.n = n
        self.Acl = self.A + self.B @ self.K
        nA, nBK = np.linalg.norm(self.A, 2), np.linalg.norm(self.B @ self.K, 2)
        if not nA + nBK > 0:
            raise ValueError("A = B K = 0 has no time scale; expected a loop with dynamics")
        self.tau0 = 1.0 / (nA + nBK)
        self.normA, self.normAcl = nA, np.linalg.norm(self.Acl, 2)
        self.mu = float(np.linalg.eigvalsh((self.A + self.A.T) / 2)[-1])

    def D(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """(D(s), D'(s)) from one 3n-by-3n matrix exponential."""
        n = self.n
        N = np.zeros((3 * n, 3 * n))
        N[:n, :n] = self.A * s
        N[:n, n:2 * n] = np.eye(n)
        N[n:2 * n, 2 * n:] = np.eye(n)
        E = sl.expm(N)
        D, E13 = E[:n, n:2 * n], E[:n, 2 * n:]        # int e^{Asv} dv, int e^{Asv}(1-v) dv
        return D, self.A @ (D - E13)

    def terms(self, s: float) -> tuple[np.ndarray, np.ndarray]:
        """(G, G') with G(s) = D(s) Acl: M = G'P + PG + s G'PG (+ 2 alpha P)."""
        D, D1 = self.D(s)
        return D @ self.Acl, D1 @ self.Acl

    def M(self, P, s: float, alpha: float = 0.0, bmat=None):
        """tau0 M(s) (cvxpy expression or numpy array, depending on P)."""
        G, _ = self.terms(s)
        out = G.T @ P + P @ G + s * (G.T @ P @ G) + 2 * alpha * P
        return self.tau0 * out

    def M_and_slope(self, P: np.ndarray, s: float, alpha: float) -> tuple[np.ndarray, np.ndarray]:
        """tau0 M(s) and tau0 M'(s) as numpy arrays."""
        G, G1 = self.terms(s)
        GPG = G.T @ P @ G
        M = G.T @ P + P @ G + s * GPG + 2 * alpha * P
        cross = G1.T @ P @ G
        M1 = G1.T @ P + P @ G1 + GPG + s * (cross + cross.T)
        return self.tau0 * M, self.tau0 * M1

    def curvature(self, P: np.ndarray, s_hi: float) -> float:
        """Upper bound on tau0 ||M''(s)|| for 0 <= s <= s_hi (module docstring)."""
        g = math.exp(max(self.mu, 0.0) * s_hi)
        d0, d1, d2 = g, self.normA * g / 2, self.normA ** 2 * g / 3
        a, p = self.normAcl, np.linalg.norm(P, 2)
        return self.tau0 * (2 * a * p * d2 + 4 * a * a * p * d0 * d1
                            + s_hi * a * a * p * (2 * d2 * d0 + 2 * d1 * d1))


def _sym(M):
    return (M + M.T) / 2


def continuum_margin(fam: LiftedFamily, P: np.ndarray, grid, alpha: float, scale: float,
                     margin: float) -> tuple[float, list[float]]:
    """Certified lower bound on the relative margin of M(s) over the grid's hull.

    Returns ``(bound, cuts)``: ``bound`` >= ``margin`` proves
    ``lambda_max(tau0 M(s)) <= -margin * scale`` for every s in
    [grid[0], grid[-1]]; ``cuts`` are points where M itself fails that
    margin (or cells the budget could not settle), to add to the grid.
    """
    target = -margin * scale
    stack = [(float(a), float(b)) for a, b in zip(grid[:-1], grid[1:]) if b > a]
    worst, cuts, used = math.inf, [], 0
    while stack:
        a, b = stack.pop()
        c, delta = 0.5 * (a + b), 0.5 * (b - a)
        Mc, M1 = fam.M_and_slope(P, c, alpha)
        used += 1
        point = float(np.linalg.eigvalsh(_sym(Mc))[-1])
        if point > target:
            cuts.append(c)
            worst = min(worst, -point / scale)
            continue
        lin = max(float(np.linalg.eigvalsh(_sym(Mc + sgn * delta * M1))[-1]) for sgn in (-1, 1))
        bound = lin + fam.curvature(P, b) * delta * delta / 2
        if bound <= target:
            worst = min(worst, -bound / scale)
        elif used + len(stack) >= CELL_BUDGET:
            cuts.append(c)
            worst = min(worst, -bound / scale)
        else:
            stack += [(a, c), (c, b)]
    return worst, sorted(cuts)


def _solve_grid(fam: LiftedFamily, grid, alpha: float):
    n = fam.n
    P, t = cp.Variable((n, n), symmetric=True), cp.Variable()
    cons = [P >> t * np.eye(n), cp.trace(P) <= 1]
    for s in grid:
        M = _sym(fam.M(P, float(s), alpha))
        cons += [M << -t * np.eye(n), -cp.trace(M) <= 1]
    prob = cp.Problem(cp.Maximize(t), cons)
    status, _ = guarded_solve(prob)
    if status != cp.OPTIMAL:
        return status, None, None
    return status, float(t.value), np.array(P.value, dtype=float)


def recheck(fam: LiftedFamily, P: np.ndarray, grid, alpha: float,
            margin: float) -> tuple[dict[str, float], list[float]]:
    """Relative margins of P, of every grid block and of the continuum, with numpy."""
    P = _sym(np.asarray(P, dtype=float))
    blocks = [np.linalg.eigvalsh(P)] + [np.linalg.eigvalsh(_sym(fam.M(P, float(s), alpha)))
                                        for s in grid]
    scale = max(float(np.sum(np.abs(e))) for e in blocks)
    if not scale > 0:
        return {"P": -math.inf, "grid": -math.inf, "continuum": -math.inf}, []
    out = {"P": float(blocks[0][0]) / scale,
           "grid": min(float(-e[-1]) for e in blocks[1:]) / scale}
    out["continuum"], cuts = continuum_margin(fam, P, grid, alpha, scale, margin)
    return out, cuts


def decide_lifted(fam: LiftedFamily, T_max: float, *, T_min: float = 0.0, alpha: float = 0.0,
                  margin: float = DEFAULT_MARGIN) -> Step:
    """Decide the theorem of the module docstring for intervals in [T_min, T_max].

    Returns a :class:`~workbench.lmi.core.Step` (``h`` = T_max):
    CERTIFIED with ``certificate = {"P", "grid"}`` and the re-check margins,
    REFUTED when the gridded LMI has no point with the margin, INCONCLUSIVE
    otherwise (solver not optimal, or the cutting planes did not settle).
    """
    t0 = time.perf_counter()
    grid = list(np.linspace(T_min, T_max, INITIAL_GRID))
    status, t_opt, checks = "not solved", None, {}
    for _ in range(ROUNDS):
        status, t_opt, P = _solve_grid(fam, grid, alpha)
        if P is None:
            return Step(T_max, Outcome.INCONCLUSIVE, status, None, {}, None,
                        time.perf_counter() - t0)
        if t_opt < margin:
            return Step(T_max, Outcome.REFUTED, status, t_opt, {}, None, time.perf_counter() - t0)
        checks, cuts = recheck(fam, P, grid, alpha, margin)
        if all(v >= margin for v in checks.values()):
            return Step(T_max, Outcome.CERTIFIED, status, t_opt, checks,
                        {"P": P, "grid": np.array(grid)}, time.perf_counter() - t0)
        if not cuts:
            break
        worst = sorted(cuts)[:: max(1, len(cuts) // 16)]
        grid = sorted(set(grid) | set(worst))
    return Step(T_max, Outcome.INCONCLUSIVE, status, t_opt, checks, None,
                time.perf_counter() - t0)


@dataclass(frozen=True)
class SamplingBound:
    """Largest T_max certified by :func:`decide_lifted` (a bracket).

    ``bracket.h_certified`` is the largest certified T_max (s): the loop is
    exponentially stable (rate ``alpha``) for EVERY sequence of sampling
    intervals in [T_min, T_max]; ``bracket.h_refuted`` the smallest T_max whose
    gridded LMI was infeasible (the criterion's limit, not instability).
    """

    T_min: float
    alpha: float
    margin: float
    bracket: Bracket

    @property
    def T_certified(self) -> float:
        return self.bracket.h_certified

    @property
    def T_refuted(self) -> float:
        return self.bracket.h_refuted


def certified_sampling_bound(A, B, K, *, T_min: float = 0.0, alpha: float = 0.0,
                             T_hi: float | None = None, rel_tol: float = 1e-4,
                             guess: float | None = None, max_solves: int = 40,
                             margin: float = DEFAULT_MARGIN) -> SamplingBound:
    """Bisection on T_max of the aperiodic-sampling certificate (module docstring).

    Parameters
    ----------
    A, B, K : array_like
        Plant and gain.
    T_min : float
        Smallest sampling interval (s), >= 0.
    alpha : float
        Required decay rate (1/s), >= 0.
    T_hi : float, optional
        Search cap (s); default 20 time scales 1 / (||A|| + ||B K||).
    rel_tol, guess, max_solves
        Bisection settings (:func:`~workbench.lmi.core.bisect_delay`; at most
        :data:`MAX_SECONDS` of wall clock).
    margin : float
        Named relative margin.

    Returns
    -------
    SamplingBound
    """
    fam = LiftedFamily(A, B, K)
    if not (T_min >= 0 and alpha >= 0):
        raise ValueError(f"T_min = {T_min!r} s, alpha = {alpha!r} 1/s; expected both >= 0")
    T_hi = 20 * fam.tau0 if T_hi is None else float(T_hi)
    lo = max(T_min * (1 + 1e-6), 1e-3 * fam.tau0, T_min + 1e-3 * fam.tau0)
    br = bisect_delay(lambda h: decide_lifted(fam, h, T_min=T_min, alpha=alpha, margin=margin),
                      h_lo=min(lo, T_hi / 2), h_hi=T_hi, rel_tol=rel_tol, guess=guess,
                      max_solves=max_solves, max_seconds=MAX_SECONDS)
    return SamplingBound(T_min, alpha, margin, br)
