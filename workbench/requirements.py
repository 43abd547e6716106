"""Design to requirements: a gain, its certificates and an exact check per requirement.

A requirement set (delay range, decay rate, L2 gain, input limit, objective)
is turned into a gain by :func:`~workbench.lmi.requirements_synthesis.synthesize_requirements`
(LMI layer); every requirement of the returned (rounded) gain is then put
next to an exact check that uses no LMI (:mod:`workbench.margins.decay` and a
simulation of the delayed loop from the box's vertices):

=================  ===========================================  ====================================
requirement        certificate (rounded K, K fixed)             exact check
=================  ===========================================  ====================================
delay [lo, hi]     largest stability cap H (every h in [0, H])  worst exact decay > 0 on the range
decay_rate alpha   Bessel-Legendre cells on [lo, hi]            rightmost root, dense grid + cells
l2_gain gamma      descriptor bounded-real LMI on [0, hi]       H-infinity norm on the delay grid
input_limit        invariant ellipsoid containing the box       simulations from the box's vertices
=================  ===========================================  ====================================

Verdicts (closed set): PASS when the certified value meets the requirement
and the exact check confirms the certificate; FAIL when the exact check
shows the requirement is not met (or contradicts a certificate);
INCONCLUSIVE when no gain was returned or the certificate does not reach the
requirement while the exact check does not refute it.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from .lmi.requirements import Loop, box_vertices
from .lmi.requirements_synthesis import RequirementDesign, synthesize_requirements
from .margins.decay import worst_decay, worst_hinf
from .outcome import Verdict

__all__ = ["Requirements", "RequirementRow", "RequirementResult", "design_to_requirements",
           "simulate_limit"]


@dataclass(frozen=True)
class Requirements:
    """A requirement set (units of the model: s, 1/s, input units).

    Attributes
    ----------
    delay : (float, float)
        Constant delays [h_min, h_max] (s) the loop must tolerate.
    decay_rate : float or None
        Every solution decays at least like e^{-alpha t} (1/s).
    l2_gain : float or None
        ||z||_2 <= gamma ||w||_2 (needs ``Bw``, ``Cz``, ``Dz`` in the loop).
    input_limit : tuple of float or None
        |u_k| <= u_max_k from every constant initial history in ``box``.
    box : tuple of float or None
        Half-widths of the initial-deviation box (state units).
    objective : {"decay", "l2_gain", "delay"}
    rate : float or None
        Time-varying delay: every delay function h(t) in [h_min, h_max] with
        |h'(t)| <= rate (0 <= rate < 1; the certificates cover h(t) in
        [0, h_max]); None: constant delays.
    """

    delay: tuple[float, float]
    decay_rate: float | None = None
    l2_gain: float | None = None
    input_limit: tuple[float, ...] | None = None
    box: tuple[float, ...] | None = None
    objective: str = "decay"
    rate: float | None = None


@dataclass(frozen=True)
class RequirementRow:
    """One requirement: required, certified and exact values and the verdict."""

    name: str
    required: str
    certified: float | None
    exact: float | None
    verdict: str
    note: str = ""

    def as_dict(self) -> dict:
        return {"name": self.name, "required": self.required, "certified": self.certified,
                "exact": self.exact, "verdict": self.verdict, "note": self.note}


@dataclass(frozen=True)
class RequirementResult:
    """The gain designed to a requirement set, with one row per requirement.

    Attributes
    ----------
    K : numpy.ndarray or None
        The returned gain (rounded; the gain every row is about).
    rows : tuple[RequirementRow, ...]
    design : RequirementDesign
        The synthesis (brackets, canonical point, the gain's certificates).
    seconds : float
        Synthesis and certification time (not printed in reports).
    reason : str
        Why no gain was returned ("" otherwise).
    rate : float or None
        The delay-derivative bound the certificates hold for (None: constant
        delays).
    varying : VaryingDelayRun or None
        With ``rate``: a simulation of the loop (first point) under a
        triangle-wave delay in [h_min, h_max] with slope ``rate``.
    """

    K: np.ndarray | None
    rows: tuple[RequirementRow, ...]
    design: RequirementDesign = field(repr=False)
    seconds: float = 0.0
    reason: str = ""
    rate: float | None = None
    varying: object = field(default=None, repr=False)

    def row(self, name: str) -> RequirementRow:
        return next(r for r in self.rows if r.name == name)

    def as_dict(self) -> dict:
        return {"K": None if self.K is None else self.K.tolist(),
                "objective": self.design.objective, "reason": self.reason, "rate": self.rate,
                "requirements": {r.name: r.as_dict() for r in self.rows}}


def simulate_limit(points, K, box, h_values, *, t_end: float, steps_per_delay: int = 40
                   ) -> float:
    """Largest |u_k(t)| (per input) over RK4 simulations of x' = A_i x + B_i K x(t - h)
    from constant initial histories at +-(each box vertex), for each h in
    ``h_values`` (s), over [0, t_end] (s); the input u(t) = K x(t - h) is
    the delayed feedback the plant receives."""
    K = np.atleast_2d(K)
    peak = np.zeros(K.shape[0])
    for A, B in points:
        Ad = B @ K
        for h in h_values:
            m = steps_per_delay if h > 0 else 1
            dt = h / m if h > 0 else min(t_end / 4000, 1e-3)
            n_steps = int(math.ceil(t_end / dt))
            for v in box_vertices(np.asarray(box, float)):
                for x0 in (v, -v):
                    hist = [np.array(x0, float)] * (m + 1)     # x on [-h, 0]
                    x = np.array(x0, float)

                    def xd(k, frac):   # x(t_k + frac dt - h)
                        a, b = hist[k], hist[k + 1]
                        return a + frac * (b - a)
                    for k in range(n_steps):
                        if h == 0:
                            f = lambda y, _f: (A + Ad) @ y
                        else:
                            f = lambda y, _f: A @ y + Ad @ xd(k, _f)
                        peak = np.maximum(peak, np.abs(K @ (xd(k, 0.0) if h > 0 else x)))
                        k1 = f(x, 0.0)
                        k2 = f(x + 0.5 * dt * k1, 0.5)
                        k3 = f(x + 0.5 * dt * k2, 0.5)
                        k4 = f(x + dt * k3, 1.0)
                        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
                        hist.append(x)
    return peak


def _verdict(meets_cert: bool | None, meets_exact: bool, consistent: bool) -> str:
    if not consistent or not meets_exact:
        return Verdict.FAIL.value
    if meets_cert:
        return Verdict.PASS.value
    return Verdict.INCONCLUSIVE.value


def design_to_requirements(points: Sequence[tuple[np.ndarray, np.ndarray]], req: Requirements,
                           *, Bw=None, Cz=None, Dz=None, t_sim: float | None = None
                           ) -> RequirementResult:
    """Design the canonical gain to ``req`` and check every requirement exactly.

    Parameters
    ----------
    points : sequence of (A, B)
        Operating points (one gain for all).
    req : Requirements
    Bw, Cz, Dz : arrays, optional
        Disturbance input and performance output z = Cz x + Dz u(t - h)
        (required with ``req.l2_gain`` or objective ``"l2_gain"``).
    t_sim : float, optional
        Horizon (s) of the input-limit simulations (default 10 / decay or
        20 h_max).

    Returns
    -------
    RequirementResult
    """
    h_min, h_max = map(float, req.delay)
    alpha = float(req.decay_rate or 0.0)
    l2 = req.l2_gain is not None or req.objective == "l2_gain"
    limited = req.input_limit is not None
    loop = Loop(tuple((np.asarray(A, float), np.asarray(B, float)) for A, B in points),
                np.asarray(Bw, float) if l2 else None, np.asarray(Cz, float) if l2 else None,
                np.asarray(Dz, float) if l2 else None,
                np.asarray(req.box, float) if limited else None,
                np.asarray(req.input_limit, float) if limited else None)
    t0 = time.perf_counter()
    mu = req.rate
    d = synthesize_requirements(loop, objective=req.objective, H=h_max, h_min=h_min,
                                alpha=alpha, gamma=float(req.l2_gain or 1.0), mu=mu)
    seconds = time.perf_counter() - t0
    K, c = d.K, d.certificate
    rows = []
    if K is None:
        for name, need in (("delay", f"[{h_min:g}, {h_max:g}] s"),
                           ("decay", _opt(req.decay_rate, req.objective == "decay", ">=")),
                           ("l2_gain", _opt(req.l2_gain, req.objective == "l2_gain", "<=")),
                           ("input_limit", None if not limited else str(req.input_limit))):
            if need is not None:
                rows.append(RequirementRow(name, need, None, None, Verdict.INCONCLUSIVE.value,
                                           f"no gain: {d.reason}"))
        return RequirementResult(None, tuple(rows), d, seconds, d.reason, mu)
    ad = [(A, B @ K) for A, B in loop.points]
    a_c = c.alpha_certified
    ex = worst_decay(ad, h_min, h_max, alpha=a_c)
    hk = c.h_certified
    covers = (f"every constant delay in [{h_min:g}, {h_max:g}] s" if mu is None else
              f"every delay function h(t) in [0, {h_max:g}] s with |h'| <= {mu:g} (certificate;"
              " constant delays are the case h' = 0, the exact check's)")
    rows.append(RequirementRow(
        "delay", f"[{h_min:g}, {h_max:g}] s" + ("" if mu is None else f", |h'| <= {mu:g}"),
        hk, ex.decay,
        _verdict(hk is not None and hk >= h_max, ex.decay > 0, True),
        "certified: largest cap H with asymptotic stability for every delay in [0, H]"
        + ("" if mu is None else f" (every h(t) with |h'| <= {mu:g})")
        + "; exact: worst decay on the range of constant delays (> 0: stable)"))
    if req.decay_rate is not None or req.objective == "decay":
        ok_exact = ex.decay >= alpha if req.decay_rate is not None else True
        consistent = a_c is None or (ex.decay >= a_c and ex.clear)
        rows.append(RequirementRow(
            "decay", _opt(req.decay_rate, req.objective == "decay", ">="), a_c, ex.decay,
            _verdict(a_c is not None and a_c >= alpha, ok_exact, consistent),
            f"{covers}; exact worst at h = {ex.h:.4g} s"
            + ("" if ex.clear else "; a cell is not clear of crossings")))
    if l2:
        g_c = c.gamma_certified
        g_x = worst_hinf(ad, loop.Bw, loop.Cz, loop.Dz @ K,
                         h_min, h_max)[0]
        req_g = req.l2_gain if req.l2_gain is not None else math.inf
        rows.append(RequirementRow(
            "l2_gain", _opt(req.l2_gain, req.objective == "l2_gain", "<="), g_c, g_x,
            _verdict(g_c is not None and g_c <= req_g, g_x <= req_g,
                     g_c is None or g_x <= g_c * (1 + 1e-6)),
            f"every delay in [0, {h_max:g}] s (certificate) and on the delay grid (exact)"))
    if limited:
        horizon = t_sim or (10.0 / max(a_c or 0.0, 1e-9) if a_c else 20.0 * h_max)
        horizon = min(horizon, 200.0 * h_max + 60.0)
        peak = simulate_limit(loop.points, K, req.box, sorted({h_min, (h_min + h_max) / 2,
                                                               h_max}), t_end=horizon)
        ratio = float(np.max(peak / np.asarray(req.input_limit, float)))
        joint = c.joint is not None and c.joint.outcome.value == "certified"
        rows.append(RequirementRow(
            "input_limit", "|u| <= " + ", ".join(f"{u:g}" for u in req.input_limit),
            1.0 if joint else None, ratio, _verdict(joint, ratio <= 1.0, True),
            "certified: invariant ellipsoid containing the box of constant initial histories "
            f"(box {list(req.box)}), every delay in [0, {h_max:g}] s; exact: peak |u|/u_max of "
            "simulations from the box's vertices at h_min, mid, h_max"))
    run = None
    if mu is not None and mu > 0 and h_max > h_min:
        run = simulate_varying(loop.points[0], K, (h_min, h_max), mu, a_c)
    return RequirementResult(K, tuple(rows), d, seconds, "", mu, run)


def simulate_varying(point, K, delay: tuple[float, float], mu: float,
                     alpha: float | None, *, periods: int = 3):
    """The loop x' = A x + B K x(t - h(t)) under the triangle-wave delay of
    :func:`workbench.sim.varying_delay.triangle_delay` (h_min to h_max with
    slope ``mu``), from the constant initial history x0 = (1, ..., 1) state
    units, over ``periods`` delay periods or 8 / alpha (s), whichever is
    longer: a time-domain illustration of the rate certificate (not a proof)."""
    from .sim.varying_delay import simulate_varying_delay, triangle_delay
    A, B = point
    h_min, h_max = delay
    period = 2.0 * (h_max - h_min) / mu
    t_end = max(periods * period, 8.0 / alpha if alpha else 0.0, 20.0 * h_max)
    dt = min(h_max / 40.0, t_end / 4000.0)
    return simulate_varying_delay(A, B @ np.atleast_2d(K), triangle_delay(h_min, h_max, mu),
                                  h_max, np.ones(A.shape[0]), t_end, dt,
                                  record_every=max(1, int(t_end / dt / 2000)))


def _opt(value, objective: bool, sense: str) -> str:
    if value is None:
        return "maximise" if sense == ">=" else "minimise"
    return f"{sense} {value:g}" + (" (objective)" if objective else "")
