"""Analysis LMIs for x'(t) = A x(t) + A_d x(t - h) with a constant delay h.

Each criterion is a :class:`~workbench.lmi.core.MarginLMI` (blocks written once, solved
by Clarabel in canonical coordinates, re-checked with numpy against the caller's loop,
margins relative to the largest block norm); :func:`certified_delay` bisects.

Notation (block selectors on the augmented vector xi):
``x = x(t)``, ``x_d = x(t - h)``, and for the Bessel-Legendre hierarchy the
Legendre moments ``Omega_k = (1/h) int_{t-h}^t l_k(u(s)) x(s) ds`` with the
shifted Legendre polynomials ``l_k(u) = P_k(2u - 1)``, ``u = (s - t + h)/h``
(``l_k(1) = 1``, ``l_k(0) = (-1)^k``, ``int_0^1 l_j l_k = delta_jk/(2k+1)``).

Criteria: :class:`DelayIndependentLMI` (every h >= 0), :class:`JensenLMI`,
:class:`FreeWeightingLMI` (He et al. 2004), :class:`WirtingerLMI` (Seuret &
Gouaisbaut 2013; Bessel-Legendre N = 1), :class:`BesselLegendreLMI` (SG15).

What a CERTIFIED step proves: at the delay tested, the Lyapunov-Krasovskii
functional of the criterion is positive definite and strictly decreasing
along solutions, so the system is asymptotically stable **at that constant
delay** (a point certificate). Feasibility is not monotone in h: a system can
be stable on several separate windows, and a bisection over point
certificates can land in a later one, so :func:`certified_delay` reports a
point, never a margin. Intervals ("stable for every constant delay in
[h_a, h_b]") come from :mod:`workbench.lmi.interval`, which solves the
criterion once with the decision variables shared at both ends (each class
declares in ``h_blocks`` how its blocks depend on h). The free-weighting
criterion is a delay-range criterion: a certificate at h bounds the
derivative of a functional for every constant delay tau <= h (the
free-weighting term -2 xi'N int_{t-tau}^t x' <= tau xi'N Z^{-1} N' xi +
int_{t-tau}^t x''Z x', and tau <= h), so its point at h is the interval
[0, h] (``range_from_zero``).

References
----------
.. [HE04] He Y., Wu M., She J.-H., Liu G.-P., "Parameter-dependent Lyapunov
   functional for stability of time-delay systems with polytopic-type
   uncertainties", IEEE TAC 49(5), 828-832, 2004 (Theorem 1, free weighting
   matrices N1, N2).
.. [GU00] Gu K., "An integral inequality in the stability problem of time-delay
   systems", IEEE CDC 2000 (Jensen inequality).
.. [SG13] Seuret A., Gouaisbaut F., "Wirtinger-based integral inequality:
   application to time-delay systems", Automatica 49(9), 2860-2866, 2013
   (Lemma 3, Theorem 5).
.. [SG15] Seuret A., Gouaisbaut F., "Hierarchy of LMI conditions for the
   stability analysis of time-delay systems", Systems & Control Letters 81,
   1-7, 2015 (Lemma 3 Bessel-Legendre inequality, Theorem 4).
"""
from __future__ import annotations

import copy
import dataclasses
import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Literal, Mapping

import cvxpy as cp
import numpy as np

from .coordinates import canonical, recheck_original
from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI, Outcome, Step, bisect_delay
from .delay_input import check_bisection, search_range, system_matrices, time_scale
from .legendre import blockdiag_S, legendre_derivative_coefficients
from .point_search import resumed
from .scaling import balance_loop

#: Clarabel settings of the retries after an ``optimal_inaccurate`` answer, in order
#: (near the bound the higher Bessel-Legendre orders are degenerate); a retry certifies
#: only through the same numpy re-check.
RETRY_SETTINGS = (
    {"iterative_refinement_reltol": 1e-14, "iterative_refinement_abstol": 1e-14,
     "iterative_refinement_max_iter": 50},
    {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7, "tol_ktratio": 1e-5},
)

#: Blocks' time unit UNIT_SCALE / R, R = rho(A) + rho(A_d) (time_scale), not a power of two: (c A,
#: c A_d) reaches the solver as the same numbers for any c (issue 31); u A is one more rounding,
#: of the size of the numpy re-check's own (the relative margin covers both).
UNIT_SCALE = 4.0

MethodName = Literal["delay-independent", "jensen", "free-weighting", "wirtinger",
                     "bessel-legendre"]
METHODS: tuple[str, ...] = ("delay-independent", "jensen", "free-weighting", "wirtinger",
                            "bessel-legendre")


def _sym(n: int, name: str) -> cp.Variable:
    return cp.Variable((n, n), symmetric=True, name=name)


class _DelayAnalysis(MarginLMI):
    """Common parts: the loop, balanced (x = T x~, exact: scaling.balance_loop) as ``A0``,
    ``Ad0``, and as ``A``, ``Ad`` in the solve's modal coordinates x~ = L z (coordinates.py)."""

    method: str = ""
    retry_settings = RETRY_SETTINGS

    def __init__(self, A, Ad, **kw):
        self.T, _, A0, Ad0 = balance_loop(*system_matrices(A, Ad))
        self.L, self.A0, self.Ad0, self.A, self.Ad = canonical(A0, Ad0)
        self.n = self.A.shape[0]
        R = 1.0 / time_scale(self.A, self.Ad)       # similarity-invariant rate (1/s)
        self.unit = UNIT_SCALE / R if R > 0 else 1.0   # time unit (s): see UNIT_SCALE
        super().__init__(**kw)

    def scaled(self, p):
        """(A u, A_d u, h / u, iota u) with u = :attr:`unit`: every block is written
        for the system in its own time unit, so the relative margins and the
        solver's numbers do not depend on the unit of A. Certificates are those
        of the scaled system at h / u, which is the same system."""
        u = self.unit
        if self.A.dtype == object:          # exact rational re-check
            u = Fraction(u)
        return self.A * u, self.Ad * u, p["h"] * (1 / u), p["iota"] * u

    def recheck(self, values, h: float) -> dict[str, float]:   # against A0, A_d0
        return recheck_original(self, values, h)

    def solve_at(self, h: float) -> Step:
        """:meth:`MarginLMI.solve_at`; an answer still INCONCLUSIVE after the
        settings retries is retried once more on a twin problem with the
        variable bound 100 times larger (another scaling of the same
        criterion; its point passes the same re-check of the same blocks)."""
        step = super().solve_at(h)
        if step.outcome is not Outcome.INCONCLUSIVE:
            return step
        if getattr(self, "_twin_lmi", None) is None:
            self._twin_lmi = copy.copy(self)
            MarginLMI.__init__(self._twin_lmi, margin=self.margin, bound=100 * self.bound)
        again = MarginLMI.solve_at(self._twin_lmi, h)
        return dataclasses.replace(again, seconds=step.seconds + again.seconds)

    N = None          # Bessel-Legendre order (None for the other criteria)


class DelayIndependentLMI(_DelayAnalysis):
    """Delay-independent test: stable for every constant h >= 0.

    Decision variables: P, Q (symmetric n x n). Blocks:
    ``[[A'P + P A + Q, P A_d], [A_d' P, -Q]] <= 0``, P >= 0, Q >= 0.
    Feasible => V = x'Px + int_{t-h}^t x'Qx decreases for every h
    (Gu, Kharitonov & Chen 2003, Prop. 5.2). The blocks do not depend on h.
    """

    method = "delay-independent"
    h_blocks: dict[str, str] = {}

    def variables(self):
        return {"P": _sym(self.n, "P"), "Q": _sym(self.n, "Q")}

    def blocks(self, x, p, bmat):
        P, Q = x["P"], x["Q"]
        A, Ad, _, _ = self.scaled(p)
        lmi = bmat([[A.T @ P + P @ A + Q, P @ Ad], [Ad.T @ P, -Q]])
        return [Block("lmi", lmi, "nsd"), Block("P_pos", P, "psd"), Block("Q_pos", Q, "psd")]


class JensenLMI(_DelayAnalysis):
    """Jensen-based criterion (Gu 2000), written independently of the hierarchy.

    V = x'Px + int_{t-h}^t x'Sx + h int_{-h}^0 int_{t+s}^t x''R x'. With
    xi = [x; x_d], F = [A, A_d] and the Jensen bound
    h int x''Rx' >= (x - x_d)' R (x - x_d), dividing by h > 0:

        (1/h) (He([I 0]' P F) + diag(S, -S) - [I -I]' R [I -I]) + h F'RF <= 0.

    Decision variables: P, S, R (symmetric n x n), all >= 0. Equals
    :class:`BesselLegendreLMI` with N = 0 (a test checks they agree).
    """

    method = "jensen"
    h_blocks = {"lmi": "h"}     # h * block = phi0 + h^2 F'RF, R >= 0

    def variables(self):
        return {k: _sym(self.n, k) for k in ("P", "S", "R")}

    def blocks(self, x, p, bmat):
        P, S, R = x["P"], x["S"], x["R"]
        A, Ad, h, iota = self.scaled(p)
        PA, PAd = P @ A, P @ Ad
        phi0 = bmat([[PA + PA.T + S - R, PAd + R], [PAd.T + R, -S - R]])
        F = np.hstack([A, Ad])
        lmi = iota * phi0 + h * (F.T @ R @ F)
        return [Block("lmi", lmi, "nsd")] + [Block(f"{k}_pos", x[k], "psd") for k in "PSR"]


class FreeWeightingLMI(_DelayAnalysis):
    """Free-weighting-matrix criterion, He et al. 2004, Theorem 1 (constant delay).

    V = x'Px + int_{t-h}^t x'Qx + int_{-h}^0 int_{t+s}^t x''Z x', with the
    zero term 2 (x'N1 + x_d'N2)(x - x_d - int x') added. Block (xi = [x; x_d]):

        [[Phi11, Phi12, h N1, h A'Z],
         [Phi12', Phi22, h N2, h A_d'Z],
         [h N1', h N2', -h Z, 0],
         [h Z A, h Z A_d, 0, -h Z]] <= 0,

    Phi11 = PA + A'P + N1 + N1' + Q, Phi12 = P A_d - N1 + N2',
    Phi22 = -N2 - N2' - Q. Decision variables: P, Q, Z (symmetric, >= 0),
    N1, N2 (n x n). Feasible at h => stable for every constant delay in [0, h].
    """

    method = "free-weighting"
    h_blocks = {"lmi": "1"}     # affine in h
    #: a certificate at h proves every constant delay in [0, h] (class docstring)
    range_from_zero = True

    def variables(self):
        v = {k: _sym(self.n, k) for k in ("P", "Q", "Z")}
        v.update(N1=cp.Variable((self.n, self.n), name="N1"),
                 N2=cp.Variable((self.n, self.n), name="N2"))
        return v

    def blocks(self, x, p, bmat):
        P, Q, Zm, N1, N2 = x["P"], x["Q"], x["Z"], x["N1"], x["N2"]
        A, Ad, h, _ = self.scaled(p)
        O = np.zeros((self.n, self.n), dtype=int)
        p11 = P @ A + A.T @ P + N1 + N1.T + Q
        p12 = P @ Ad - N1 + N2.T
        p22 = -N2 - N2.T - Q
        lmi = bmat([[p11, p12, h * N1, h * (A.T @ Zm)],
                    [p12.T, p22, h * N2, h * (Ad.T @ Zm)],
                    [h * N1.T, h * N2.T, -h * Zm, O],
                    [h * (Zm @ A), h * (Zm @ Ad), O, -h * Zm]])
        return [Block("lmi", lmi, "nsd")] + [Block(f"{k}_pos", x[k], "psd") for k in "PQZ"]


class BesselLegendreLMI(_DelayAnalysis):
    """Bessel-Legendre criterion of order N >= 0 (Seuret & Gouaisbaut 2015).

    State of the functional: z = [x; h Omega_0; ...; h Omega_{N-1}], so that
    z' = [A x + A_d x_d; chi_0; ...; chi_{N-1}] with (integration by parts)

        chi_k = h Omega_k' = x - (-1)^k x_d - sum_{j<k} c_kj Omega_j

    (c of :func:`legendre_derivative_coefficients`). Augmented vector
    xi = [x; x_d; Omega_0; ...; Omega_{N-1}] ((N+2) n), z = (G0 + h G1) xi,
    z' = H xi, x' = F xi, chi_k = Gamma_k xi.

    V = z'Pz + int_{t-h}^t x'Sx + h int_{-h}^0 int_{t+s}^t x''R x'. The
    Bessel-Legendre inequality (SG15 Lemma 3)
    h int x''Rx' >= sum_{k=0}^{N} (2k+1) chi_k' R chi_k and division by h give

        Phi_N(h) = (1/h) He(G0' P H) + He(G1' P H) + (1/h) diag(S, -S, 0)
                   + h F'RF - (1/h) sum_{k=0}^{N} (2k+1) Gamma_k' R Gamma_k <= 0,

        Theta_N(h) = P + (1/h) diag(0, S, 3S, ..., (2N-1)S) >= 0,  S, R >= 0

    (Theta from int x'Sx >= (1/h) sum (2k+1) (h Omega_k)' S (h Omega_k)).
    Decision variables: Theta ((N+1) n symmetric, with
    P = Theta - (1/h) diag(0, S, ..., (2N-1) S) substituted), S, R (n x n
    symmetric).
    N = 0 is the Jensen criterion, N = 1 the Wirtinger one of SG13; the bound
    is non-decreasing in N (SG15 Theorem 4: the hierarchy).
    """

    method = "bessel-legendre"
    h_blocks = {"phi": "h"}     # h * Phi_N = X + h He(G1' Theta H) + h^2 F'RF, R >= 0

    def __init__(self, A, Ad, N: int, **kw):
        if not (isinstance(N, (int, np.integer)) and N >= 0):
            raise ValueError(f"N = {N!r}; expected an integer >= 0")
        self._N = int(N)
        super().__init__(A, Ad, **kw)

    @property
    def N(self) -> int:
        return self._N

    def variables(self):
        n, N = self.n, self._N
        # Theta (not P) is the variable: P = Theta - (1/h) D(S), so the
        # block norm bound of the solver's normalisation applies to a
        # positive semidefinite matrix.
        return {"Theta": _sym((N + 1) * n, "Theta"), "S": _sym(n, "S"), "R": _sym(n, "R")}

    def selectors(self, A=None, Ad=None):
        """(G0, G1, H, F, [Gamma_0..Gamma_N]) as numpy arrays (see class doc);
        F from ``A``, ``A_d`` (default: the system's)."""
        A = self.A if A is None else A
        Ad = self.Ad if Ad is None else Ad
        n, N = self.n, self._N
        I = np.eye(n, dtype=int)      # integer selectors keep exact re-checks exact
        m = (N + 2) * n

        def e(i):               # block selector of xi's i-th block
            E = np.zeros((n, m), dtype=int)
            E[:, i * n:(i + 1) * n] = I
            return E
        c = legendre_derivative_coefficients(N)
        gam = []
        for k in range(N + 1):
            g = e(0) - (-1) ** k * e(1)
            for j in range(k):
                g = g - c[k, j] * e(2 + j)
            gam.append(g)
        F = A @ e(0) + Ad @ e(1)
        G0 = np.vstack([e(0)] + [np.zeros((n, m), dtype=int)] * N)
        G1 = np.vstack([np.zeros((n, m), dtype=int)] + [e(2 + k) for k in range(N)])
        H = np.vstack([F] + gam[:N])
        return G0, G1, H, F, gam

    def blocks(self, x, p, bmat):
        Th, S, R = x["Theta"], x["S"], x["R"]
        n, N = self.n, self._N
        A, Ad, h, iota = self.scaled(p)
        G0, G1, H, F, gam = self.selectors(A, Ad)
        e0, e1 = G0[:n], np.eye(n, (N + 2) * n, n, dtype=int)
        # G0' D(S) = 0, so (1/h) He(G0' P H) = (1/h) He(G0' Theta H): affine in the
        # parameters (DPP); He(G1' P H) = He(G1' Theta H) - (1/h) He(G1' D(S) H).
        he0 = G0.T @ Th @ H
        he1 = G1.T @ Th @ H
        if N:
            he1 = he1 - iota * (G1.T @ blockdiag_S(S, N, n, bmat) @ H)
        sterm = e0.T @ S @ e0 - e1.T @ S @ e1
        rsum = sum((2 * k + 1) * (g.T @ R @ g) for k, g in enumerate(gam))
        phi = iota * (he0 + he0.T + sterm - rsum) + (he1 + he1.T) + h * (F.T @ R @ F)
        return [Block("phi", phi, "nsd"), Block("theta", Th, "psd"),
                Block("S_pos", S, "psd"), Block("R_pos", R, "psd")]

    def lyapunov_matrix(self, values: Mapping[str, np.ndarray], h: float) -> np.ndarray:
        """P = Theta - (u/h) diag(0, S, 3S, ..., (2N-1)S) of a certificate (in the
        time unit u = :attr:`unit` of the blocks)."""
        return values["Theta"] - blockdiag_S(values["S"], self._N, self.n,
                                              np.block) * (self.unit / h)


class WirtingerLMI(BesselLegendreLMI):
    """Wirtinger-based criterion, SG13 Theorem 5: the hierarchy at N = 1.

    Decision variables: P (2n x 2n, on z = [x; int_{t-h}^t x]), S, R (n x n).
    The Wirtinger inequality h int x''Rx' >= chi_0'R chi_0 + 3 chi_1'R chi_1
    (SG13 Lemma 3) is the Bessel-Legendre inequality of order 1.
    """

    method = "wirtinger"

    def __init__(self, A, Ad, **kw):
        super().__init__(A, Ad, 1, **kw)


def make_criterion(method: MethodName, A, Ad, *, N: int | None = None,
                   margin: float = DEFAULT_MARGIN) -> _DelayAnalysis:
    """The criterion object for a method name of :data:`METHODS`."""
    if method == "bessel-legendre":
        if N is None:
            raise ValueError("N = None; expected an integer order >= 0 for bessel-legendre")
        return BesselLegendreLMI(A, Ad, N, margin=margin)
    if N is not None:
        raise ValueError(f"N = {N!r}; expected None for method {method!r} (only "
                         "bessel-legendre has an order)")
    cls = {"delay-independent": DelayIndependentLMI, "jensen": JensenLMI,
           "free-weighting": FreeWeightingLMI, "wirtinger": WirtingerLMI}.get(method)
    if cls is None:
        raise ValueError(f"method = {method!r}; expected one of {', '.join(METHODS)}")
    return cls(A, Ad, margin=margin)


@dataclass(frozen=True)
class DelayBound:
    """Largest delay at which a criterion certifies stability, with its bracket.

    A **point** certificate: stable at ``h_certified`` (the LMIs of this
    module are not monotone in h in general; a system may be stable on
    several windows). The interval form is
    :func:`~workbench.lmi.interval.certified_interval`.

    Attributes
    ----------
    method : str
    N : int or None
        Bessel-Legendre order.
    bracket : Bracket
        From :func:`~workbench.lmi.core.bisect_delay`; for the
        delay-independent test a single solve (``h_certified = inf`` when
        certified, else 0).
    certified_by : int or None
        Bessel-Legendre order whose certificate gives ``bracket`` when it is
        not ``N`` itself: a lower order certified more than order N's own
        search (an inaccurate solve there). A certificate of order N - 1 at h
        makes order N feasible at h (SG15 Theorem 4), so the bound stands.
    """

    method: str
    N: int | None
    bracket: Bracket
    certified_by: int | None = None

    form = "point"              # see workbench.lmi.interval.Form

    @property
    def h_certified(self) -> float:
        return self.bracket.h_certified

    @property
    def solves(self) -> int:
        return self.bracket.solves

    @property
    def seconds(self) -> float:
        return self.bracket.seconds


def certified_delay(lmi: _DelayAnalysis, *, h_lo: float | None = None,
                    h_hi: float | None = None, rel_tol: float = 1e-5,
                    guess: float | None = None, max_solves: int = 60) -> DelayBound:
    """Largest constant delay (s) at which the criterion certifies stability: a
    **point** certificate (stable at ``h_certified``; nothing is said about
    smaller delays — see :func:`~workbench.lmi.interval.certified_interval`
    for intervals), by the shared bisection.

    The delay-independent test does not depend on h: one solve decides it
    (certified => ``h_certified = inf``, which is an interval [0, inf)). A
    search ended by an inconclusive answer is resumed above it
    (:mod:`workbench.lmi.point_search`).

    Parameters
    ----------
    lmi : criterion of :data:`METHODS` (:func:`make_criterion`)
    h_lo, h_hi : float, optional
        Search range (s), 0 < h_lo < h_hi; default 1e-4 and 1e4 times the
        system's time scale 1 / (||A||_2 + ||A_d||_2).
    rel_tol : float
        Relative bracket width, in (0, 1).
    guess : float, optional
        First delay tried (s).
    max_solves : int
        Solver budget.

    Raises
    ------
    ValueError
        h_lo >= h_hi, NaN/inf or non-positive delays, rel_tol outside (0, 1),
        a bad budget (expected-versus-found message).
    """
    if not isinstance(lmi, _DelayAnalysis):
        raise ValueError(f"lmi = {type(lmi).__name__}; expected a delay criterion of "
                         "workbench.lmi.analysis (make_criterion)")
    h_lo, h_hi = search_range(lmi.A, lmi.Ad, h_lo, h_hi)
    check_bisection(rel_tol, guess, max_solves)
    if isinstance(lmi, DelayIndependentLMI):
        step = lmi.solve_at(1.0)
        ok = step.outcome is Outcome.CERTIFIED
        br = Bracket(math.inf if ok else 0.0, math.inf if ok else 0.0, step.outcome,
                     step if ok else None, (step,))
        return DelayBound(lmi.method, None, br)
    br = bisect_delay(lmi.solve_at, h_lo=h_lo, h_hi=h_hi, rel_tol=rel_tol, guess=guess,
                      max_solves=max_solves)
    br = resumed(lmi.solve_at, br, h_hi=h_hi, rel_tol=rel_tol, max_solves=max_solves)
    return DelayBound(lmi.method, lmi.N, br)
