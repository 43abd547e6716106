"""Claimable quantities of a ``switched-run`` design, declared once
(:mod:`workbench.features.quantities`).

Per scenario ``s`` (``scenario.<s>.<metric>``, values of the run at the
designed step)::

    final.<x> peak.<x> min.<x>        state at the end, largest, smallest
    final_error.<x> peak_error.<x>    x - target at the end (signed), largest |x - target|
    peak_abs.<u>                      largest |command|
    time_in.<phase>                   s spent in the phase
    switch_time.<a>.<b>               first switch a -> b (s; not determined if none)
    switches end_time completed       count; s; 1 when `until` ended the run
    diverged diverged_time            1 when the run diverged or chattered; s
    peak_abs_accel peak_abs_jerk      with [comfort]: |d speed/dt|, |d^2 speed/dt^2|
    time_above_accel time_above_jerk  with a_max, jerk_max in [comfort]: s above the limit

With ``[montecarlo]``: ``montecarlo.<s>.runs``, ``.diverged``,
``.completed`` (counts), ``montecarlo.<s>.max.<metric>`` and ``.min.<metric>``
over the runs; per claim on a scenario metric ``montecarlo.claim.<id>.pass_rate``,
``.lo``, ``.hi`` (Wilson 95 %), ``.failures`` and ``.success_run_lower`` (with
no failure: 0.05**(1/n), the one-sided 95 % lower bound of the pass
probability; n >= 299 runs without a failure show P >= 0.99).
"""
from __future__ import annotations


from ...features.quantities import Declared, determined

__all__ = ["TABLE", "scenario_metrics"]


def scenario_metrics(spec, scenario: str) -> dict[str, str]:
    """metric -> unit of the named scenario (the spec's states, inputs, phases)."""
    sc = next(s for s in spec.scenarios if s.name == scenario)
    plant = spec.plant
    out = {}
    for v in plant.states:
        out |= {f"final.{v.name}": v.unit, f"peak.{v.name}": v.unit, f"min.{v.name}": v.unit}
    for v in plant.states:
        if v.name in sc.target:
            out |= {f"final_error.{v.name}": v.unit, f"peak_error.{v.name}": v.unit}
    out |= {f"peak_abs.{u.name}": u.unit for u in plant.inputs}
    out |= {f"time_in.{p.name}": "s" for p in spec.phases}
    out |= {f"switch_time.{p.name}.{to}": "s" for p in spec.phases for to, _ in p.next}
    out |= {"switches": "1", "end_time": "s", "completed": "1", "diverged": "1",
            "diverged_time": "s"}
    if spec.speed is not None:
        from ...features.comfort import metric_units
        u = next(v.unit for v in plant.states if v.name == spec.speed)
        out |= metric_units(u, spec.comfort)
    return out


def _scenario_members(spec):
    for sc in spec.scenarios:
        for metric, unit in scenario_metrics(spec, sc.name).items():
            yield {"s": sc.name, "metric": metric, "unit": unit}


def _mc_scenarios(spec):
    return [{"s": sc.name} for sc in spec.scenarios] if spec.montecarlo else []


def _mc_metrics(spec):
    return list(_scenario_members(spec)) if spec.montecarlo else []


def _mc_claims(spec):
    return [{"id": c.claim.id} for c in spec.claims] if spec.montecarlo else []


def _run(r, s):
    return next(x for x in r.scenarios if x.scenario.name == s)


def _rate(r, id):
    return next(c for c in r.claim_rates if c.claim_id == id)


def _extreme(r, s, metric, fn):
    v = _run(r, s).montecarlo.metrics[metric]
    import numpy as np
    return None if np.all(np.isnan(v)) else float(fn(v))


def _nanmax(v):
    import numpy as np
    return np.nanmax(v)


def _nanmin(v):
    import numpy as np
    return np.nanmin(v)


TABLE = (
    Declared("scenario.{s}.{metric}", "{unit}",
             lambda r, s, metric, unit: determined(float(_run(r, s).values[metric])), over=_scenario_members),
    Declared("montecarlo.{s}.runs", "1",
             lambda r, s: _run(r, s).montecarlo.samples, over=_mc_scenarios),
    Declared("montecarlo.{s}.diverged", "1",
             lambda r, s: int(_run(r, s).montecarlo.metrics["diverged"].sum()),
             over=_mc_scenarios),
    Declared("montecarlo.{s}.completed", "1",
             lambda r, s: int(_run(r, s).montecarlo.metrics["completed"].sum()),
             over=_mc_scenarios),
    Declared("montecarlo.{s}.max.{metric}", "{unit}",
             lambda r, s, metric, unit: _extreme(r, s, metric, _nanmax), over=_mc_metrics),
    Declared("montecarlo.{s}.min.{metric}", "{unit}",
             lambda r, s, metric, unit: _extreme(r, s, metric, _nanmin), over=_mc_metrics),
    Declared("montecarlo.claim.{id}.pass_rate", "1", lambda r, id: _rate(r, id).p,
             over=_mc_claims),
    Declared("montecarlo.claim.{id}.lo", "1", lambda r, id: _rate(r, id).lo, over=_mc_claims),
    Declared("montecarlo.claim.{id}.hi", "1", lambda r, id: _rate(r, id).hi, over=_mc_claims),
    Declared("montecarlo.claim.{id}.failures", "1", lambda r, id: _rate(r, id).n
             - _rate(r, id).passes, over=_mc_claims),
    Declared("montecarlo.claim.{id}.success_run_lower", "1",
             lambda r, id: _rate(r, id).success_run_lower, over=_mc_claims),
)
