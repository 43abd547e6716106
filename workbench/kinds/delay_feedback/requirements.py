"""The ``[requirements]`` table of a ``delay-feedback`` design.

::

    [requirements]
    objective  = "decay"                  # "decay" | "l2_gain" | "delay"
    delay      = [0.3, 0.8]               # s (default: the [delay] table)
    rate       = { value = 0.2, unit = "1", source = "..." }   # optional: |h'(t)| <= rate < 1
    decay_rate = { value = 0.3, unit = "1/s", source = "..." }
    input_limit = { u = { value = 1.0, unit = "m/s^2", source = "..." } }
    box         = { v = { value = 1.0, unit = "m/s", source = "..." } }
    l2_gain     = { value = 2.0, source = "..." }
    disturbance = { parameter = "w", source = "..." }   # a parameter (value 0) in the equations
    outputs     = ["v", "0.1*u"]          # z: expressions of the states and inputs (deviations)

The gain is designed by :func:`workbench.requirements.design_to_requirements`
at the linearisation(s): one gain for the operating point and every
``[[vertices]]`` entry. ``box`` (deviations from the operating point, state
units) and ``input_limit`` (deviation of each input from its operating
value) go together. The disturbance enters through B_w = df/dw at the
operating point; z = C_z dx + D_z du(t - h) is the linearisation of the
output expressions.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["RequirementsSpec", "load_rate_requirements", "load_requirements", "requirement_quantities",
           "requirement_quantity_names", "run_requirements"]

ROWS = ("delay", "decay", "l2_gain", "input_limit")
FIELDS = ("certified", "exact", "verdict")

#: Declared ranges of the ``[requirements]`` values (issue 32: out of range exits 2
#: naming file, key, value and range). Delays (s): h_max in [H_MIN, H_MAX] and
#: h_min = 0 or in [H_MIN, h_max]: below about 1e-6 s the collocation of the
#: characteristic roots (order ~ R h) loses every digit. Rates (1/s) and gains as stated.
H_MIN, H_MAX = 1e-6, 1e3
RANGES = {"decay_rate": (1e-6, 1e3), "l2_gain": (1e-6, 1e6), "input_limit": (1e-9, 1e9),
          "box": (1e-9, 1e9), "rate": (0.0, 1e3)}


@dataclass(frozen=True)
class RequirementsSpec:
    """Validated ``[requirements]`` (see the module docstring)."""

    objective: str
    delay: tuple[float, float]
    decay_rate: float | None
    input_limit: dict | None     # input -> u_max
    box: dict | None             # state -> half-width
    l2_gain: float | None
    disturbance: str | None
    outputs: tuple[str, ...]
    sources: dict
    rate: float | None = None    # |h'(t)| <= rate (None: constant delays)


def _entry(t, name: str, unit: str | None, row: str | None = None):
    """(value, source) of ``{ value, unit, source }`` (unit checked when given),
    the value in ``RANGES[row or name]``."""
    sub = t.table(name)
    lo, hi = RANGES[row or name]
    x = sub.number("value", lo=lo, hi=hi, what=f"number ({unit or 'its unit'})")
    if unit is not None:
        u = sub.string("unit")
        if u != unit:
            raise sub.fail("unit", u, f'"{unit}"')
    else:
        sub.string("unit", default="")
    src = sub.string("source")
    sub.finish()
    return x, src


def _delay_range(t, default=None) -> tuple[float, float]:
    """``delay = [h_min, h_max]`` (s): h_max in [H_MIN, H_MAX], h_min = 0 or in
    [H_MIN, h_max]."""
    rng = t.numbers("delay", what="delays (s)",
                    **({} if default is None else {"default": default}))
    if len(rng) != 2 or not (rng[0] == 0 or H_MIN <= rng[0]) or not (
            rng[0] <= rng[1] and H_MIN <= rng[1] <= H_MAX):
        raise t.fail("delay", list(rng), f"[h_min, h_max] with h_max in [{H_MIN:g}, {H_MAX:g}] "
                     f"and h_min = 0 or in [{H_MIN:g}, h_max] (s)")
    return rng


def load_requirements(root, plant, delay) -> RequirementsSpec | None:
    """Read ``[requirements]`` (None when absent); DesignError on bad input."""
    if not root.has("requirements"):
        return None
    t = root.table("requirements")
    objective = t.string("objective", default="decay", choices=("decay", "l2_gain", "delay"))
    rng = _delay_range(t, (delay.h_min, delay.h_max))
    sources = {"delay": t.string("delay_source", default=delay.source)}
    rate = None
    if t.has("rate"):
        rate, sources["rate"] = _entry(t, "rate", "1")
        if not (rate == 0 or 1e-6 <= rate < 1):     # 5e-324: the drift period overflows
            raise t.table("rate").fail("value", rate, "a delay-derivative bound below 1: 0 "
                                       "or in [1e-06, 1)")
        if not rng[1] > rng[0]:
            raise t.fail("delay", list(rng), "h_min < h_max with a rate (a varying delay)")
        sources["delay"] += f"; |h'| <= {rate:g}: {sources['rate']}"
    alpha = None
    if t.has("decay_rate"):
        alpha, sources["decay"] = _entry(t, "decay_rate", "1/s")
    units = {v.name: v.unit for v in plant.states + plant.inputs}
    limit = box = None
    if t.has("input_limit") != t.has("box"):
        raise t.fail("input_limit" if t.has("input_limit") else "box", "<alone>",
                     "input_limit and box together")
    if t.has("input_limit"):
        lt, bt = t.table("input_limit"), t.table("box")
        limit, box, srcs = {}, {}, []
        for name in plant.input_names:
            limit[name], s = _entry(lt, name, units[name], "input_limit")
            srcs.append(f"{name}: {s}")
        for name in list(bt.data):
            if name not in plant.state_names:
                raise bt.fail(name, bt.data[name], "a state of [states]")
            box[name], s = _entry(bt, name, units[name], "box")
            srcs.append(f"box {name}: {s}")
        lt.finish()
        bt.finish()
        sources["input_limit"] = "; ".join(srcs)
    gamma, dist, outputs = None, None, ()
    if t.has("l2_gain") or objective == "l2_gain" or t.has("disturbance"):
        if t.has("l2_gain"):
            gamma, sources["l2_gain"] = _entry(t, "l2_gain", None)
        d = t.table("disturbance")
        dist = d.string("parameter")
        if dist not in plant.parameters or plant.parameters[dist].value != 0:
            raise d.fail("parameter", dist, "a parameter of [parameters] with value 0")
        sources.setdefault("l2_gain", d.string("source"))
        d.finish()
        raw = t.raw("outputs")
        if not isinstance(raw, list) or not raw or not all(isinstance(s, str) for s in raw):
            raise t.fail("outputs", raw, "a non-empty list of expressions of states and inputs")
        outputs = tuple(raw)
    t.finish()
    return RequirementsSpec(objective, (float(rng[0]), float(rng[1])), alpha, limit, box,
                            gamma, dist, outputs, sources, rate)


def load_rate_requirements(root) -> RequirementsSpec | None:
    """``[requirements]`` with ``delay = [h_min, h_max]`` (s), ``decay_rate``
    and ``objective`` ("decay" or "delay") only: for studies whose plant is
    not a ``delay-feedback`` model (e.g. ``antiskid-robust``)."""
    if not root.has("requirements"):
        return None
    t = root.table("requirements")
    objective = t.string("objective", default="decay", choices=("decay", "delay"))
    rng = _delay_range(t)
    sources = {"delay": t.string("delay_source")}
    alpha = None
    if t.has("decay_rate"):
        alpha, sources["decay"] = _entry(t, "decay_rate", "1/s")
    t.finish()
    return RequirementsSpec(objective, (float(rng[0]), float(rng[1])), alpha, None, None,
                            None, None, (), sources)


def _l2_matrices(spec, req, model, values, op):
    """B_w = df/dw and (C_z, D_z) = dz/d(x, u) at the operating point."""
    import sympy as sp

    from ...expr import parse_expression
    w = model.p[req.disturbance]
    at = {s: float(v) for s, v in zip(model.x + model.u, np.concatenate([op.x, op.u]))}
    Bw = np.array(model.substituted(model.f.diff(w), values).subs(at).evalf(),
                  dtype=float).reshape(-1, 1)
    names = dict(zip(spec.plant.state_names, model.x)) | dict(zip(spec.plant.input_names,
                                                                   model.u))
    z = sp.Matrix([parse_expression(e, names, path=spec.plant.path,
                                    key=f"requirements.outputs[{i}]")
                   for i, e in enumerate(req.outputs)])
    C = np.array(z.jacobian(sp.Matrix(model.x)).subs(at).evalf(), dtype=float)
    D = np.array(z.jacobian(sp.Matrix(model.u)).subs(at).evalf(), dtype=float)
    return Bw, C, D


def run_requirements(spec, req: RequirementsSpec, model, values, op, A, B, points=()):
    """Design the gain to ``req`` at (A, B) and ``points`` (vertex linearisations):
    :class:`workbench.requirements.RequirementResult`."""
    from ...requirements import Requirements, design_to_requirements
    kw = {}
    if req.disturbance is not None:
        Bw, C, D = _l2_matrices(spec, req, model, values, op)
        kw = dict(Bw=Bw, Cz=C, Dz=D)
    limit = box = None
    if req.input_limit is not None:
        limit = tuple(req.input_limit[k] for k in spec.plant.input_names)
        box = tuple(req.box.get(k, 0.0) for k in spec.plant.state_names)
    r = Requirements(req.delay, req.decay_rate, req.l2_gain, limit, box, req.objective,
                     req.rate)
    return design_to_requirements([(A, B)] + list(points), r, **kw)


def requirement_quantity_names(req: RequirementsSpec | None) -> set[str]:
    if req is None:
        return set()
    return {f"requirements.{r}.{f}" for r in ROWS for f in FIELDS}


def requirement_quantities(result) -> dict:
    """``requirements.<row>.{certified, exact, verdict}`` (None when the row
    is absent or a value undetermined)."""
    q = {}
    rows = {} if result is None else {r.name: r for r in result.rows}
    for name in ROWS:
        r = rows.get(name)
        for f in FIELDS:
            v = None if r is None else getattr(r, f)
            q[f"requirements.{name}.{f}"] = (None if isinstance(v, float) and not math.isfinite(v)
                                             else v)
    return q

