"""State-feedback synthesis for a time-varying input delay h(t) in [h1, h2], |h'| <= mu.

For x'(t) = A x(t) + B K x(t - h(t)), :class:`VaryingDelaySynthesis` is the
criterion of :class:`~workbench.lmi.varying.VaryingDelayLMI` in descriptor
form, made linear in the gain by the congruence of Fridman & Shaked 2002
(the same steps as :class:`~workbench.lmi.tight_synthesis.WirtingerSynthesis`
for a constant delay):

* x' becomes a block of xi (``dx``) and the zero term
  2 (x'P2' + x'' eps P2')(-x' + A x + B K x(t - h(t))) is added, so the x''
  weights h1^2 R1 + h12^2 R2 act on the ``dx`` block instead of on F'(.)F;
* the whole inequality is multiplied by diag(Y, ..., Y)' and diag(Y, ..., Y),
  Y = P2^{-1}; every LKF matrix M is replaced by Y'MY (P, S1, S2, Q, R1, R2 and
  the reciprocally convex slack X by diag(Y, Y)' X diag(Y, Y)), which keeps
  every block linear, and V = K Y.

The ``dx`` diagonal block is h1^2 R1 + h12^2 R2 - eps (Y + Y') <= 0, so a
certificate has Y + Y' > 0, Y is nonsingular and K = V Y^{-1}. Decision
variables: those of the analysis criterion (transformed) plus Y (n x n) and
V (m x n). A CERTIFIED point at h2 proves that the loop with K = V Y^{-1} is
asymptotically stable for every delay function h(t) in [h1, h2] with
|h'(t)| <= mu (``mu=None``: any derivative) — an interval certificate.

:func:`synthesize_varying` searches eps (log grid + golden section,
:func:`~workbench.lmi.robust.maximise_log_scalar`), bisects h2 for each eps,
takes the canonical gain of the best eps (:func:`~workbench.lmi.gain.canonical_gain`:
minimum-norm certificate, K rounded, certified on its own by
:class:`VaryingDelaySynthesisFixedK`) and checks K by the analysis criterion
on (A, B K). The exact constant-delay margin (an upper bound the time-varying
set can never exceed) is the caller's cross-check: the LMI layer never
computes or sees it.

References
----------
.. [SG13] Seuret A., Gouaisbaut F., Automatica 49(9), 2860-2866, 2013
   (Lemma 3, Theorem 7).
.. [PKJ11] Park P., Ko J. W., Jeong C., Automatica 47(1), 235-238, 2011
   (Lemma 1).
.. [FS02] Fridman E., Shaked U., "An improved stabilization method for linear
   time-delay systems", IEEE TAC 47(11), 1931-1937, 2002 (descriptor method,
   P3 = eps P2, congruence by P2^{-1}).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import cvxpy as cp
import numpy as np

from .core import DEFAULT_MARGIN, Block, Bracket, MarginLMI, Outcome, bisect_delay
from .diagnosis import INFEASIBLE, uncontrollable_mode
from .gain import DEFAULT_DIGITS, DEFAULT_FRACTION, CanonicalGain, FixedGain, canonical_gain

#: Fractions of the certified h2 at which the canonical gain is tried, in order.
GAIN_FRACTIONS = (DEFAULT_FRACTION, 0.95, 0.9, 0.8, 0.6)
from .robust import DescriptorSynthesis, eps_grid_for, maximise_log_scalar
from .scaling import balance_points, check_unit, time_unit
from .varying import (RETRY_SETTINGS, VaryingDelayBound, Windows, _VaryingTerms,
                      certified_varying_delay)


class VaryingDelaySynthesis(_VaryingTerms, MarginLMI):
    """Descriptor / congruence synthesis LMI for h(t) in [h1, h2], |h'| <= mu.

    Blocks: the vertex blocks ``phi_*`` of the analysis criterion with xi
    extended by ``dx`` = x', the x'' weights on ``dx`` and the descriptor term

        He([I; eps I] at (x, dx)  [A Y, B V, -Y] at (x, x(t - h(t)), dx)),

    all in the congruence variables (module docstring); ``P``, ``S*``, ``Q``,
    ``R*``, ``rcc`` >= 0.

    Parameters
    ----------
    A : (n, n) array
    B : (n, m) array
    eps : float
        Descriptor scalar (P3 = eps P2), > 0 (DPP parameter, :meth:`set_eps`).
    h1, mu, windows
        As in :class:`~workbench.lmi.varying.VaryingDelayLMI`.
    """

    method = "wirtinger-rcc-synthesis"
    retry_settings = RETRY_SETTINGS
    set_eps = DescriptorSynthesis.set_eps
    gain = DescriptorSynthesis.gain

    def __init__(self, A, B, eps: float, *, h1: float = 0.0, mu: float | None = None,
                 windows: Windows | None = None, unit: float = 1.0, **kw):
        self.unit = check_unit(unit)
        self.A = np.atleast_2d(np.asarray(A, float))
        self.B = np.asarray(B, float).reshape(self.A.shape[0], -1)
        self.m = self.B.shape[1]
        self._init_terms(h1, mu, windows, self.A.shape[0], extra_names=("dx",))
        super().__init__(**kw)
        self.set_eps(eps)

    def parameters(self) -> tuple[str, ...]:
        return super().parameters() + ("eps",)

    def variables(self):
        v = self._lkf_variables()
        v.update(Y=cp.Variable((self.n, self.n), name="Y"),
                 V=cp.Variable((self.m, self.n), name="V"))
        return v

    def blocks(self, v, p, bmat) -> list[Block]:
        e = self._e
        x, xh, dx = e("x"), e("xh"), e("dx")
        Y = v["Y"]
        # Y'P2'(-x' + A x + B K x_h) Y with P2 Y = I, V = K Y:
        u = self.unit                    # blocks in the time unit u (exact)
        row = (self.A * u) @ Y @ x + (self.B * u) @ v["V"] @ xh - Y @ dx
        desc = (x + p["eps"] * (1 / u) * dx).T @ row
        return (self._phi_blocks(v, p, bmat, dx, lambda W: dx.T @ W @ dx, desc + desc.T)
                + self._positive_blocks(v, bmat))


class VaryingDelaySynthesisFixedK(FixedGain, VaryingDelaySynthesis):
    """The same LMI with the gain fixed (V = K Y): the descriptor form of the
    analysis of a given K (what a rounded canonical gain certifies)."""

    gain_basis = "Y"


@dataclass(frozen=True)
class VaryingSynthesis:
    """A gain for h(t) in [h1, h2], |h'| <= mu, and its independent checks.

    Attributes
    ----------
    h1 : float
    mu : float or None
    windows : str
        ``"delay"`` or ``"fixed"``.
    eps : float
        Best descriptor scalar of the search.
    bracket : Bracket
        Bisection on h2 (s) of the synthesis LMI at ``eps`` (balanced
        coordinates): an interval certificate [h1, h2] for K = V Y^{-1} of
        its certificate.
    K : numpy.ndarray or None
        Canonical gain (original coordinates, rounded); None when nothing was
        certified.
    eps_tried : tuple[tuple[float, float], ...]
        (eps, h2 certified) of the search, sorted by eps.
    gain : CanonicalGain or None
        How K was chosen; ``gain.h_certified`` is the h2 the rounded K
        certifies with the synthesis LMI (K fixed).
    analysis : VaryingDelayBound or None
        The analysis criterion on (A, B K): an independent interval
        certificate for the rounded K.
    h_max : float
        Search cap on h2 (s).
    """

    h1: float
    mu: float | None
    windows: str
    eps: float
    bracket: Bracket
    K: np.ndarray | None
    eps_tried: tuple[tuple[float, float], ...]
    gain: CanonicalGain | None
    analysis: VaryingDelayBound | None
    h_max: float
    T: np.ndarray = field(repr=False)

    form = "interval"

    @property
    def h2(self) -> float:
        """Upper delay (s) certified by the synthesis LMI (0 when none)."""
        return self.bracket.h_certified


#: Default eps grid of :func:`synthesize_varying`, in units of the cap ``h_max``.
VARYING_EPS_GRID = (0.01, 0.03, 0.1, 0.3, 1.0, 3.0)


def synthesize_varying(A, B, *, h_max: float, h1: float = 0.0, mu: float | None = None,
                       windows: Windows | None = None,
                       eps_grid: Sequence[float] | None = None,
                       golden_steps: int = 4, rel_tol: float = 1e-3,
                       margin: float = DEFAULT_MARGIN,
                       gain_fractions: Sequence[float] = GAIN_FRACTIONS,
                       gain_digits: int = DEFAULT_DIGITS) -> VaryingSynthesis:
    """Largest h2 with a gain certified for h(t) in [h1, h2], |h'| <= mu; eps searched.

    Parameters
    ----------
    A : (n, n) array_like
    B : (n, m) array_like
        The loop is x' = A x + B K x(t - h(t)).
    h1 : float
        Lower delay bound (s).
    mu : float or None
        Bound on |h'(t)|; None = unknown.
    windows : {"delay", "fixed"}, optional
        See :class:`~workbench.lmi.varying.VaryingDelayLMI`.
    eps_grid : sequence of float, optional
        Log grid of the descriptor scalar (s), refined by ``golden_steps``
        golden-section steps (a fixed eps: a one-element grid and
        ``golden_steps=0``); default :data:`VARYING_EPS_GRID` times ``h_max``.
    h_max : float
        Search cap on h2 (s), required (no absolute default); the search
        starts at h1 + 1e-3 max(h1, h_max / 10).
    rel_tol : float
        Relative bracket width of each bisection.
    margin : float
        Relative LMI margin.
    gain_fractions : sequence of float
        Fractions of h2 tried in order for the canonical gain: the first
        whose minimum-norm point is certified and whose rounded K certifies
        a delay on its own gives K (near h2 the minimum-norm problem is
        ill-conditioned and Clarabel may answer "inaccurate").
    gain_digits : int
        Significant digits of K (:func:`~workbench.lmi.gain.canonical_gain`).

    Returns
    -------
    VaryingSynthesis
        Solved in balanced coordinates (exact power-of-two scaling); K is
        mapped back.
    """
    eps_grid = eps_grid_for(eps_grid, VARYING_EPS_GRID, h_max)
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(A.shape[0], -1)
    T, Tinv, ((At, Bt),) = balance_points([(A, B)])
    u = time_unit(h_max)
    lmi = VaryingDelaySynthesis(At, Bt, eps_grid[0], h1=h1, mu=mu, windows=windows,
                                margin=margin, unit=u)
    h_lo = lmi.h1 + 1e-3 * max(lmi.h1, h_max / 10)
    if uncontrollable_mode([(A, B)]) is not None:   # diagnosed before any solve
        return VaryingSynthesis(lmi.h1, lmi.mu, lmi.windows, eps_grid[0], INFEASIBLE, None, (),
                                None, None, float(h_max), T)
    tried: dict[float, Bracket] = {}

    def h_of(eps: float) -> float:
        lmi.set_eps(eps)
        guess = max((b.h_certified for b in tried.values()), default=0.0) or None
        tried[eps] = bisect_delay(lmi.solve_at, h_lo=h_lo, h_hi=h_max, rel_tol=rel_tol,
                                  guess=guess)
        return tried[eps].h_certified

    best, _ = maximise_log_scalar(h_of, list(eps_grid), golden_steps=golden_steps,
                                  stop_at=h_max)
    br = tried[best]
    K = gain = analysis = None
    if br.certificate is not None:
        lmi.set_eps(best)
        for fraction in gain_fractions:
            if not fraction * br.h_certified > lmi.h1:      # stay inside (h1, h2]
                continue
            gain = canonical_gain(
                lmi, br.h_certified,
                lambda Kt: VaryingDelaySynthesisFixedK(At, Bt, best, K=Kt, h1=lmi.h1,
                                                       mu=lmi.mu, windows=lmi.windows,
                                                       margin=margin, unit=u),
                T, fraction=fraction, digits=gain_digits, h_lo=h_lo, h_hi=h_max,
                rel_tol=rel_tol)
            if gain.outcome is Outcome.CERTIFIED:
                break
        K = None if gain is None else gain.K
    if K is not None:
        Ad = B @ K
        analysis = certified_varying_delay(At, Tinv @ Ad @ T, h1=lmi.h1, mu=lmi.mu,
                                           windows=lmi.windows, h_hi=h_max, rel_tol=rel_tol,
                                           margin=margin, guess=br.h_certified)
    pairs = tuple(sorted((e, b.h_certified) for e, b in tried.items()))
    return VaryingSynthesis(lmi.h1, lmi.mu, lmi.windows, best, br, K, pairs, gain, analysis,
                            float(h_max), T)


def recheck_varying(A, B, result: VaryingSynthesis,
                    certificate=None) -> dict[str, float]:
    """Re-evaluate the synthesis LMI at ``result``'s eps and h2 with numpy.

    Parameters
    ----------
    A, B : array_like
        The system the result was synthesised for.
    result : VaryingSynthesis
    certificate : mapping, optional
        Decision variables to check (default: the result's own); pass a
        modified copy to see a tampered certificate fail.

    Returns
    -------
    dict[str, float]
        Relative margin of each block (>= the LMI's margin passes).
    """
    A = np.atleast_2d(np.asarray(A, float))
    B = np.asarray(B, float).reshape(A.shape[0], -1)
    Tinv = np.diag(1.0 / np.diag(result.T))
    lmi = VaryingDelaySynthesis(Tinv @ A @ result.T, Tinv @ B, result.eps, h1=result.h1,
                                mu=result.mu, windows=result.windows,
                                unit=time_unit(result.h_max))
    cert = result.bracket.certificate.certificate if certificate is None else certificate
    return lmi.recheck(cert, result.bracket.h_certified)


