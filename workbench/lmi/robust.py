"""One gain for several operating points, and the decay-rate variant.

:class:`DescriptorSynthesis` is a state-feedback synthesis LMI for
x' = A_i x + B_i K x(t - h) at every operating point i at once (common Y and
V, so one K = V Y^{-1}; Lyapunov-Krasovskii matrices per operating point),
built from Fridman's descriptor method with the Jensen inequality and the
slack P3 = eps P2; eps is searched automatically (:func:`synthesize_robust`),
not fixed by hand. :func:`gain_delay_bound` is the tighter
Bessel-Legendre analysis of a given gain; the layer above puts it next to
the exact margin (:func:`workbench.crosscheck.check_gain`) — the LMI never
sees the exact answer.

Operating points are a finite list (e.g. rail x speed x mass corners of
the antiskid linearisation): a certificate holds at each listed point, not
in between (the linearisation is not affine in speed or mass).

:func:`decay_rate_bracket`: with x = e^{-alpha t} z the loop
x' = A x + A_d x(t-h) becomes z' = (A + alpha I) z + e^{alpha h} A_d z(t-h);
a Bessel-Legendre certificate of that system at h proves exponential
stability with rate alpha at delay h (cross-checked by the spectral
abscissa in :func:`workbench.crosscheck.decay_rate_bound`).

References
----------
.. [FR01] Fridman E., "New Lyapunov-Krasovskii functionals for stability of
   linear retarded and neutral type systems", Systems & Control Letters 43
   (2001) 309-319 (descriptor method).
.. [FS02] Fridman E., Shaked U., "An improved stabilization method for linear
   time-delay systems", IEEE TAC 47(11), 2002 (P3 = eps P2 and the
   congruence by Y = P2^{-1}).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Sequence

import cvxpy as cp
import numpy as np

from .analysis import RETRY_SETTINGS, BesselLegendreLMI, certified_delay
from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI, bisect_delay
from .gain import DEFAULT_DIGITS, DEFAULT_FRACTION, CanonicalGain, FixedGain, canonical_gain
from .delay_input import H_HI_SCALE, H_LO_SCALE
from .diagnosis import INFEASIBLE, synthesis_reason, uncontrollable_mode
from .scaling import (SYNTHESIS_CAP_IN_UNITS, balance_loop, balance_points, check_unit,
                      time_unit)

#: The eps-search bisections of a synthesis stop going down at this fraction
#: of the search cap (relative: the search is the same in any time unit).
SYNTHESIS_FLOOR = 1e-5
#: Default eps grid of :func:`synthesize_robust`, in units of the cap ``h_hi``
#: (eps of the descriptor method is a time: it scales with the delay range).
ROBUST_EPS_GRID = (0.003, 0.01, 0.03, 0.1, 0.3)


def eps_grid_for(grid: Sequence[float] | None, default: Sequence[float], h_cap: float
                 ) -> tuple[float, ...]:
    """The eps grid (s) of a synthesis: the given one, or ``default`` (in units
    of the search cap) times ``h_cap``; ValueError on a non-positive entry."""
    if isinstance(h_cap, bool) or not (isinstance(h_cap, (int, float, np.floating))
                                       and 0 < h_cap < math.inf):
        raise ValueError(f"h_max = {h_cap!r}; expected a positive finite delay cap (s)")
    out = tuple(float(e) for e in grid) if grid is not None else tuple(
        float(e) * float(h_cap) for e in default)
    if not out or not all(0 < e < math.inf for e in out):
        raise ValueError(f"eps_grid = {grid!r}; expected positive finite values (s)")
    return out


def _set_product(prm) -> None:
    """``eps_ealpha = eps * ealpha`` (:class:`DescriptorSynthesis`), once both are set."""
    if "eps_ealpha" in prm and prm["ealpha"].value is not None and prm["eps"].value is not None:
        prm["eps_ealpha"].value = float(prm["eps"].value) * float(prm["ealpha"].value)


class DescriptorSynthesis(MarginLMI):
    """Jensen/descriptor synthesis LMI over operating points (eps a DPP parameter).

    For each operating point i, with eta = [x; x'; x_d] and the descriptor
    zero term 2 (x'P2' + x''P3')(-x' + A_i x + B_i K x_d), P3 = eps P2,
    Y = P2^{-1}, V = K Y and the congruence diag(Y, Y, Y), the functional
    V_i = x'P_i x + int x'S_i x + h int int x''R_i x' decreases if

        [[A_i Y + Y'A_i' + S_i - R_i/h, P_i - Y + eps Y'A_i', B_i V + R_i/h],
         [*, -eps (Y + Y') + h R_i, eps B_i V],
         [*, *, -S_i - R_i/h]] <= 0,   P_i, S_i, R_i >= 0

    (P_i, S_i stand for Y'P_iY, Y'S_iY and R_i for h Y'R_iY). Decision
    variables: Y (n x n), V (m x n) common; P_i, S_i, R_i (symmetric n x n)
    per point. Feasible at h => the loop with
    K = V Y^{-1} is asymptotically stable at delay h at every point; with
    alpha = 0 also at every h' <= h (in terms of Y'RY the LMI changes only by
    -(h^2 - h'^2) in the x' block).

    With a decay rate ``alpha`` > 0 the LMI is written for
    z' = (A_i + alpha I) z + e^{alpha h} B_i K z(t-h) (x = e^{-alpha t} z):
    feasible => exponentially stable with rate alpha at delay h.
    """

    #: The minimum-norm canonical point is retried like the analysis LMIs'
    #: solves (the bisection's steps are not: an inaccurate step stays
    #: inconclusive).
    canonical_retry_settings = RETRY_SETTINGS


    def __init__(self, points: Sequence[tuple[np.ndarray, np.ndarray]], eps: float,
                 alpha: float = 0.0, *, unit: float = 1.0, **kw):
        self.unit = check_unit(unit)
        if not alpha >= 0:
            raise ValueError(f"alpha = {alpha!r}; expected a non-negative rate (1/s)")
        self.alpha = float(alpha)
        pts = [(np.asarray(A, float), np.asarray(B, float)) for A, B in points]
        if not pts:
            raise ValueError("points = []; expected at least one (A, B)")
        self.n, self.m = pts[0][1].shape
        # decay rate alpha: A -> A + alpha I, B K -> e^{alpha h} B K (parameter ``ealpha``)
        self.points = [(A + self.alpha * np.eye(self.n), B) for A, B in pts]
        super().__init__(**kw)
        self.set_eps(eps)

    def parameters(self):
        # eps_ealpha = eps * ealpha, its own parameter: a product of two
        # parameters is not DPP, and a problem that is not DPP is compiled
        # again by cvxpy for every solve (issue 36, item 4)
        return ("eps", "ealpha", "eps_ealpha")

    def set_delay(self, h: float) -> None:
        super().set_delay(h)
        self.set_parameters(ealpha=math.exp(self.alpha * h))
        _set_product(self._params)

    def set_eps(self, eps: float) -> None:
        if not eps > 0:
            raise ValueError(f"eps = {eps!r}; expected a positive number")
        self.eps = float(eps)
        self.set_parameters(eps=eps)
        _set_product(self._params)

    def variables(self):
        n = self.n
        v = {"Y": cp.Variable((n, n), name="Y"), "V": cp.Variable((self.m, n), name="V")}
        for i in range(len(self.points)):
            for k in "PSR":
                v[f"{k}{i}"] = cp.Variable((n, n), symmetric=True, name=f"{k}{i}")
        return v

    def blocks(self, x, p, bmat):
        u = self.unit                    # blocks in the time unit u (exact, see time_unit)
        Y, V, eps, h, iota = x["Y"], x["V"], p["eps"] * (1 / u), p["h"] * (1 / u), p["iota"] * u
        out = []
        for i, (A, B) in enumerate(self.points):
            A, B = A * u, B * u
            P, S, R = x[f"P{i}"], x[f"S{i}"], x[f"R{i}"]
            AY, BV = A @ Y, p["ealpha"] * (B @ V)
            eBV = p["eps_ealpha"] * (1 / u) * (B @ V)        # eps * BV
            lmi = bmat([[AY + AY.T + S - iota * R, P - Y + eps * AY.T, BV + iota * R],
                        [P - Y.T + eps * AY, -eps * (Y + Y.T) + h * R, eBV],
                        [BV.T + iota * R, eBV.T, -S - iota * R]])
            out += [Block(f"lmi{i}", lmi, "nsd"), Block(f"P{i}_pos", P, "psd"),
                    Block(f"S{i}_pos", S, "psd"), Block(f"R{i}_pos", R, "psd")]
        return out

    def gain(self, values) -> np.ndarray:
        """K = V Y^{-1} from a certificate."""
        return np.linalg.solve(values["Y"].T, values["V"].T).T


class DescriptorSynthesisFixedK(FixedGain, DescriptorSynthesis):
    """The same LMI with the gain fixed (V = K Y): what a given K certifies
    at every operating point at once."""

    gain_basis = "Y"


@dataclass(frozen=True)
class RobustSynthesis:
    """Best eps and its bracket; the canonical K (original coordinates).

    Attributes
    ----------
    eps : float
    bracket : Bracket
    K : numpy.ndarray or None
        Canonical gain (:mod:`workbench.lmi.gain`), rounded.
    eps_tried : tuple[tuple[float, float], ...]
        (eps, h_certified) of the automatic search.
    gain : CanonicalGain or None
        How K was chosen, and the delay it certifies on its own.
    reason : str
        Why no certified gain was returned: an uncontrollable mode found
        before any solve (the bracket is then INFEASIBLE), the solver status,
        the block that failed its re-check, a search cap below the delay the
        caller requires; empty when K certifies a delay.
    """

    eps: float
    bracket: Bracket
    K: np.ndarray | None
    eps_tried: tuple[tuple[float, float], ...]
    gain: CanonicalGain | None = None
    reason: str = ""


def maximise_log_scalar(value: Callable[[float], float], grid: Sequence[float], *,
                        golden_steps: int = 6, stop_at: float = math.inf
                        ) -> tuple[float, dict[float, float]]:
    """Maximise ``value(eps)`` over eps > 0: log grid, then golden section.

    The grid is evaluated in order; then ``golden_steps`` golden-section steps
    in log eps refine the bracket formed by the best grid value's neighbours.
    Each eps (rounded to 12 significant digits, as golden points recur up to
    rounding) is evaluated once. The search stops early once a value reaches
    ``stop_at`` (e.g. the delay search cap: nothing larger can be found).

    Returns
    -------
    best : float
        The first eps with the largest value.
    values : dict[float, float]
        Every eps evaluated, with its value, in evaluation order.
    """
    seen: dict[float, float] = {}

    def run(eps: float) -> float:
        eps = float(f"{eps:.12g}")
        if eps not in seen:
            seen[eps] = value(eps)
        return seen[eps]

    def done() -> bool:
        return max(seen.values()) >= stop_at

    for e in grid:
        run(e)
        if done():
            break
    best = max(seen, key=lambda e: seen[e])
    if not done():
        k = list(grid).index(best)
        lo = math.log(grid[max(k - 1, 0)])
        hi = math.log(grid[min(k + 1, len(grid) - 1)])
        g = (math.sqrt(5) - 1) / 2
        for _ in range(golden_steps):             # golden section on log eps
            a, b = hi - g * (hi - lo), lo + g * (hi - lo)
            if run(math.exp(a)) >= run(math.exp(b)):
                hi = b
            else:
                lo = a
            if done():
                break
        best = max(seen, key=lambda e: seen[e])
    return best, seen


def best_eps_bracket(lmi, eps_grid: Sequence[float], *, golden_steps: int, h_hi: float,
                     rel_tol: float, stop_at: float = math.inf
                     ) -> tuple[float, dict[float, Bracket]]:
    """The eps of an LMI with a slack scalar (``lmi.set_eps``) that certifies
    the largest delay, by :func:`maximise_log_scalar` over certified
    bisections on h (each started from the best bound so far; the first from
    ``h_hi / 4``, where the LMI is better scaled than at tiny h, where 1/h
    dominates the blocks). Returns the best eps and every eps's bracket."""
    tried: dict[float, Bracket] = {}

    def h_of(eps: float) -> float:
        lmi.set_eps(eps)
        guess = max((b.h_certified for b in tried.values()), default=0.0) or h_hi / 4
        tried[eps] = bisect_delay(lmi.solve_at, h_lo=SYNTHESIS_FLOOR * h_hi, h_hi=h_hi,
                                  rel_tol=rel_tol,
                                  guess=guess)
        return tried[eps].h_certified

    best, _ = maximise_log_scalar(h_of, eps_grid, golden_steps=golden_steps, stop_at=stop_at)
    return best, tried


def synthesize_robust(points, *, h_hi: float, alpha: float = 0.0,
                      eps_grid: Sequence[float] | None = None,
                      golden_steps: int = 6, rel_tol: float = 1e-3,
                      margin: float = DEFAULT_MARGIN,
                      gain_fraction: float = DEFAULT_FRACTION,
                      gain_digits: int = DEFAULT_DIGITS) -> RobustSynthesis:
    """Largest h with one gain certified at every point, eps searched automatically.

    eps is chosen by a log grid, then golden-section refinement (in log eps)
    around the best grid value; each eps is a certified bisection on h
    (shared :func:`~workbench.lmi.core.bisect_delay`). Coordinates are
    balanced by a common power-of-two diagonal T (exact), K is mapped back.
    K is the canonical gain (:func:`~workbench.lmi.gain.canonical_gain`).

    ``h_hi`` (the search cap, s) is required: it states the delay range of
    interest in the system's own time unit. ``eps_grid`` defaults to
    :data:`ROBUST_EPS_GRID` times ``h_hi``. The blocks (and the fixed-gain
    analysis's) are written in the time unit
    u = ``time_unit(h_hi, SYNTHESIS_CAP_IN_UNITS)`` (:mod:`workbench.lmi.scaling`,
    exact), so (c A_i, c B_i) with cap h_hi / c and rate c alpha gives the same
    gain and h / c, numerically too (issue 21).
    """
    eps_grid = eps_grid_for(eps_grid, ROBUST_EPS_GRID, h_hi)
    diag = uncontrollable_mode(points, alpha)
    if diag is not None:                 # no solve: nothing can be certified
        return RobustSynthesis(math.nan, INFEASIBLE, None, (), None, diag.reason)
    T, Tinv, pts = balance_points(points)
    u = time_unit(h_hi, SYNTHESIS_CAP_IN_UNITS)
    lmi = DescriptorSynthesis(pts, eps_grid[0], alpha, margin=margin, unit=u)
    best, tried = best_eps_bracket(lmi, eps_grid, golden_steps=golden_steps, h_hi=h_hi,
                                   rel_tol=rel_tol)
    br = tried[best]
    gain = None
    if br.certificate is not None:
        lmi.set_eps(best)
        gain = canonical_gain(
            lmi, br.h_certified,
            lambda Kt: DescriptorSynthesisFixedK(pts, best, alpha, K=Kt, margin=margin,
                                                 unit=u), T,
            fraction=gain_fraction, digits=gain_digits, h_hi=h_hi, rel_tol=rel_tol)
    pairs = tuple(sorted((e, b.h_certified) for e, b in tried.items()))
    return RobustSynthesis(best, br, None if gain is None else gain.K, pairs, gain,
                           synthesis_reason(br, gain, margin=margin, h_cap=h_hi))


def gain_delay_bound(A, B, K, *, N: int = 2, margin: float = DEFAULT_MARGIN,
                     rel_tol: float = 1e-4, h_hi: float | None = None) -> Bracket:
    """Bessel-Legendre (order N) certified bound of x' = A x + B K x(t - h).

    The LMI side of a gain check: it knows nothing of the exact margin
    (:func:`workbench.crosscheck.check_gain` puts the two side by side).
    The point certificate holds at ``h_certified``; see :class:`Bracket`.
    ``h_hi`` defaults to the loop's own time scale times ``H_HI_SCALE``
    (:func:`~workbench.lmi.analysis.certified_delay`).
    """
    A = np.atleast_2d(np.asarray(A, float))
    Ad = np.asarray(B, float).reshape(A.shape[0], -1) @ np.atleast_2d(np.asarray(K, float))
    _, _, At, Adt = balance_loop(A, Ad)
    return certified_delay(BesselLegendreLMI(At, Adt, N, margin=margin),
                           rel_tol=rel_tol, h_hi=h_hi)


def decay_rate_bracket(A, Ad, alpha: float, *, N: int = 2, margin: float = DEFAULT_MARGIN,
                       rel_tol: float = 1e-4, h_hi: float | None = None) -> Bracket:
    """Bessel-Legendre bound for z' = (A + alpha I) z + e^{alpha h} A_d z(t-h).

    A certificate at h proves exponential stability with rate alpha of
    x' = A x + A_d x(t-h) at that delay. The delayed matrix depends on h,
    so each step builds its own criterion (no DPP re-use); the shared
    bisection decides. The search range is relative to the system's time
    scale tau = 1 / (||A|| + ||A_d|| + alpha): ``H_LO_SCALE`` tau up to
    ``h_hi`` (default ``H_HI_SCALE`` tau), not an absolute number of seconds.
    """
    if not alpha >= 0:
        raise ValueError(f"alpha = {alpha!r}; expected a non-negative rate (1/s)")
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    _, _, At, Adt = balance_loop(A, Ad)
    Aa = At + alpha * np.eye(A.shape[0])

    def decide(h: float):
        return BesselLegendreLMI(Aa, math.exp(alpha * h) * Adt, N, margin=margin).solve_at(h)

    rate = np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2) + alpha
    if h_hi is None:
        if not rate > 0:
            raise ValueError("A = A_d = 0 and alpha = 0 have no time scale; expected h_hi (s)")
        h_hi = H_HI_SCALE / rate
    h_lo = min(H_LO_SCALE / rate, h_hi / 2) if rate > 0 else H_LO_SCALE * h_hi
    return bisect_delay(decide, h_lo=h_lo, h_hi=h_hi, rel_tol=rel_tol)
