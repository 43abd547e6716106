"""Analysis LMIs for x'(t) = A x(t) + A_d x(t - h) with a constant delay h.

Each criterion is a :class:`~workbench.lmi.core.MarginLMI`: blocks written
once, solved as "maximise t" by Clarabel, re-checked with numpy; the largest
certified h comes from the shared bracketed bisection
(:func:`~workbench.lmi.core.bisect_delay`) through :func:`certified_delay`.
Margins are relative to the largest block norm (see :mod:`workbench.lmi.core`),
so no criterion depends on how its Lyapunov matrix is scaled.

Notation (block selectors on the augmented vector xi):
``x = x(t)``, ``x_d = x(t - h)``, and for the Bessel-Legendre hierarchy the
Legendre moments ``Omega_k = (1/h) int_{t-h}^t l_k(u(s)) x(s) ds`` with the
shifted Legendre polynomials ``l_k(u) = P_k(2u - 1)``, ``u = (s - t + h)/h``
(``l_k(1) = 1``, ``l_k(0) = (-1)^k``, ``int_0^1 l_j l_k = delta_jk/(2k+1)``).

Criteria (weakest to tightest on the classic example):

* :class:`DelayIndependentLMI` — stable for every h >= 0;
* :class:`JensenLMI` and :class:`FreeWeightingLMI` (He et al. 2004);
* :class:`WirtingerLMI` (Seuret & Gouaisbaut 2013) = Bessel-Legendre N = 1;
* :class:`BesselLegendreLMI` of order N (Seuret & Gouaisbaut 2015).

What a CERTIFIED step proves: at the delay tested, the Lyapunov-Krasovskii
functional of the criterion is positive definite and strictly decreasing
along solutions, so the system is asymptotically stable for that constant
delay (for the free-weighting criterion, whose LMI is affine in h with a
positive semidefinite slope: for every constant delay in [0, h]). The
bisection treats the certified set as an interval [0, h], as the literature
does; the benchmark and the soundness suite compare every bound with the
exact margin of :mod:`workbench.margins`.

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

import math
from dataclasses import dataclass
from typing import Literal, Mapping

import cvxpy as cp
import numpy as np

from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI, Outcome, bisect_delay

#: Clarabel settings of the retries after an ``optimal_inaccurate`` answer,
#: tried in order (near the bound the higher Bessel-Legendre orders are
#: degenerate enough for the default refinement to stop short). The looser
#: tolerances of the second retry cannot make a step CERTIFIED on their own:
#: every certified point is re-checked with numpy against the margin.
RETRY_SETTINGS = (
    {"iterative_refinement_reltol": 1e-14, "iterative_refinement_abstol": 1e-14,
     "iterative_refinement_max_iter": 50},
    {"tol_gap_abs": 1e-7, "tol_gap_rel": 1e-7, "tol_feas": 1e-7, "tol_ktratio": 1e-5},
)

MethodName = Literal["delay-independent", "jensen", "free-weighting", "wirtinger",
                     "bessel-legendre"]
METHODS: tuple[str, ...] = ("delay-independent", "jensen", "free-weighting", "wirtinger",
                            "bessel-legendre")


def _sym(n: int, name: str) -> cp.Variable:
    return cp.Variable((n, n), symmetric=True, name=name)


class _DelayAnalysis(MarginLMI):
    """Common parts: the system matrices."""

    method: str = ""
    retry_settings = RETRY_SETTINGS

    def __init__(self, A, Ad, **kw):
        self.A = np.atleast_2d(np.asarray(A, float))
        self.Ad = np.atleast_2d(np.asarray(Ad, float))
        if self.A.shape != self.Ad.shape or self.A.shape[0] != self.A.shape[1]:
            raise ValueError(f"A {self.A.shape}, A_d {self.Ad.shape}; expected equal square shapes")
        self.n = self.A.shape[0]
        super().__init__(**kw)

    @property
    def N(self) -> int | None:
        """Bessel-Legendre order (None for the other criteria)."""
        return None

class DelayIndependentLMI(_DelayAnalysis):
    """Delay-independent test: stable for every constant h >= 0.

    Decision variables: P, Q (symmetric n x n). Blocks:
    ``[[A'P + P A + Q, P A_d], [A_d' P, -Q]] <= 0``, P >= 0, Q >= 0.
    Feasible => V = x'Px + int_{t-h}^t x'Qx decreases for every h
    (Gu, Kharitonov & Chen 2003, Prop. 5.2). The blocks do not depend on h.
    """

    method = "delay-independent"

    def variables(self):
        return {"P": _sym(self.n, "P"), "Q": _sym(self.n, "Q")}

    def blocks(self, x, p, bmat):
        P, Q, A, Ad = x["P"], x["Q"], self.A, self.Ad
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

    def variables(self):
        return {k: _sym(self.n, k) for k in ("P", "S", "R")}

    def blocks(self, x, p, bmat):
        P, S, R, A, Ad = x["P"], x["S"], x["R"], self.A, self.Ad
        PA, PAd = P @ A, P @ Ad
        phi0 = bmat([[PA + PA.T + S - R, PAd + R], [PAd.T + R, -S - R]])
        F = np.hstack([A, Ad])
        lmi = p["iota"] * phi0 + p["h"] * (F.T @ R @ F)
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

    def variables(self):
        v = {k: _sym(self.n, k) for k in ("P", "Q", "Z")}
        v.update(N1=cp.Variable((self.n, self.n), name="N1"),
                 N2=cp.Variable((self.n, self.n), name="N2"))
        return v

    def blocks(self, x, p, bmat):
        P, Q, Zm, N1, N2, A, Ad, h = x["P"], x["Q"], x["Z"], x["N1"], x["N2"], self.A, \
            self.Ad, p["h"]
        O = np.zeros((self.n, self.n), dtype=int)
        p11 = P @ A + A.T @ P + N1 + N1.T + Q
        p12 = P @ Ad - N1 + N2.T
        p22 = -N2 - N2.T - Q
        lmi = bmat([[p11, p12, h * N1, h * (A.T @ Zm)],
                    [p12.T, p22, h * N2, h * (Ad.T @ Zm)],
                    [h * N1.T, h * N2.T, -h * Zm, O],
                    [h * (Zm @ A), h * (Zm @ Ad), O, -h * Zm]])
        return [Block("lmi", lmi, "nsd")] + [Block(f"{k}_pos", x[k], "psd") for k in "PQZ"]


def legendre_derivative_coefficients(N: int) -> np.ndarray:
    """c[k, j] with l_k'(u) = sum_{j<k} c[k, j] l_j(u) on [0, 1].

    For l_k(u) = P_k(2u - 1): c[k, j] = (2j + 1)(1 - (-1)^(k+j)) (SG15, eq. 4).
    """
    c = np.zeros((N + 1, N + 1), dtype=int)
    for k in range(N + 1):
        for j in range(k):
            c[k, j] = (2 * j + 1) * (1 - (-1) ** (k + j))
    return c


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

    def selectors(self):
        """(G0, G1, H, F, [Gamma_0..Gamma_N]) as numpy arrays (see class doc)."""
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
        F = self.A @ e(0) + self.Ad @ e(1)
        G0 = np.vstack([e(0)] + [np.zeros((n, m), dtype=int)] * N)
        G1 = np.vstack([np.zeros((n, m), dtype=int)] + [e(2 + k) for k in range(N)])
        H = np.vstack([F] + gam[:N])
        return G0, G1, H, F, gam

    def blocks(self, x, p, bmat):
        Th, S, R = x["Theta"], x["S"], x["R"]
        n, N = self.n, self._N
        G0, G1, H, F, gam = self.selectors()
        h, iota = p["h"], p["iota"]
        e0, e1 = G0[:n], np.eye(n, (N + 2) * n, n, dtype=int)
        # G0' D(S) = 0, so (1/h) He(G0' P H) = (1/h) He(G0' Theta H): affine in the
        # parameters (DPP); He(G1' P H) = He(G1' Theta H) - (1/h) He(G1' D(S) H).
        he0 = G0.T @ Th @ H
        he1 = G1.T @ Th @ H
        if N:
            he1 = he1 - iota * (G1.T @ _blockdiag_S(S, N, n, bmat) @ H)
        sterm = e0.T @ S @ e0 - e1.T @ S @ e1
        rsum = sum((2 * k + 1) * (g.T @ R @ g) for k, g in enumerate(gam))
        phi = iota * (he0 + he0.T + sterm - rsum) + (he1 + he1.T) + h * (F.T @ R @ F)
        return [Block("phi", phi, "nsd"), Block("theta", Th, "psd"),
                Block("S_pos", S, "psd"), Block("R_pos", R, "psd")]

    def lyapunov_matrix(self, values: Mapping[str, np.ndarray], h: float) -> np.ndarray:
        """P = Theta - (1/h) diag(0, S, 3S, ..., (2N-1)S) of a certificate."""
        return values["Theta"] - _blockdiag_S(values["S"], self._N, self.n, np.block) / h


def _blockdiag_S(S, N: int, n: int, bmat):
    """diag(0, S, 3S, ..., (2N-1)S) as a cvxpy or numpy block matrix."""
    Z = np.zeros((n, n), dtype=int)
    rows = []
    for i in range(N + 1):
        rows.append([(2 * i - 1) * S if (i == j and i > 0) else Z for j in range(N + 1)])
    return bmat(rows)


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
    """Largest delay a criterion certifies, with its bracket.

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

    @property
    def h_certified(self) -> float:
        return self.bracket.h_certified

    @property
    def solves(self) -> int:
        return self.bracket.solves

    @property
    def seconds(self) -> float:
        return self.bracket.seconds


def certified_delay(lmi: _DelayAnalysis, *, h_lo: float = 1e-3, h_hi: float = 100.0,
                    rel_tol: float = 1e-5, guess: float | None = None,
                    max_solves: int = 60) -> DelayBound:
    """Largest constant delay (s) the criterion certifies, by the shared bisection.

    The delay-independent test does not depend on h: one solve decides it
    (certified => ``h_certified = inf``).
    """
    if isinstance(lmi, DelayIndependentLMI):
        step = lmi.solve_at(1.0)
        ok = step.outcome is Outcome.CERTIFIED
        br = Bracket(math.inf if ok else 0.0, math.inf if ok else 0.0, step.outcome,
                     step if ok else None, (step,))
        return DelayBound(lmi.method, None, br)
    br = bisect_delay(lmi.solve_at, h_lo=h_lo, h_hi=h_hi, rel_tol=rel_tol, guess=guess,
                      max_solves=max_solves)
    return DelayBound(lmi.method, lmi.N, br)


@dataclass(frozen=True)
class AutoOrder:
    """Result of :func:`bessel_legendre_auto`: one bound per order tried.

    ``N_reached`` is the first order whose gap to the exact margin is below
    the tolerance (None when the cap was reached first).
    """

    bounds: tuple[DelayBound, ...]
    N_reached: int | None

    @property
    def best(self) -> DelayBound:
        """The bound at ``N_reached`` (or the largest bound when not reached)."""
        if self.N_reached is not None:
            return next(b for b in self.bounds if b.N == self.N_reached)
        return max(self.bounds, key=lambda b: b.h_certified)


def bessel_legendre_auto(A, Ad, exact: float, *, gap_tol: float = 1e-4, N_max: int = 6,
                         N_through: int = 0, rel_tol: float = 1e-5,
                         margin: float = DEFAULT_MARGIN, h_hi: float = 100.0) -> AutoOrder:
    """Raise the Bessel-Legendre order N = 0, 1, ... until
    ``1 - h_N / exact < gap_tol`` or N = ``N_max``.

    Orders up to ``N_through`` are computed in any case (for tables). Each
    order's bisection starts from the previous order's bound (the hierarchy
    is non-decreasing in N). ``exact`` is the exact margin (s) from
    :mod:`workbench.margins`; with ``exact = inf`` the gap never closes.
    The hierarchy never goes backwards: when order N's own search certifies
    less than order N - 1 (an inaccurate solve there), order N reports the
    lower order's certificate (``certified_by``), which proves order N
    feasible at that delay.
    """
    out: list[DelayBound] = []
    guess, reached = None, None
    for N in range(0, max(N_max, N_through) + 1):
        if N > N_through and (reached is not None or N > N_max):
            break
        b = certified_delay(BesselLegendreLMI(A, Ad, N, margin=margin), rel_tol=rel_tol,
                            guess=guess, h_hi=h_hi)
        if out and b.h_certified < out[-1].h_certified:
            prev = out[-1]
            b = DelayBound(b.method, N, prev.bracket,
                           prev.certified_by if prev.certified_by is not None else prev.N)
        out.append(b)
        if b.h_certified > 0:
            guess = b.h_certified
        if (reached is None and math.isfinite(exact) and exact > 0
                and 1 - b.h_certified / exact < gap_tol):
            reached = N
    return AutoOrder(tuple(out), reached)
