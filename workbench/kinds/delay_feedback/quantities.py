"""The claimable quantities of a ``delay-feedback`` design, declared once:
name, unit and reader (:mod:`workbench.features.quantities`).

:data:`TABLE` is the single list; :meth:`DelayFeedback.quantity_names` and
:func:`~workbench.kinds.delay_feedback.run.quantities` both expand it. Units
are those of the design's ``[[states]]`` and ``[[inputs]]`` (``x`` a state,
``u`` an input); ``""`` marks a word (``yes``/``no``, an outcome).
"""
from __future__ import annotations

import math

import numpy as np

from ...features.quantities import Declared, Group

__all__ = ["TABLE"]


def _eps_key(eps: float) -> str:
    return f"{eps:g}"


# -- indices (from the spec: every name is known before running) ----------------------
def _point(spec):
    p = spec.plant
    return [{"k": v.name, "i": i, "unit": v.unit} for i, v in enumerate(p.states + p.inputs)]


def _entries(rows, cols):
    return lambda spec: [{"i": i + 1, "j": j + 1, "ui": a.unit, "uj": b.unit}
                         for i, a in enumerate(rows(spec)) for j, b in enumerate(cols(spec))]


_states = lambda spec: spec.plant.states
_inputs = lambda spec: spec.plant.inputs


def _rows(field):
    return lambda spec: [{"e": _eps_key(e), "f": field} for e in spec.synthesis.eps]


def _vertices(field):
    return lambda spec: [{"v": v.name, "f": field} for v in spec.vertices]


def _scenarios(spec):
    return [{"s": s.name} for s in spec.scenarios]


def _per_variable(metric, variables, scheduled_only=False):
    return lambda spec: [{"s": s.name, "m": metric, "k": v.name, "unit": v.unit}
                         for s in spec.scenarios for v in variables(spec)
                         if s.parameters or not scheduled_only]


# -- readers ----------------------------------------------------------------------------
def _last(items):
    """The last of ``items`` (None if empty): a later entry of the same name wins."""
    out = None
    for out in items:
        pass
    return out


def _yes(b) -> str:
    return "yes" if b else "no"


def _h_certified(r):
    s = r.synthesis
    return s.h_certified if s.h_certified > 0 and s.K is not None else None  # no gain: undetermined


def _row(r, e, f):
    from ...features.sweep_study import row_value
    row = _last(x for x in r.synthesis.rows if _eps_key(x.eps) == e)
    return None if row is None else row_value(row, f)


def _vertex(r, v, f):
    hit = _last((c, ab) for vx, c, ab in r.vertex_checks if vx.name == v)
    if hit is None:
        return None
    c, ab = hit
    return {"abscissa_at_h_gain": ab, "exact_margin": c.exact.h, "h_analysis": c.h_certified,
            "stable_at_zero": _yes(c.stable_at_zero)}[f]


def _scenario(r, s):
    return _last(x for x in r.scenarios if x.scenario.name == s)


def _metric(r, s, m, k, unit):
    sr = _scenario(r, s)
    v = None if sr is None else sr.metrics.get(f"{m}.{k}")
    return None if v is None or math.isnan(v) else v


def _gain(r, i, j, ui, uj):
    K = r.synthesis.K
    return None if K is None else float(K[i - 1, j - 1])


def _closed_loop_hurwitz(r):
    K = r.synthesis.K
    return None if K is None else _yes(np.max(np.linalg.eigvals(r.A + r.B @ K).real) < 0)


def covers(res) -> str:
    """``yes``: the certificate holds for every delay in [0, h_certified] and
    that reaches the design's largest delay; ``at-h-only``: the bound
    reaches it but the certificate is for the single delay h; else ``no``."""
    s = res.synthesis
    if s.status != "certified" or s.h_gain is None:
        return "no"
    return "no" if not s.h_gain >= res.delay.h_max else ("yes" if s.all_delays
                                                            else "at-h-only")


# -- the features' own quantities ---------------------------------------------------------
def _requirement_names(spec):
    from .requirements import requirement_quantity_names
    return requirement_quantity_names(spec.requirements)


def _requirement_values(r):
    from .requirements import requirement_quantities
    s = r.synthesis
    return requirement_quantities(s.requirements) if s.method == "requirements" else {}


def _basin_names(spec):
    from ...features.basin import basin_quantity_names
    return basin_quantity_names(spec)


def _basin_values(r):
    from ...features.basin import basin_quantities
    return {} if r.basin is None else basin_quantities(r.basin)


def _implementation_names(spec):
    from ...features.sampled import implementation_quantity_names
    return implementation_quantity_names(spec)


def _implementation_values(r):
    from ...features.sampled import implementation_quantities
    return {} if r.implementation is None else implementation_quantities(r.implementation)


def _montecarlo_names(spec):
    from .montecarlo import montecarlo_names
    return montecarlo_names(spec)


def _montecarlo_values(r):
    from .montecarlo import montecarlo_values
    return montecarlo_values(r)


def _gain_tables_names(spec):
    from .gain_tables import gain_tables_names
    return gain_tables_names(spec)


def _gain_tables_values(r):
    from .gain_tables import gain_tables_values
    return gain_tables_values(r)


#: Every claimable quantity of a ``delay-feedback`` design.
TABLE = (
    Declared("operating_point.{k}", "{unit}",
             lambda r, k, i, unit: float(np.concatenate([r.op.x, r.op.u])[i]), over=_point),
    Declared("operating_point.residual", "x/s", lambda r: r.op.residual),
    Declared("open_loop.hurwitz", "", lambda r: _yes(np.max(np.linalg.eigvals(r.A).real) < 0)),
    Declared("exact_margin", "s", lambda r: None if r.exact is None else r.exact.h),
    Declared("exact.agreement", "", lambda r: None if r.exact is None else r.exact.outcome.value),
    Declared("exact.delay_range_stable", "",
             lambda r: None if r.range_stable is None else _yes(r.range_stable)),
    Declared("certificate.covers_delay_range", "", covers),
    Declared("synthesis.h_certified", "s", _h_certified),
    Declared("synthesis.h_refuted", "s", lambda r: r.synthesis.h_refuted),
    Declared("synthesis.h_gain", "s", lambda r: r.synthesis.h_gain),
    Declared("synthesis.status", "", lambda r: r.synthesis.status),
    Declared("synthesis.eps", "1", lambda r: r.synthesis.eps),
    Declared("synthesis.h_analysis", "s", lambda r: r.synthesis.h_analysis),
    Declared("synthesis.at_cap", "", lambda r: _yes(r.synthesis.at_cap)),
    Declared("closed_loop.hurwitz", "", _closed_loop_hurwitz),
    Declared("linearisation.A[{i},{j}]", "({ui})/(({uj}) s)",
             lambda r, i, j, ui, uj: float(r.A[i - 1, j - 1]), over=_entries(_states, _states)),
    Declared("linearisation.B[{i},{j}]", "({ui})/(({uj}) s)",
             lambda r, i, j, ui, uj: float(r.B[i - 1, j - 1]), over=_entries(_states, _inputs)),
    Declared("synthesis.K[{i},{j}]", "({ui})/({uj})", _gain, over=_entries(_inputs, _states)),
    *(Declared("synthesis.rows[eps={e}].{f}", unit, _row, over=_rows(f))
      for f, unit in (("h_certified", "s"), ("h_refuted", "s"), ("h_gain", "s"),
                      ("status", ""), ("exact_margin", "s"))),
    *(Declared("vertices.{v}.{f}", unit, _vertex, over=_vertices(f))
      for f, unit in (("exact_margin", "s"), ("h_analysis", "s"), ("stable_at_zero", ""),
                      ("abscissa_at_h_gain", "1/s"))),
    Declared("simulation.{s}.diverged", "",
             lambda r, s: None if _scenario(r, s) is None
             else _yes(_scenario(r, s).metrics["diverged"]), over=_scenarios),
    Declared("simulation.{s}.converged", "",
             lambda r, s: None if _scenario(r, s) is None else _yes(_scenario(r, s).converged),
             over=_scenarios),
    *(Declared("simulation.{s}.{m}.{k}", "{unit}", _metric, over=_per_variable(m, variables))
      for m, variables in (("peak_error", _states), ("final_error", _states),
                           ("peak_input_dev", _inputs))),
    # the signed smallest deviation, in scenarios with a parameter schedule
    Declared("simulation.{s}.{m}.{k}", "{unit}", _metric,
             over=_per_variable("min_error", _states, scheduled_only=True)),
    Group(_requirement_names, _requirement_values),
    Group(_basin_names, _basin_values, present=lambda spec: spec.basin is not None),
    Group(_implementation_names, _implementation_values,
          present=lambda spec: spec.implementation is not None),
    Group(_montecarlo_names, _montecarlo_values,
          present=lambda spec: spec.montecarlo is not None),
    Group(_gain_tables_names, _gain_tables_values, present=lambda spec: bool(spec.gain_tables)),
)
