"""Wirtinger-based delay-bound synthesis with an automatically searched scalar.

For x'(t) = A x(t) + B K x(t - h) (constant delay h), :class:`WirtingerSynthesis`
is the state-feedback synthesis LMI built from the Wirtinger-based criterion
of Seuret & Gouaisbaut (2013, Theorem 5) with Fridman's descriptor zero term
and the slack ``P3 = eps P2`` (Fridman & Shaked 2002), made linear by the
congruence ``Y = P2^{-1}``, ``V = K Y``. The scalar eps is not fixed by hand:
:func:`synthesize_tight` searches it (log grid + golden section, the shared
:func:`~workbench.lmi.robust.best_eps_bracket`), each eps deciding the
largest certified delay by the shared bracketed bisection
(:func:`~workbench.lmi.core.bisect_delay`).

The gain is the canonical one of :mod:`workbench.lmi.gain` (minimum-norm
certificate at ``gain_fraction * h_certified`` of the best eps, rounded to
``gain_digits`` significant digits, certified on its own by
:class:`WirtingerSynthesisFixedK`). The layer above checks it twice,
independently of the synthesis LMI (:func:`workbench.crosscheck.check_gain`):
by the Bessel-Legendre *analysis* criterion of :mod:`workbench.lmi.analysis`
with that K, and by the exact delay margin of :mod:`workbench.margins`.

When the exact margin with the synthesised K is infinite (no imaginary-axis
crossing: stable for every constant delay) the largest certified delay is
bounded only by the search cap ``h_max``; a result at the cap says "at least
h_max", not "at most".

References
----------
.. [SG13] Seuret A., Gouaisbaut F., "Wirtinger-based integral inequality:
   application to time-delay systems", Automatica 49(9), 2860-2866, 2013
   (Lemma 3, Theorem 5).
.. [FS02] Fridman E., Shaked U., "An improved stabilization method for linear
   time-delay systems", IEEE TAC 47(11), 1931-1937, 2002 (descriptor method,
   P3 = eps P2, congruence by P2^{-1}).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Sequence

import cvxpy as cp
import numpy as np

import math

from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI
from .diagnosis import INFEASIBLE, synthesis_reason, uncontrollable_mode
from .gain import DEFAULT_DIGITS, DEFAULT_FRACTION, CanonicalGain, FixedGain, canonical_gain
from .robust import DescriptorSynthesis, best_eps_bracket, eps_grid_for
from .scaling import SYNTHESIS_CAP_IN_UNITS, balance_points, check_unit, time_unit


class WirtingerSynthesis(MarginLMI):
    """Wirtinger-based state-feedback synthesis LMI (eps a DPP parameter).

    Functional (SG13 Theorem 5), z = [x; int_{t-h}^t x(s) ds]:

        V = z'Pz + int_{t-h}^t x'Sx + h int_{-h}^0 int_{t+s}^t x''R x'.

    With xi = [x; x'; x_d; Omega], Omega = (1/h) int_{t-h}^t x, the descriptor
    zero term 2 (x'P2' + x''eps P2')(-x' + A x + B K x_d), the Wirtinger bound
    h int x''Rx' >= chi0'R chi0 + 3 chi1'R chi1 (chi0 = x - x_d,
    chi1 = x + x_d - 2 Omega), the congruence diag(Y, Y, Y, Y), Y = P2^{-1},
    and the change of variables P~ = diag(Y,Y)'P diag(Y,Y), S~ = Y'SY,
    R~ = h Y'RY, V = K Y, the derivative is negative if

        Psi = He(G0' Theta Gd) + h He(G1' Theta Gd) - He(G1' D(S~) Gd)
              + diag(S~, h R~, -S~, 0) - (1/h)(chi0' R~ chi0 + 3 chi1' R~ chi1)
              + He([I; eps I; 0; 0] [A Y, -Y, B V, 0]) <= 0,

    where G0 xi = [x; 0], G1 xi = [0; Omega] (z = (G0 + h G1) xi), Gd xi = z' = [x'; x - x_d],
    D(S~) = diag(0, S~) and Theta = P~ + (1/h) D(S~) (so that V >= z'(P + D(S)/h)z
    by Jensen's inequality on the S term). Blocks: ``psi`` <= 0, ``theta``,
    ``S_pos``, ``R_pos`` >= 0. The (2,2) block h R~ - eps (Y + Y') <= 0 makes
    Y nonsingular, so K = V Y^{-1}.

    Decision variables: Theta (2n symmetric), S, R (n symmetric),
    Y (n x n), V (m x n). A CERTIFIED point at h proves that the loop with
    K = V Y^{-1} is asymptotically stable at the constant delay h.

    Parameters
    ----------
    A : (n, n) array
    B : (n, m) array
    eps : float
        Descriptor slack scalar (P3 = eps P2), > 0.
    """


    def __init__(self, A, B, eps: float, *, unit: float = 1.0, **kw):
        self.unit = check_unit(unit)
        self.A = np.atleast_2d(np.asarray(A, float))
        self.B = np.asarray(B, float).reshape(self.A.shape[0], -1)
        self.n, self.m = self.B.shape
        super().__init__(**kw)
        self.set_eps(eps)

    def parameters(self) -> tuple[str, ...]:
        return ("eps",)

    #: Same slack scalar (DPP parameter ``eps``) and gain K = V Y^{-1} as the
    #: Jensen descriptor synthesis of :mod:`workbench.lmi.robust`.
    set_eps = DescriptorSynthesis.set_eps
    gain = DescriptorSynthesis.gain
    canonical_retry_settings = DescriptorSynthesis.canonical_retry_settings

    def variables(self) -> dict[str, cp.Variable]:
        n = self.n
        return {"Theta": cp.Variable((2 * n, 2 * n), symmetric=True, name="Theta"),
                "S": cp.Variable((n, n), symmetric=True, name="S"),
                "R": cp.Variable((n, n), symmetric=True, name="R"),
                "Y": cp.Variable((n, n), name="Y"),
                "V": cp.Variable((self.m, n), name="V")}

    def _selectors(self):
        n = self.n
        I, O = np.eye(n, dtype=int), np.zeros((n, n), dtype=int)

        def e(i):
            return np.hstack([I if j == i else O for j in range(4)])
        x, dx, xd, om = e(0), e(1), e(2), e(3)
        Z = np.zeros_like(x)
        G0, G1, Gd = np.vstack([x, Z]), np.vstack([Z, om]), np.vstack([dx, x - xd])
        return x, dx, xd, om, G0, G1, Gd

    def blocks(self, v: Mapping[str, object], p, bmat) -> list[Block]:
        Th, S, R, Y, V = v["Theta"], v["S"], v["R"], v["Y"], v["V"]
        u = self.unit                    # blocks in the time unit u (exact, see time_unit)
        h, iota, eps = p["h"] * (1 / u), p["iota"] * u, p["eps"] * (1 / u)
        x, dx, xd, om, G0, G1, Gd = self._selectors()
        n = self.n
        Z = np.zeros((n, n), dtype=int)
        DS = bmat([[Z, Z], [Z, S]])
        chi0, chi1 = x - xd, x + xd - 2 * om
        he = G0.T @ Th @ Gd + h * (G1.T @ Th @ Gd) - G1.T @ DS @ Gd
        row = bmat([[(self.A * u) @ Y, -Y, (self.B * u) @ V, Z]])           # -x' + A x + B K x_d, times Y
        desc = x.T @ row + eps * (dx.T @ row)
        psi = (he + he.T + x.T @ S @ x - xd.T @ S @ xd + h * (dx.T @ R @ dx)
               - iota * (chi0.T @ R @ chi0 + 3 * (chi1.T @ R @ chi1)) + desc + desc.T)
        return [Block("psi", psi, "nsd"), Block("theta", Th, "psd"),
                Block("S_pos", S, "psd"), Block("R_pos", R, "psd")]


@dataclass(frozen=True)
class TightSynthesis:
    """A Wirtinger-synthesised gain and its independent checks.

    Attributes
    ----------
    eps : float
        Best eps of the automatic search.
    bracket : Bracket
        Certified bisection of the synthesis LMI at ``eps`` (balanced
        coordinates, see :func:`synthesize_tight`).
    K : numpy.ndarray or None
        Canonical gain (original coordinates, rounded), None when nothing
        was certified.
    eps_tried : tuple[tuple[float, float], ...]
        (eps, h_certified) of the search, sorted by eps.
    h_max : float
        Search cap (s) of both bisections.
    T : numpy.ndarray
        Balancing T (x = T x~) of the certificate's coordinates.
    gain : CanonicalGain or None
        How K was chosen, and the delay it certifies on its own.
    unit : float
        Time unit (s, a power of two) the blocks were written in
        (:func:`~workbench.lmi.scaling.time_unit` of the cap).
    diagnosis : str
        An uncontrollable mode found before any solve (the bracket is then
        INFEASIBLE), else empty.
    """

    eps: float
    bracket: Bracket
    K: np.ndarray | None
    eps_tried: tuple[tuple[float, float], ...]
    h_max: float
    T: np.ndarray = field(repr=False)
    gain: CanonicalGain | None = field(default=None, repr=False)
    unit: float = 1.0
    margin: float = DEFAULT_MARGIN
    diagnosis: str = ""

    @property
    def h_certified(self) -> float:
        """Delay certified by the synthesis LMI (s), for the unrounded solver
        gain; what the returned K certifies is ``gain.h_certified``."""
        return self.bracket.h_certified

    @property
    def reason(self) -> str:
        """Why no certified gain was returned (empty when one was)."""
        return synthesis_reason(self.bracket, self.gain, margin=self.margin, h_cap=self.h_max,
                                diagnosis=self.diagnosis)

    @property
    def at_cap(self) -> bool:
        """True when the synthesis bound is the search cap (a lower bound only)."""
        return self.bracket.h_certified >= self.h_max


#: Default eps grid of :func:`synthesize_tight`, in units of the cap ``h_max``.
TIGHT_EPS_GRID = (1e-3, 1e-2, 0.1, 1.0, 10.0)


def synthesize_tight(A, B, *, h_max: float, eps_grid: Sequence[float] | None = None,
                     golden_steps: int = 6, rel_tol: float = 1e-3,
                     margin: float = DEFAULT_MARGIN,
                     gain_fraction: float = DEFAULT_FRACTION,
                     gain_digits: int = DEFAULT_DIGITS) -> TightSynthesis:
    """Largest delay certified by :class:`WirtingerSynthesis`, eps searched.

    Parameters
    ----------
    A : (n, n) array_like
        Open-loop matrix.
    B : (n, m) array_like
        Input matrix; the closed loop is x' = A x + B K x(t - h).
    h_max : float
        Delay search cap (s), required: the delay range of interest in the
        system's own time unit (no absolute default).
    eps_grid : sequence of float, optional
        Log grid of the descriptor scalar (s), refined by golden section;
        default :data:`TIGHT_EPS_GRID` times ``h_max``. The blocks are written
        in the time unit u = ``time_unit(h_max, SYNTHESIS_CAP_IN_UNITS)``
        (:mod:`workbench.lmi.scaling`, exact), so (c A, c B) with cap h_max / c
        gives the same gain and h / c, numerically too (issue 21).
    golden_steps : int
    rel_tol : float
        Relative bracket width of the delay bisection.
    margin : float
        Relative LMI definiteness margin.
    gain_fraction, gain_digits
        Canonical gain (:func:`~workbench.lmi.gain.canonical_gain`).

    Returns
    -------
    TightSynthesis
        The LMI is solved in balanced coordinates (exact power-of-two
        scaling, :func:`workbench.lmi.scaling.balancing`); K is mapped back.
    """
    eps_grid = eps_grid_for(eps_grid, TIGHT_EPS_GRID, h_max)
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(A.shape[0], -1)
    T, Tinv, ((At, Bt),) = balance_points([(A, B)])
    u = time_unit(h_max, SYNTHESIS_CAP_IN_UNITS)
    diag = uncontrollable_mode([(A, B)])
    if diag is not None:                 # no solve: nothing can be certified
        return TightSynthesis(math.nan, INFEASIBLE, None, (), float(h_max), T, None, u,
                              margin, diag.reason)
    lmi = WirtingerSynthesis(At, Bt, eps_grid[0], margin=margin, unit=u)
    best, tried = best_eps_bracket(lmi, eps_grid, golden_steps=golden_steps, h_hi=h_max,
                                   rel_tol=rel_tol, stop_at=h_max)   # nothing beyond the cap
    br = tried[best]
    K = gain = None
    if br.certificate is not None:
        lmi.set_eps(best)
        gain = canonical_gain(
            lmi, br.h_certified,
            lambda Kt: WirtingerSynthesisFixedK(At, Bt, best, K=Kt, margin=margin, unit=u), T,
            fraction=gain_fraction, digits=gain_digits, h_hi=h_max, rel_tol=rel_tol)
        K = gain.K
    tried_h = tuple(sorted((e, b.h_certified) for e, b in tried.items()))
    return TightSynthesis(best, br, K, tried_h, float(h_max), T, gain, u, margin)


def recheck_tight(A, B, result: TightSynthesis,
                  certificate: Mapping[str, np.ndarray] | None = None) -> dict[str, float]:
    """Re-evaluate the synthesis LMI at ``result``'s eps and delay with numpy.

    Parameters
    ----------
    A, B : array_like
        The system the result was synthesised for.
    result : TightSynthesis
    certificate : mapping, optional
        Decision variables to check (default: the result's own certificate);
        pass a modified copy to see a tampered certificate fail.

    Returns
    -------
    dict[str, float]
        Smallest eigenvalue margin of each block (>= ``margin`` passes).
    """
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(A.shape[0], -1)
    Tinv = np.diag(1.0 / np.diag(result.T))
    lmi = WirtingerSynthesis(Tinv @ A @ result.T, Tinv @ B, result.eps, unit=result.unit)
    cert = result.bracket.certificate.certificate if certificate is None else certificate
    return lmi.recheck(cert, result.bracket.h_certified)


def recheck_gain(A, B, result: TightSynthesis) -> dict[str, float]:
    """Re-evaluate, with numpy and a fresh criterion object, the certificate of
    the *returned* (rounded) K: :class:`WirtingerSynthesisFixedK` at the delay
    ``result.gain.h_certified`` (empty when that K certified nothing)."""
    an = None if result.gain is None else result.gain.analysis
    if an is None or an.certificate is None:
        return {}
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(A.shape[0], -1)
    Tinv = np.diag(1.0 / np.diag(result.T))
    lmi = WirtingerSynthesisFixedK(Tinv @ A @ result.T, Tinv @ B, result.eps,
                                   K=result.K @ result.T, unit=result.unit)
    return lmi.recheck(an.certificate.certificate, an.certificate.h)


class WirtingerSynthesisFixedK(FixedGain, WirtingerSynthesis):
    """The same LMI with the gain fixed (V = K Y): the descriptor form of the
    Wirtinger *analysis* of a given K, e.g. to test the blocks against
    :class:`~workbench.lmi.analysis.WirtingerLMI` and exact margins."""

    gain_basis = "Y"
