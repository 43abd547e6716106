"""Claimable quantities of a ``platoon`` design, declared once
(:mod:`workbench.features.quantities`).

Per run ``<r>`` of ``[[runs]]`` and laws ``<a>``, ``<b>``::

    leader.v_cruise                          the leader's cruise speed (m/s)
    <r>.max_abs_e, <r>.cruise_abs_e          worst |e| over the followers: whole run, cruise (m)
    <r>.cruise_abs_de                        worst |e'| in cruise (m/s)
    <r>.chatter, <r>.sign_rate               (1/t) sum |du|/m (m/s^3); sign flips of s (1/s)
    <r>.lumped_ratio, <r>.string_ratio       max |w + d| / (G_w + G_d); max ||e_i+1|| / ||e_i||
    <r>.max_speed                            (m/s)
    <r1>_over_<r2>.max_abs_e                 two runs from exact spacing
    convergence.train<i>.<k>, convergence.max_*   with [reaching]
    emergency.<case>.link.<k>                mean_age, max_age (s), lost
    emergency.<case>.<a>.<k>                 min_gap, t_min_gap, min_margin, t_min_margin,
                                             cruise_abs_e, stopped (yes/no)
    emergency.<case>.<a>_minus_<b>.<k>       min_gap, min_margin (m)
    emergency.<a or worst>.<k>               min_gap, min_margin over both cases (m)
    delay_margin.<k>, delay_sweep.<a>.<k>    with [delay_margin]
    and the [analysis] module's own.
"""
from __future__ import annotations

import math

from ...features.quantities import Declared, Group, names, units, values
from .realism import CASES

__all__ = ["TABLE"]

#: Per-run metric -> unit.
METRICS = {"max_abs_e": "m", "cruise_abs_e": "m", "cruise_abs_de": "m/s", "chatter": "m/s^3",
           "sign_rate": "1/s", "lumped_ratio": "1", "string_ratio": "1", "max_speed": "m/s"}
#: Per-follower reaching quantity -> unit.
REACH = {"t_reach": "s", "e_reach": "m", "slide_eq22": "s", "slide_band": "s",
         "slide_measured": "s"}
_EMERGENCY = {"min_gap": "m", "t_min_gap": "s", "min_margin": "m", "t_min_margin": "s",
              "cruise_abs_e": "m", "stopped": ""}
_MARGIN = {"k_e": "1/s^2", "k_d": "1/s", "h_eig": "s", "h_siso": "s", "omega": "1/s",
           "agreement": "", "h_over_delay": "1", "current_h": "s"}
_SWEEP = {"amp_ratio": "1", "amp_at_delay": "m", "saturated_at_delay": "1"}


def _metric(r, run, k, u):
    m = r.metrics[run]
    x = getattr(m, k)
    return max(x) if isinstance(x, tuple) else x


def _exact(spec):
    return [r.name for r in spec.runs if r.initial_errors is None]


def _ratio(r, a, b):
    den = max(r.metrics[b].max_abs_e)
    return max(r.metrics[a].max_abs_e) / den if den else None


def _done(r):
    done = [c for c in r.convergence if c.slide_measured is not None]
    return done if len(done) == len(r.convergence) and done else None


def _reaching(spec):
    return [] if spec.reaching is None else [{}]


def _pairs(laws):
    return [(a, b) for a in laws for b in laws if a != b]


def _worst(r, who, k):
    return min(getattr(e, k) for (case, law), e in r.realism.emergency.items()
               if who in (law, "worst"))


def _margin(spec):
    return [] if spec.margin is None else [{"k": k, "u": u} for k, u in _MARGIN.items()]


def _margin_value(r, k, u):
    m, delay = r.realism.margin, r.realism.delay
    return {"k_e": lambda: m.k_e, "k_d": lambda: m.k_d, "h_eig": lambda: m.eig.h,
            "h_siso": lambda: m.siso.h, "omega": lambda: m.eig.omega,
            "agreement": lambda: m.agreement[0].value,
            "h_over_delay": lambda: m.eig.h / delay if delay > 0 else math.inf,
            "current_h": lambda: m.current.h}[k]()


def _row(rows, law, factor):
    return next((x for x in rows if x.law == law and x.factor == factor), None)


def _sweep_value(r, law, k, u):
    m = r.realism.margin
    if k == "amp_ratio":
        below = max((f for f in m.factors if f < 1.0), default=None)
        above = min((f for f in m.factors if f > 1.0), default=None)
        lo, hi = _row(m.sweep, law, below), _row(m.sweep, law, above)
        return hi.amp_first / lo.amp_first if lo is not None and hi is not None else None
    d = _row(m.sweep, law, None)
    return d.amp_first if k == "amp_at_delay" else d.saturated


TABLE = (
    Declared("leader.v_cruise", "m/s", lambda r: r.profile.v_cruise),
    Declared("{run}.{k}", "{u}", _metric, over=lambda spec: [
        {"run": x.name, "k": k, "u": u} for x in spec.runs for k, u in METRICS.items()]),
    Declared("{a}_over_{b}.max_abs_e", "1", _ratio, over=lambda spec: [
        {"a": a, "b": b} for a, b in _pairs(_exact(spec))]),
    Declared("convergence.train{i}.{k}", "{u}",
             lambda r, i, k, u: getattr(r.convergence[i - 2], k), over=lambda spec: [
                 {"i": i, "k": k, "u": u} for _ in _reaching(spec)
                 for i in range(2, spec.n + 1) for k, u in REACH.items()]),
    Declared("convergence.max_reaching_time", "s", lambda r: None if _done(r) is None else
             max(c.t_reach for c in _done(r)), over=_reaching),
    Declared("convergence.max_rel_error_band", "1", lambda r: None if _done(r) is None else
             max(abs(c.slide_measured / c.slide_band - 1.0) for c in _done(r)), over=_reaching),
    Declared("convergence.max_ratio_eq22", "1", lambda r: None if _done(r) is None else
             max(c.slide_measured / c.slide_eq22 for c in _done(r)), over=_reaching),
    Declared("emergency.{case}.link.{k}", "{u}",
             lambda r, case, k, u: getattr(r.realism.links[case], k), over=lambda spec: [
                 {"case": c, "k": k, "u": u} for c in CASES
                 for k, u in (("mean_age", "s"), ("max_age", "s"), ("lost", "1"))]),
    Declared("emergency.{case}.{law}.{k}", "{u}", lambda r, case, law, k, u: (
        ("yes" if r.realism.emergency[case, law].stopped else "no") if k == "stopped"
        else getattr(r.realism.emergency[case, law], k)), over=lambda spec: [
            {"case": c, "law": law, "k": k, "u": u} for c in CASES
            for law in spec.emergency.laws for k, u in _EMERGENCY.items()]),
    Declared("emergency.{case}.{a}_minus_{b}.{k}", "m", lambda r, case, a, b, k: (
        getattr(r.realism.emergency[case, a], k) - getattr(r.realism.emergency[case, b], k)),
        over=lambda spec: [{"case": c, "a": a, "b": b, "k": k} for c in CASES
                           for a, b in _pairs(spec.emergency.laws)
                           for k in ("min_gap", "min_margin")]),
    Declared("emergency.{who}.{k}", "m", lambda r, who, k: _worst(r, who, k), over=lambda spec: [
        {"who": w, "k": k} for w in spec.emergency.laws + ("worst",)
        for k in ("min_gap", "min_margin")]),
    Declared("delay_margin.{k}", "{u}", _margin_value, over=_margin),
    Declared("delay_sweep.{law}.{k}", "{u}", _sweep_value, over=lambda spec: [] if spec.margin
             is None else [{"law": law, "k": k, "u": u} for law in spec.margin.sweep
                           for k, u in _SWEEP.items()]),
    # an [analysis] module's own Declared entries (its QUANTITIES)
    Group(names=lambda spec: names(spec.analysis.QUANTITIES, spec),
          values=lambda r: values(r.spec.analysis.QUANTITIES, r.spec, r),
          present=lambda spec: spec.analysis is not None,
          units=lambda spec: units(spec.analysis.QUANTITIES, spec)),
)
