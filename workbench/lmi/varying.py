"""Interval certificates for a time-varying delay h(t) in [h1, h2], |h'(t)| <= mu.

For x'(t) = A x(t) + A_d x(t - h(t)) (and the state-feedback loop
A_d = B K) the criteria of this module prove asymptotic stability **for
every delay function** h(t) with ``h1 <= h(t) <= h2`` and ``|h'(t)| <= mu``
— hence for every constant delay in [h1, h2]. That is an *interval*
certificate, unlike the point certificates of :mod:`workbench.lmi.analysis`
(stable at the delay solved for). With ``mu=None`` the derivative is
unknown (any piecewise continuous h(t) in [h1, h2], fast switching
included).

The functional (Seuret & Gouaisbaut 2013, sec. 4, with the delay interval
[h1, h2] of Park, Ko & Jeong 2011), h12 = h2 - h1,

    V = z'Pz + int_{t-h1}^t x'S1x + int_{t-h2}^{t-h1} x'S2x
        + int_{t-h(t)}^t x'Qx
        + h1 int_{-h1}^0 int_{t+s}^t x''R1x' + h12 int_{-h2}^{-h1} int_{t+s}^t x''R2x'

(S1, R1 and the h1 window are absent when h1 = 0), with one of two
augmented states (``windows``):

* ``"delay"`` (SG13 Theorem 7): z = [x; int_{t-h1}^t x; int_{t-h(t)}^{t-h1} x;
  int_{t-h2}^{t-h(t)} x], whose derivative contains (1 - h'(t)) x(t - h(t));
  V' is affine in h(t) and in h'(t) separately, so the four vertices
  h(t) in {h1, h2}, h' in {-mu, mu} decide it. Needs a known mu.
* ``"fixed"``: z = [x; int_{t-h1}^t x; int_{t-h2}^{t-h1} x]; z' has no h'(t),
  which enters only through the Q term, bounded by
  x'Qx - (1 - mu) x(t-h)'Q x(t-h) (Q >= 0, mu < 1); with mu unknown (or
  mu >= 1) the Q term is removed. Two vertices h(t) in {h1, h2}. This is the
  criterion for an **unknown derivative** (fast switching included).

The R1 integral is bounded by the Wirtinger-based inequality (SG13 Lemma 3)
on [t-h1, t]; the R2 integral is split at t - h(t) into two windows of
lengths alpha h12 and (1 - alpha) h12, each bounded by Wirtinger, and the
two bounds (weights 1/alpha and 1/(1-alpha)) are combined by the
reciprocally convex lemma (Park, Ko & Jeong 2011, Lemma 1) with the slack X:

    (1/alpha) a'R~a + (1/(1-alpha)) b'R~b >= [a; b]' [[R~, X], [X', R~]] [a; b],
    R~ = diag(R2, 3 R2),  if [[R~, X], [X', R~]] >= 0.

With xi = [x; x(t-h1); x(t-h(t)); x(t-h2); nu1; nu2; nu3] (nu1, nu2, nu3 the
averages of x over [t-h1, t], [t-h(t), t-h1], [t-h2, t-h(t)]) the derivative
is V' <= xi' Phi(h(t), h'(t)) xi, z being affine in h(t)
(int_{t-h2}^{t-h1} x = (h(t) - h1) nu2 + (h2 - h(t)) nu3).

Decision variables: P (2n to 4n), S1, S2, Q, R1, R2 (n x n symmetric),
X (2n x 2n). Blocks: ``phi_*`` (one per vertex) <= 0; ``P``, ``S1``, ``S2``,
``Q``, ``R1``, ``R2``, ``rcc`` >= 0 (each with the relative margin of
:mod:`workbench.lmi.core`). A CERTIFIED point at h2 proves: V is positive
definite and V' <= -eps |x(t)|^2 along every solution, for every delay
function in the set above, so the system is uniformly asymptotically
stable for all of them — in particular for every constant delay in
[h1, h2]: an interval certificate, never larger than the exact constant-delay
stability window that contains it.

The boundary of these LMIs is degenerate: the largest certified h2 moves in
the third digit between relative margins 1e-9 and 1e-7 (the workbench
default); SG13 Table 2 is reproduced at 1e-9 (``tests/test_varying_delay.py``).

References
----------
.. [SG13] Seuret A., Gouaisbaut F., "Wirtinger-based integral inequality:
   application to time-delay systems", Automatica 49(9), 2860-2866, 2013
   (Lemma 3; section 4, Theorem 7 and Table 2: time-varying delay).
.. [PKJ11] Park P., Ko J. W., Jeong C., "Reciprocally convex approach to
   stability of systems with time-varying delays", Automatica 47(1),
   235-238, 2011 (Lemma 1, Theorem 1).
.. [FR14] Fridman E., *Introduction to Time-Delay Systems*, Birkhauser 2014,
   sec. 3.6 (interval time-varying delay, LKF theorem for h(t) bounded).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import cvxpy as cp
import numpy as np

from .analysis import RETRY_SETTINGS, UNIT_SCALE
from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI, bisect_delay
from .delay_input import H_HI_SCALE, time_scale
from .scaling import balance_loop


def _check_interval(h1: float, mu: float | None) -> tuple[float, float | None]:
    if not (h1 >= 0 and math.isfinite(h1)):
        raise ValueError(f"h1 = {h1!r}; expected a finite delay >= 0 (s)")
    if mu is not None and not (mu >= 0 and math.isfinite(mu)):
        raise ValueError(f"mu = {mu!r}; expected a finite derivative bound >= 0 or None "
                         "(unknown)")
    return float(h1), None if mu is None else float(mu)


class _Selectors:
    """Block selectors on xi (integer matrices, so re-checks stay exact)."""

    def __init__(self, n: int, with_h1: bool, names: tuple[str, ...]):
        self.n, self.names = n, names
        self.m = len(names) * n
        self.with_h1 = with_h1

    def __call__(self, name: str) -> np.ndarray:
        if name in ("x1", "nu1") and not self.with_h1:
            if name == "nu1":
                raise KeyError(name)
            name = "x"                       # h1 = 0: x(t - h1) = x(t)
        i = self.names.index(name)
        E = np.zeros((self.n, self.m), dtype=int)
        E[:, i * self.n:(i + 1) * self.n] = np.eye(self.n, dtype=int)
        return E


Windows = Literal["delay", "fixed"]


class _VaryingTerms:
    """The functional's terms shared by the analysis and the synthesis LMIs.

    ``names`` lists xi's blocks: ``x``, ``xh`` (= x(t - h(t))), ``x2``,
    ``nu2``, ``nu3`` always, ``x1`` and ``nu1`` when h1 > 0 (the synthesis
    adds ``dx`` = x'). Subclasses set ``h1``, ``mu``, ``windows``, ``n`` and
    ``_e`` (a :class:`_Selectors`) before ``MarginLMI.__init__``.
    """

    h1: float
    mu: float | None
    windows: str
    n: int
    #: Time unit (s) of the blocks (a power of two): they are written for the
    #: same system in that unit (A u, A_d u, h1 / u, h2 / u, eps / u), exact,
    #: so the solver sees the same numbers in any time unit of the model.
    unit: float = 1.0

    def _times(self, p):
        """(h1, h12, h12^2) in the blocks' time unit."""
        u = self.unit
        return self.h1 / u, p["h12"] * (1 / u), p["h12sq"] * (1 / (u * u))

    @property
    def with_h1(self) -> bool:
        return self.h1 > 0

    @property
    def with_Q(self) -> bool:
        """The Q term: with delay windows at every known mu (h' is a vertex
        value); with fixed windows only for mu < 1 (worst case 1 - mu > 0)."""
        if self.mu is None:
            return False
        return self.windows == "delay" or self.mu < 1

    def _vertices(self) -> tuple[tuple[str, float], ...]:
        """(h(t) vertex, h'(t) value) pairs at which Phi is checked."""
        if self.windows == "delay":
            return tuple((v, d) for v in ("h1", "h2") for d in (-self.mu, self.mu))
        return (("h1", self.mu or 0.0), ("h2", self.mu or 0.0))

    def parameters(self) -> tuple[str, ...]:
        return ("h12", "h12sq")

    def set_delay(self, h: float) -> None:
        """Set the upper delay h2 (s) and the derived parameters
        h12 = h2 - h1 and h12^2."""
        if not h > self.h1:
            raise ValueError(f"h2 = {h!r}; expected an upper delay > h1 = {self.h1!r} (s)")
        MarginLMI.set_delay(self, h)
        self.set_parameters(h12=h - self.h1, h12sq=(h - self.h1) ** 2)

    def evaluate_blocks(self, values, h: float):
        self.set_delay(h)        # h12 parameters of this h, not of the last solve
        return MarginLMI.evaluate_blocks(self, values, h)

    def _init_terms(self, h1, mu, windows, n, extra_names=()):
        self.h1, self.mu = _check_interval(h1, mu)
        if windows is None:
            windows = "fixed" if self.mu is None else "delay"
        if windows not in ("delay", "fixed"):
            raise ValueError(f"windows = {windows!r}; expected 'delay' or 'fixed'")
        if windows == "delay" and self.mu is None:
            raise ValueError("windows = 'delay', mu = None; expected a derivative bound mu "
                             "(delay windows put h'(t) into z'), or windows = 'fixed'")
        self.windows, self.n = windows, n
        names = (("x", "x1", "xh", "x2", "nu1", "nu2", "nu3") if self.with_h1
                 else ("x", "xh", "x2", "nu2", "nu3")) + tuple(extra_names)
        self._e = _Selectors(n, self.with_h1, names)

    def _lkf_variables(self) -> dict[str, cp.Variable]:
        n = self.n
        k = 2 + int(self.with_h1) + int(self.windows == "delay")
        v = {"P": cp.Variable((k * n, k * n), symmetric=True, name="P"),
             "S2": cp.Variable((n, n), symmetric=True, name="S2"),
             "R2": cp.Variable((n, n), symmetric=True, name="R2"),
             "X": cp.Variable((2 * n, 2 * n), name="X")}
        if self.with_h1:
            v.update(S1=cp.Variable((n, n), symmetric=True, name="S1"),
                     R1=cp.Variable((n, n), symmetric=True, name="R1"))
        if self.with_Q:
            v["Q"] = cp.Variable((n, n), symmetric=True, name="Q")
        return v

    def _common(self, v, p, bmat, dx_form):
        """Everything in V' but He(G' P H) and the Q term: the S terms, the
        x'' weights (``dx_form(W)`` is the quadratic form of x' with weight W
        on xi) and the Wirtinger / reciprocally convex lower bounds."""
        e = self._e
        x, xh, x2, x1 = e("x"), e("xh"), e("x2"), e("x1")
        h1, _, h12sq = self._times(p)
        out = x1.T @ v["S2"] @ x1 - x2.T @ v["S2"] @ x2 + h12sq * dx_form(v["R2"])
        if self.with_h1:
            S1, R1 = v["S1"], v["R1"]
            c0, c1 = x - x1, x + x1 - 2 * e("nu1")
            out = (out + x.T @ S1 @ x - x1.T @ S1 @ x1 + h1 ** 2 * dx_form(R1)
                   - c0.T @ R1 @ c0 - 3 * (c1.T @ R1 @ c1))
        gam = np.vstack([x1 - xh, x1 + xh - 2 * e("nu2"), xh - x2, xh + x2 - 2 * e("nu3")])
        return out - gam.T @ self._rcc(v, bmat) @ gam

    def _Q_term(self, v, d: float):
        """x'Qx - (1 - h') x(t-h)'Q x(t-h) at h' = d (fixed windows: d = mu)."""
        if not self.with_Q:
            return 0
        x, xh, Q = self._e("x"), self._e("xh"), v["Q"]
        return x.T @ Q @ x - (1.0 - d) * (xh.T @ Q @ xh)

    def _rcc(self, v, bmat):
        n = self.n
        Z = np.zeros((n, n), dtype=int)
        R2, X = v["R2"], v["X"]
        Rt = bmat([[R2, Z], [Z, 3 * R2]])
        return bmat([[Rt, X], [X.T, Rt]])

    def _G_H(self, p, dx, vertex: str, d: float):
        """Row blocks of z = G xi at h(t) = h1 or h2 and of z' = H xi at h' = d
        (``dx`` is the row block of x')."""
        e = self._e
        x, x1, xh, x2 = e("x"), e("x1"), e("xh"), e("x2")
        h1, h12, _ = self._times(p)
        c2, c3 = (0, h12) if vertex == "h1" else (h12, 0)
        head_G = [x] + ([h1 * e("nu1")] if self.with_h1 else [])
        head_H = [dx] + ([x - x1] if self.with_h1 else [])
        if self.windows == "delay":     # [int_{t-h(t)}^{t-h1} x; int_{t-h2}^{t-h(t)} x]
            return (head_G + [c2 * e("nu2"), c3 * e("nu3")],
                    head_H + [x1 - (1.0 - d) * xh, (1.0 - d) * xh - x2])
        return head_G + [c2 * e("nu2") + c3 * e("nu3")], head_H + [x1 - x2]

    def _phi_blocks(self, v, p, bmat, dx, dx_form, extra=0) -> list[Block]:
        common = self._common(v, p, bmat, dx_form) + extra
        out = []
        for vertex, d in self._vertices():
            G, H = self._G_H(p, dx, vertex, d)
            name = f"phi_{vertex}" + (f"_d{d:+g}" if self.windows == "delay" else "")
            out.append(Block(name, _he_GPH(G, v["P"], H) + self._Q_term(v, d) + common,
                             "nsd"))
        return out

    def _positive_blocks(self, v, bmat) -> list[Block]:
        out = [Block("P", v["P"], "psd"), Block("S2", v["S2"], "psd"),
               Block("R2", v["R2"], "psd"), Block("rcc", self._rcc(v, bmat), "psd")]
        out += [Block(k, v[k], "psd") for k in ("S1", "R1", "Q") if k in v]
        return out


def _he_GPH(G_rows, P, H_rows):
    """He(G' P H) for G, H given as lists of row blocks (G may hold parameters)."""
    k = len(G_rows)
    n = H_rows[0].shape[0]
    out = 0
    for i in range(k):
        for j in range(k):
            term = G_rows[i].T @ P[i * n:(i + 1) * n, j * n:(j + 1) * n] @ H_rows[j]
            out = out + term + term.T
    return out


class VaryingDelayLMI(_VaryingTerms, MarginLMI):
    """Wirtinger + reciprocally convex criterion for h(t) in [h1, h2], |h'| <= mu.

    See the module docstring for the functional, the vector xi and what a
    certificate proves. The blocks (``x' = F xi``, F = [A, A_d] on
    [x; x(t - h(t))]):

        Phi(h(t), h') = He(G(h(t))' P H(h')) + [S, Q terms]
                        + F'(h1^2 R1 + h12^2 R2)F - Gamma1' diag(R1, 3R1) Gamma1
                        - Gamma' [[R~2, X], [X', R~2]] Gamma  <= 0

    at h(t) in {h1, h2} (and h' in {-mu, mu} with delay windows). Phi is
    affine in h(t) and in h' separately, so its largest eigenvalue is convex
    in each and the vertices decide the whole box.

    Parameters
    ----------
    A, Ad : (n, n) array_like
    h1 : float
        Lower delay bound (s), >= 0. The upper bound h2 is the delay of
        :meth:`solve_at` (bisected by :func:`certified_varying_delay`).
    mu : float or None
        Bound on |h'(t)|; None for an unknown derivative.
    windows : {"delay", "fixed"}, optional
        Windows of z's integrals: ``"delay"`` (SG13 Theorem 7: split at
        t - h(t), four vertex LMIs; default when mu is given) or ``"fixed"``
        ([t-h2, t-h1]: h' only in the Q term, removed for mu None or >= 1;
        the only choice for mu None).
    margin, bound
        See :class:`~workbench.lmi.core.MarginLMI`.
    """

    method = "wirtinger-rcc"
    retry_settings = RETRY_SETTINGS

    def __init__(self, A, Ad, *, h1: float = 0.0, mu: float | None = None,
                 windows: Windows | None = None, **kw):
        self.A = np.atleast_2d(np.asarray(A, float))
        self.Ad = np.atleast_2d(np.asarray(Ad, float))
        if self.A.shape != self.Ad.shape or self.A.shape[0] != self.A.shape[1]:
            raise ValueError(f"A {self.A.shape}, A_d {self.Ad.shape}; expected equal square "
                             "shapes")
        # balanced coordinates, exact (as the constant-delay criteria)
        self.T, _, self.A, self.Ad = balance_loop(self.A, self.Ad)
        self._init_terms(h1, mu, windows, self.A.shape[0])
        R = float(np.linalg.norm(self.A, 2) + np.linalg.norm(self.Ad, 2))
        #: as the constant-delay criteria (:data:`~workbench.lmi.analysis.UNIT_SCALE`)
        self.unit = 2.0 ** round(math.log2(UNIT_SCALE / R)) if R > 0 else 1.0
        super().__init__(**kw)

    def variables(self):
        return self._lkf_variables()

    def blocks(self, v, p, bmat):
        e = self._e
        F = (self.A * self.unit) @ e("x") + (self.Ad * self.unit) @ e("xh")
        return (self._phi_blocks(v, p, bmat, F, lambda W: F.T @ W @ F)
                + self._positive_blocks(v, bmat))


@dataclass(frozen=True)
class VaryingDelayBound:
    """An interval certificate for a time-varying delay.

    ``bracket.h_certified`` is the largest upper bound h2 certified: the
    system is asymptotically stable for **every** delay function h(t) with
    ``h1 <= h(t) <= h2`` and ``|h'(t)| <= mu`` (``mu=None``: any derivative),
    hence for every constant delay in [h1, h2]. ``bracket.h_refuted`` is the
    smallest h2 the criterion refuted (its own limit, not a proof of
    instability).

    Attributes
    ----------
    method : str
    h1 : float
        Lower delay bound (s).
    mu : float or None
        Derivative bound; None = unknown.
    windows : str
        ``"delay"`` or ``"fixed"`` (see :class:`VaryingDelayLMI`).
    bracket : Bracket
        Bisection on h2 (s) from :func:`~workbench.lmi.core.bisect_delay`.
    """

    method: str
    h1: float
    mu: float | None
    windows: str
    bracket: Bracket

    form = "interval"

    @property
    def h2(self) -> float:
        """Largest certified upper delay (s); 0 when nothing was certified."""
        return self.bracket.h_certified

    @property
    def interval(self) -> tuple[float, float] | None:
        """The certified delay interval [h1, h2] (s), or None."""
        return (self.h1, self.h2) if self.h2 > self.h1 else None

    @property
    def seconds(self) -> float:
        return self.bracket.seconds

    @property
    def solves(self) -> int:
        return self.bracket.solves


def certified_varying_delay(A, Ad, *, h1: float = 0.0, mu: float | None = None,
                            windows: Windows | None = None, h_hi: float | None = None,
                            rel_tol: float = 1e-4, guess: float | None = None,
                            max_solves: int = 60,
                            margin: float = DEFAULT_MARGIN) -> VaryingDelayBound:
    """Largest h2 such that :class:`VaryingDelayLMI` certifies [h1, h2] with |h'| <= mu.

    Parameters
    ----------
    A, Ad : (n, n) array_like
        x' = A x + A_d x(t - h(t)).
    h1 : float
        Lower delay bound (s), >= 0.
    mu : float or None
        Bound on |h'(t)| (dimensionless); None = unknown derivative.
    windows : {"delay", "fixed"}, optional
        See :class:`VaryingDelayLMI`.
    h_hi : float, optional
        Search cap on h2 (s); a result at the cap means "at least h_hi".
        Default ``H_HI_SCALE`` times the time scale 1 / (||A|| + ||A_d||).
    rel_tol, guess, max_solves
        Bisection settings (:func:`~workbench.lmi.core.bisect_delay`); the
        search starts at h1 + 1e-3 max(h1, min(tau, h_hi)) (relative).
    margin : float
        Relative LMI margin.

    Returns
    -------
    VaryingDelayBound
        An interval certificate [h1, h2] (see its docstring).
    """
    lmi = VaryingDelayLMI(A, Ad, h1=h1, mu=mu, windows=windows, margin=margin)
    tau = time_scale(lmi.A, lmi.Ad)         # scale-free: 1e-3 of h1 or of the time scale
    if h_hi is None:
        if not math.isfinite(tau):
            raise ValueError("A = A_d = 0 has no time scale; expected h_hi (s)")
        h_hi = H_HI_SCALE * tau
    h_lo = lmi.h1 + 1e-3 * max(lmi.h1, min(tau, h_hi))
    br = bisect_delay(lmi.solve_at, h_lo=h_lo, h_hi=h_hi, rel_tol=rel_tol, guess=guess,
                      max_solves=max_solves)
    return VaryingDelayBound(lmi.method, lmi.h1, lmi.mu, lmi.windows, br)
