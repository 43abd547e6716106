"""Optimise one requirement subject to the others; the canonical gain and its
own certificate (:mod:`workbench.lmi.requirements`).

The objective is one of

* ``"decay"``: the largest decay rate alpha (1/s), the L2 gain and input
  limit (when declared) held at their required values;
* ``"l2_gain"``: the smallest gamma at the required decay rate;
* ``"delay"``: the largest delay cap H (s) at the required decay rate and gamma;

each a certified bracketed bisection (:func:`~workbench.lmi.core.bisect_delay`
on alpha, 1/gamma or H: certified below, refuted above), inside a search of
the descriptor scalar eps (:func:`~workbench.lmi.robust.maximise_log_scalar`).
The gain is the project's canonical gain (README, "A well-posed gain"): the
minimum-norm certificate at ``fraction`` of the optimum (alpha and H times
the fraction, gamma divided by it), rounded to ``digits`` significant digits,
then certified *with K fixed* by :class:`~workbench.lmi.requirements.RequirementAnalysis`
(P2, P3 free): the values reported are that rounded K's own.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable, Literal

import numpy as np

from .core import DEFAULT_MARGIN, Bracket, Outcome, Step, bisect_delay
from .gain import DEFAULT_DIGITS, DEFAULT_FRACTION, round_significant
from .requirements_decay import MAX_SECONDS, certified_decay
from .requirements import Loop, RequirementAnalysis, RequirementSynthesis
from ..printed_grid import directed
from .robust import maximise_log_scalar
from .scaling import balancing, closed_loop_scaling, gramian_scaling

__all__ = ["Objective", "GainCertificate", "RequirementDesign", "certify_gain",
           "synthesize_requirements"]

Objective = Literal["decay", "l2_gain", "delay"]
#: Searches of 1/gamma span this factor either side of 1 (relative to the
#: loop's own gain scale, see :func:`_gain_scale`).
GAMMA_SPAN = 1e6
#: Lower end of every bisection, relative to its upper end.
FLOOR = 1e-5
#: Points of the eps grid (:func:`eps_grid`).
EPS_POINTS = 6
#: Fraction of the optimum at which the minimum-norm certificate is computed.
#: Not the delay syntheses' 0.99 (:data:`~workbench.lmi.gain.DEFAULT_FRACTION`):
#: 1 % from the optimum of a decay rate the minimum-norm problem is so close
#: to infeasible that Clarabel answers ``optimal`` under one BLAS kernel and
#: ``optimal_inaccurate`` under another (two-train-spacing: AVX-512 against
#: Sandybridge, issue 36), and the fallback then picks a different gain. At
#: 5 % both kernels agreed to 1e-8 in K, until the two-pass synthesis: then
#: two-train-spacing's point at 0.24 (0.95 of 0.2568, on the 2-digit grid) was
#: again ``optimal`` under Sandybridge and ``optimal_inaccurate`` under the
#: default kernel. At 0.9 (0.23) the default, Sandybridge and Prescott kernels
#: give the same gain to 1e-9.
REQUIREMENT_FRACTION = 0.9
#: Fractions of the optimum tried, after ``fraction``, when the minimum-norm
#: certificate is not certified (solver inaccurate close to the optimum).
FALLBACK_FRACTIONS = (0.8,)
#: Significant digits (rounded down) of the objective value at which the
#: canonical point is computed: train-brake-lag's decay optimum was 0.360588
#: under the default OpenBLAS kernel and 0.360699 under Sandybridge (one
#: bisection step decided differently, within the 1e-3 bracket), and 0.95 of
#: each gave gains differing in the 4th digit; at 2 digits both are 0.34.
CANONICAL_DIGITS = 2
#: Relative improvement of the optimum for which the second synthesis pass
#: (coordinates re-balanced from the first gain's closed loop) replaces the first.
SECOND_PASS_GAIN = 0.01
#: Golden-section steps of the eps search after its grid.
GOLDEN_STEPS = 4


@dataclass(frozen=True)
class GainCertificate:
    """What one gain certifies with K fixed.

    Attributes
    ----------
    alpha : Bracket
        Decay rate (1/s) for every constant delay in [h_min, H]
        (Bessel-Legendre cells, :func:`~workbench.lmi.requirements_decay.certified_decay`).
    gamma : Bracket or None
        Bisection on 1/gamma (every constant delay in [0, H], the bounded-real
        descriptor analysis; None: no L2 requirement).
    delay : Bracket
        Largest cap H' (s) with asymptotic stability certified for every
        constant delay in [0, H'] (descriptor analysis).
    joint : Step or None
        The input-limit certificate at cap H (invariant ellipsoid containing
        the box, w = 0); None without an input limit.

    Each requirement is a property of its own (decay of every solution, L2
    gain from zero history, the input bound from the box with w = 0), so
    each has its own certificate.
    """

    alpha: Bracket
    gamma: Bracket | None
    delay: Bracket
    joint: Step | None

    @property
    def alpha_certified(self) -> float | None:
        b = self.alpha
        return None if b.outcome is not Outcome.CERTIFIED else b.h_certified

    @property
    def gamma_certified(self) -> float | None:
        b = self.gamma
        return None if b is None or b.outcome is not Outcome.CERTIFIED else 1.0 / b.h_certified

    @property
    def h_certified(self) -> float | None:
        b = self.delay
        return None if b.outcome is not Outcome.CERTIFIED else b.h_certified


@dataclass(frozen=True)
class RequirementDesign:
    """A synthesis to requirements.

    Attributes
    ----------
    objective : str
    optimum : Bracket
        The synthesis LMI's bracket of the objective (alpha, 1/gamma or H) at
        the best eps.
    eps : float
        Best descriptor scalar (s).
    K : numpy.ndarray or None
        Canonical gain (rounded), original coordinates; None when the
        synthesis certified nothing or its canonical point failed.
    point : Step or None
        The minimum-norm certificate K was taken from.
    certificate : GainCertificate or None
        What the rounded K certifies on its own.
    reason : str
        Why K is None ("" otherwise).
    """

    objective: str
    optimum: Bracket
    eps: float
    K: np.ndarray | None
    point: Step | None
    certificate: GainCertificate | None
    reason: str = ""


def eps_grid(loop: Loop, H: float) -> list[float]:
    """Descriptor scalars tried (s): a log grid from H / 10 to ten times the
    larger of H and the plant's time scale 1 / max ||A_i||."""
    rate = max(float(np.linalg.norm(A, 2)) for A, _ in loop.points)
    top = 10.0 * max(H, 1.0 / rate if rate > 0 else H)
    return [float(f"{e:.12g}") for e in np.geomspace(0.1 * H, top, EPS_POINTS)]


def _gain_scale(loop: Loop) -> float:
    """A rough size of the closed loop's L2 gain (for the 1/gamma search)."""
    A, B = loop.points[0]
    a = max(float(np.linalg.norm(A, 2)), 1e-12)
    return float(np.linalg.norm(loop.Cz, 2) + np.linalg.norm(loop.Dz, 2) + 1e-300) * float(
        np.linalg.norm(loop.Bw, 2)) / a


def _rate_scale(loop: Loop, H: float) -> float:
    """Upper end of a decay-rate search (1/s): beyond the plant's own rates
    and ten times the delay's 1/H."""
    return max(float(np.linalg.norm(A, 2)) for A, _ in loop.points) + 10.0 / H


def _decider(lmi, objective: str, *, H: float, alpha: float, gamma: float
             ) -> Callable[[float], Step]:
    """decide(value) -> Step for a bisection on the objective's variable."""
    def decide(v: float) -> Step:
        if objective == "decay":
            lmi.set_rate(v, gamma)
            step = lmi.solve_at(H)
        elif objective == "l2_gain":
            lmi.set_rate(alpha, 1.0 / v)
            step = lmi.solve_at(H)
        else:
            lmi.set_rate(alpha, gamma)
            step = lmi.solve_at(v)
        return dataclasses.replace(step, h=v)
    return decide


def _range(loop: Loop, objective: str, H: float) -> tuple[float, float]:
    if objective == "decay":
        hi = _rate_scale(loop, H)
    elif objective == "l2_gain":
        s = 1.0 / max(_gain_scale(loop), 1e-300)
        return s / GAMMA_SPAN, s * GAMMA_SPAN
    else:
        hi = 10.0 * H
    return FLOOR * hi, hi


def _bisect(lmi, objective, *, H, alpha, gamma, rel_tol, guess=None) -> Bracket:
    lo, hi = _range(lmi.loop, objective, H)
    return bisect_delay(_decider(lmi, objective, H=H, alpha=alpha, gamma=gamma), h_lo=lo,
                        h_hi=hi, rel_tol=rel_tol, guess=guess, max_seconds=MAX_SECONDS)


def certify_gain(loop: Loop, K: np.ndarray, *, h_min: float | None = None, H: float,
                 alpha: float,
                 gamma: float, margin: float = DEFAULT_MARGIN, rel_tol: float = 1e-3,
                 alpha_guess: float | None = None, N: int = 2,
                 gamma_free: bool = False, mu: float | None = None) -> GainCertificate:
    """What the gain ``K`` (coordinates of ``loop``) certifies on its own,
    one certificate per requirement (see :class:`GainCertificate`): the decay
    rate over [h_min, H] (Bessel-Legendre cells of order N), the L2 gain and
    the input limit over [0, H] and the largest stability cap (descriptor
    analysis with P2, P3 free, at rate 0). With ``mu`` (|h'(t)| <= mu < 1)
    every certificate is the descriptor analysis with the (1 - mu) factor
    (:mod:`workbench.lmi.requirements`): it covers every delay function
    h(t) in [0, H] with |h'| <= mu, the decay included (bisection on alpha).
    ``alpha``, ``gamma`` and ``gamma_free`` are kept for the callers'
    signature (unused)."""
    del alpha, gamma_free
    h_min = 0.0 if h_min is None else h_min
    plain = dataclasses.replace(loop, Bw=None, Cz=None, Dz=None, box=None, u_max=None)
    if mu is None:
        a = certified_decay([(A, B @ K) for A, B in loop.points], h_lo=h_min, H=H,
                            alpha_hi=_rate_scale(loop, H), N=N, margin=margin,
                            rel_tol=rel_tol, guess=alpha_guess)
    else:
        a = _bisect(RequirementAnalysis(plain, K, mu=mu, margin=margin), "decay", H=H,
                    alpha=0.0, gamma=1.0, rel_tol=rel_tol, guess=alpha_guess)
    g = None
    if loop.l2:
        lmi = RequirementAnalysis(dataclasses.replace(loop, box=None, u_max=None), K,
                                  mu=mu, margin=margin)
        g = _bisect(lmi, "l2_gain", H=H, alpha=0.0, gamma=gamma, rel_tol=rel_tol,
                    guess=1.0 / gamma)
    d = _bisect(RequirementAnalysis(plain, K, mu=mu, margin=margin), "delay", H=H, alpha=0.0,
                gamma=1.0, rel_tol=rel_tol, guess=H)
    joint = None
    if loop.limited:
        lmi = RequirementAnalysis(dataclasses.replace(loop, Bw=None, Cz=None, Dz=None), K,
                                  mu=mu, margin=margin)
        lmi.set_rate(0.0)
        joint = lmi.solve_at(H)
    return GainCertificate(a, g, d, joint)


def synthesize_requirements(loop: Loop, *, objective: Objective, H: float,
                            h_min: float | None = None, alpha: float = 0.0,
                            gamma: float = 1.0, margin: float = DEFAULT_MARGIN,
                            fraction: float = REQUIREMENT_FRACTION, digits: int = DEFAULT_DIGITS,
                            rel_tol: float = 1e-3, mu: float | None = None
                            ) -> RequirementDesign:
    """Optimise ``objective`` subject to the other requirements (module docstring).

    Parameters
    ----------
    loop : Loop
        Operating points and declared requirements (original coordinates).
        The synthesis runs in the coordinates of
        :func:`~workbench.lmi.scaling.gramian_scaling` (they follow any
        diagonal state scaling, so the gain does too); the rounded gain is
        certified in power-of-two coordinates balanced from sum_i |A_i| +
        |B_i K| (Osborne, exact).
    objective : {"decay", "l2_gain", "delay"}
    H : float
        Delay cap (s): every constant delay in [0, H] (for ``"delay"`` the
        search starts there).
    h_min : float or None
        Smallest delay of the range (s): the decay certificate of the gain
        covers [h_min, H]; the synthesis LMI covers [0, H].
    alpha : float
        Required decay rate (1/s) held when it is not the objective.
    gamma : float
        Required L2 gain held when it is not the objective (used only when
        ``loop`` declares a disturbance).
    margin, fraction, digits, rel_tol
        Relative LMI margin, canonical-point fraction, significant digits of
        K, relative width of every bracket.
    mu : float or None
        Time-varying delay: every delay function h(t) in [0, H] with
        |h'(t)| <= mu (0 <= mu < 1) is covered by the synthesis and by every
        certificate of the gain; None: constant delays.

    Returns
    -------
    RequirementDesign
    """
    if objective not in ("decay", "l2_gain", "delay"):
        raise ValueError(f"objective = {objective!r}; expected 'decay', 'l2_gain' or 'delay'")
    if objective == "l2_gain" and not loop.l2:
        raise ValueError("objective = 'l2_gain' needs a disturbance input w and an output z")
    T = gramian_scaling(list(loop.points), H)
    first = _pass(loop, T, objective, H=H, alpha=alpha, gamma=gamma, margin=margin,
                  fraction=fraction, rel_tol=rel_tol, mu=mu)
    if first.point is None or first.point.outcome is not Outcome.CERTIFIED:
        # the balancing step of the coordinates can defeat the synthesis (a nearly
        # decoupled state scaled by 2^12): once more with the Gramian normalisation alone
        T = gramian_scaling(list(loop.points), H, balance=False)
        retry = _pass(loop, T, objective, H=H, alpha=alpha, gamma=gamma, margin=margin,
                      fraction=fraction, rel_tol=rel_tol, mu=mu)
        if retry.point is not None and retry.point.outcome is Outcome.CERTIFIED:
            first = retry
    if first.point is None or first.point.outcome is not Outcome.CERTIFIED:
        return RequirementDesign(objective, first.bracket, first.eps, None, first.point, None,
                                 reason=first.reason)
    # second pass, in coordinates re-balanced from the first gain's closed loop
    # (:func:`~workbench.lmi.scaling.closed_loop_scaling`); it replaces the first
    # only when its optimum is better by more than SECOND_PASS_GAIN (so a tie
    # within the brackets' widths cannot pick different passes on two machines)
    T2 = closed_loop_scaling(list(loop.points), first.gain, T)
    second = _pass(loop, T2, objective, H=H, alpha=alpha, gamma=gamma, margin=margin,
                   fraction=fraction, rel_tol=rel_tol, mu=mu)
    use = first
    if (second.point is not None and second.point.outcome is Outcome.CERTIFIED
            and second.bracket.h_certified > (1.0 + SECOND_PASS_GAIN)
            * first.bracket.h_certified):
        use = second
    br, best, point, v = use.bracket, use.eps, use.point, use.value
    K = round_significant(use.gain, digits)
    # the rounded K is certified in exact (power-of-two) coordinates balanced from the
    # loop it closes, sum_i |A_i| + |B_i K| (Osborne): they follow a state scaling too
    Tc = balancing(sum(np.abs(A) + np.abs(B @ K) for A, B in loop.points))
    cert = certify_gain(_scaled(loop, Tc), K @ Tc, h_min=h_min, H=H, alpha=alpha, gamma=gamma,
                        margin=margin, rel_tol=rel_tol,
                        alpha_guess=v if objective == "decay" else None,
                        gamma_free=objective == "l2_gain", mu=mu)
    return RequirementDesign(objective, br, best, K, point, cert)


@dataclass(frozen=True)
class _Pass:
    """One synthesis in the coordinates x = T x~: the eps search, its bracket
    and the minimum-norm certificate at ``value`` (None: nothing certified)."""

    bracket: Bracket
    eps: float
    point: Step | None
    value: float
    gain: np.ndarray | None
    reason: str = ""


def _pass(loop: Loop, T: np.ndarray, objective: str, *, H: float, alpha: float,
          gamma: float, margin: float, fraction: float, rel_tol: float,
          mu: float | None) -> _Pass:
    bal = _scaled(loop, T)
    Tinv = np.diag(1.0 / np.diag(T))
    lmi = RequirementSynthesis(bal, mu=mu, margin=margin)
    tried: dict[float, Bracket] = {}

    def value(eps: float) -> float:
        lmi.set_eps(eps)
        guess = max((b.h_certified for b in tried.values()), default=0.0) or None
        tried[eps] = _bisect(lmi, objective, H=H, alpha=alpha, gamma=gamma, rel_tol=rel_tol,
                             guess=guess)
        return tried[eps].h_certified

    best, _ = maximise_log_scalar(value, eps_grid(bal, H), golden_steps=GOLDEN_STEPS)
    br = tried[best]
    if br.outcome is not Outcome.CERTIFIED:
        return _Pass(br, best, None, 0.0, None, _why(br, objective))
    lmi.set_eps(best)
    for f in (fraction,) + tuple(x for x in FALLBACK_FRACTIONS if x < fraction):
        # alpha, 1/gamma or H, rounded down to CANONICAL_DIGITS: the optimum's
        # bracket ends move with the BLAS kernels (a bisection step near the optimum
        # is decided differently), the printed grid value does not
        v = directed(f * br.h_certified, up=False, sig=CANONICAL_DIGITS)
        point = _canonical(lmi, objective, v, H=H, alpha=alpha, gamma=gamma)
        if point.outcome is Outcome.CERTIFIED:
            return _Pass(br, best, point, v, lmi.gain(point.certificate) @ Tinv)
    return _Pass(br, best, point, v, None,
                 f"canonical point not certified (solver {point.solver_status})")


def _scaled(loop: Loop, T: np.ndarray) -> Loop:
    """``loop`` in the coordinates x = T x~ (T diagonal)."""
    Tinv = np.diag(1.0 / np.diag(T))
    return Loop(tuple((Tinv @ A @ T, Tinv @ B) for A, B in loop.points),
                None if not loop.l2 else Tinv @ loop.Bw, None if not loop.l2 else loop.Cz @ T,
                loop.Dz, None if not loop.limited else np.diag(Tinv) * loop.box, loop.u_max)


def _canonical(lmi, objective: str, v: float, *, H: float, alpha: float, gamma: float) -> Step:
    """The minimum-norm certificate at the objective value ``v`` (alpha,
    1/gamma or H)."""
    if objective == "decay":
        lmi.set_rate(v, gamma)
        return lmi.canonical_point(H)
    if objective == "l2_gain":
        lmi.set_rate(alpha, 1.0 / v)
        return lmi.canonical_point(H)
    lmi.set_rate(alpha, gamma)
    return lmi.canonical_point(v)


def _why(br: Bracket, objective: str) -> str:
    statuses = sorted({s.solver_status for s in br.steps})
    if br.outcome is Outcome.REFUTED:
        return (f"every {objective} value tried was refuted by the synthesis LMI "
                f"(down to {min(s.h for s in br.steps):.3g})")
    return f"no {objective} value certified (solver status: {', '.join(statuses)})"
