"""Units of a ``delay-feedback`` design, checked with pint in its own equations.

Every unit the design declares (states, inputs, parameters) is parsed by
pint (its own tokenizer; nothing is evaluated as Python). The numbers of a
design are used as written, so the check is on units *and* their scale:
each symbol stands for one of its declared unit, and

* the terms of a sum, the arguments of ``min``/``max`` and the branches of
  ``where``/``piecewise`` must have the same unit (``km/h + m/s`` mixes
  scales: 1 km/h = 0.2778 m/s, and is refused); a bare number there takes
  the unit of the others (``min(u, 10)``: 10 in the unit of u);
* the arguments of ``exp log sin cos tanh atan`` and a non-numeric exponent
  must be dimensionless (of scale 1);
* each equation's right-hand side must have the unit of its state per
  second (scale 1).

A parameter whose dimension is a time or a mass is physical and must be
positive and within :data:`SANE` (in SI), at the design's value and at
every vertex. A unit pint does not know, or a mismatch, is a
:class:`~workbench.errors.DesignError` naming the key and both units.

References
----------
pint: https://pint.readthedocs.io (unit registry, dimensionality).
"""
from __future__ import annotations

import math
import re
from functools import lru_cache

from ...errors import DesignError

__all__ = ["SANE", "check_expression_units", "check_units", "parse_unit", "physical_ranges"]

#: Magnitudes (SI) a time or mass parameter may take.
SANE = {"[time]": (1e-9, 1e9), "[mass]": (1e-9, 1e12)}
_UNIT_TEXT = re.compile(r"[A-Za-z0-9 ^*/().\-_]{1,80}")
_RTOL = 1e-9


@lru_cache(maxsize=1)
def _registry():
    import pint
    return pint.UnitRegistry(autoconvert_offset_to_baseunit=False)


def parse_unit(text: str, path: str, key: str):
    """The pint quantity ``1 text`` (an offset unit such as degC is refused)."""
    import pint
    ureg = _registry()
    if not isinstance(text, str) or not _UNIT_TEXT.fullmatch(text):
        raise DesignError(path, key, text, "a unit of letters, digits, spaces, ^ * / ( ) "
                          "(at most 80 characters), e.g. \"m/s^2\" or \"1\"")
    try:
        q = ureg.parse_expression(text)
        q = q if isinstance(q, ureg.Quantity) else ureg.Quantity(q, "")
        if q.magnitude != 1:
            raise ValueError("a number in the unit")
        q.to_base_units()
        q * ureg.Quantity(1, "s")       # an offset unit (degC) cannot be multiplied
    except (pint.errors.PintError, ValueError, TypeError, AttributeError, SyntaxError,
            ZeroDivisionError, OverflowError, RecursionError) as exc:
        raise DesignError(path, key, text, f"a unit pint knows ({type(exc).__name__}: "
                          f"{str(exc)[:80]})") from None
    return q


def _show(q) -> str:
    u = f"{q.units:~}" or "1"
    base = q.to_base_units()
    return u if math.isclose(base.magnitude, 1.0) and f"{base.units:~}" == u else \
        f"{u} (= {base.magnitude:.6g} {base.units:~})"


def physical_ranges(spec) -> None:
    """Time and mass parameters positive and in :data:`SANE`, at the design's
    values and at every vertex (``spec``: a DelayFeedbackSpec)."""
    plant = spec.plant
    cases = [("parameters", {k: q.value for k, q in plant.parameters.items()}, ".value")]
    cases += [(f"vertices[{v.name}]", v.values, "") for v in spec.vertices]
    for where, values, suffix in cases:
        for name, value in values.items():
            unit = plant.parameters[name].unit
            q = parse_unit(unit, plant.path, f"parameters.{name}.unit")
            for dim, (lo, hi) in SANE.items():
                if q.dimensionality == _registry().get_dimensionality(dim):
                    si = value * q.to_base_units().magnitude
                    if not lo <= si <= hi:
                        base = f"{q.to_base_units().units:~}"
                        raise DesignError(plant.path, f"{where}.{name}{suffix}", value,
                                          f"a positive {dim.strip('[]')} in [{lo:g}, {hi:g}] "
                                          + base + ("" if unit == base else f" (given in {unit})"))


def _snap(q):
    """``q`` with its unit exponents rounded to 12 decimals (whole when within
    1e-9): fractional powers such as (m/s)**1.4 / (m**0.4/s**1.4) leave m**0.9999..."""
    from pint.util import UnitsContainer
    exps = {}
    for name, x in q._units.items():
        x = float(round(x)) if abs(x - round(x)) < 1e-9 else round(x, 12)
        if x:
            exps[name] = int(x) if x == int(x) else x
    return type(q)(q.magnitude, UnitsContainer(exps))


class _Walker:
    def __init__(self, path: str, units: dict, shown: dict):
        self.path, self.units, self.shown = path, units, shown

    def same(self, qs, key, what):
        qs = [q for q in qs if q is not None]     # bare numbers take the others' unit
        if not qs:
            return None
        ref = qs[0]
        for q in qs[1:]:
            if q.dimensionality != ref.dimensionality or not math.isclose(
                    q.to(ref.units).magnitude, 1.0, rel_tol=_RTOL):
                raise DesignError(self.path, key, self.shown[key],
                                  f"{what} of one unit; found {_show(ref)} and {_show(q)}")
        return ref

    def dimensionless(self, q, key, what):
        if q is None:
            return
        if not q.dimensionless or not math.isclose(q.to("").magnitude, 1.0, rel_tol=_RTOL):
            raise DesignError(self.path, key, self.shown[key],
                              f"a dimensionless {what}; found {_show(q)}")

    def unit(self, e, key):
        """The unit of ``e`` as a pint quantity of magnitude 1 (None: a bare number)."""
        import sympy as sp
        one = _registry().Quantity(1, "")
        if e.is_Symbol:
            return self.units[e.name]
        if not e.free_symbols:
            return None
        if e.is_Add:
            return self.same([self.unit(a, key) for a in e.args], key, "terms")
        if e.is_Mul:
            out = one
            for a in e.args:
                q = self.unit(a, key)
                out = out if q is None else out * q
            return _snap(out)
        if e.is_Pow:
            base, ex = e.args
            if ex.is_Number:
                qb = self.unit(base, key)
                return qb if qb is None or qb.dimensionless and math.isclose(
                    qb.to("").magnitude, 1.0) else _snap(qb ** float(ex))
            self.dimensionless(self.unit(base, key), key, "base of a power with a "
                               "non-numeric exponent")
            self.dimensionless(self.unit(ex, key), key, "exponent")
            return one
        if isinstance(e, (sp.Abs, sp.sign)):
            q = self.unit(e.args[0], key)
            return q if isinstance(e, sp.Abs) else one
        if isinstance(e, (sp.Min, sp.Max)):
            return self.same([self.unit(a, key) for a in e.args], key, "arguments of min/max")
        if isinstance(e, sp.Piecewise):
            for _, cond in e.args:
                if cond not in (sp.true, sp.false):
                    self.same([self.unit(a, key) for a in cond.args], key, "sides of a "
                              "comparison")
            return self.same([self.unit(v, key) for v, _ in e.args], key, "branches")
        if isinstance(e, sp.Function):
            for a in e.args:
                self.dimensionless(self.unit(a, key), key,
                                   f"argument of {type(e).__name__.lower()}")
            return one
        raise DesignError(self.path, key, self.shown[key], f"an expression whose unit can be "
                          f"derived (found {type(e).__name__})")


def _declared(spec) -> dict:
    """name -> pint quantity of every state, input and parameter."""
    units = {}
    for table, items in (("states", spec.states), ("inputs", spec.inputs)):
        for v in items:
            units[v.name] = parse_unit(v.unit, spec.path, f"{table}.{v.name}.unit")
    for name, q in spec.parameters.items():
        units[name] = parse_unit(q.unit, spec.path, f"parameters.{name}.unit")
    return units


def check_expression_units(spec, items) -> None:
    """Units of further expressions written over a plant's symbols (the laws
    and guards of ``switched-run``): ``items`` are (key, text, sympy
    expression, unit name or None); each must be consistent, and have the
    unit of the named state or input when one is given."""
    units = _declared(spec)
    w = _Walker(spec.path, units, {key: text for key, text, _, _ in items})
    for key, text, e, want in items:
        got = w.unit(e, key)
        if want is None or got is None:
            continue
        ref = units[want]
        if got.dimensionality != ref.dimensionality or not math.isclose(
                got.to(ref.units).magnitude, 1.0, rel_tol=_RTOL):
            raise DesignError(spec.path, key, text, f"an expression in the unit of {want}, "
                              f"{_show(ref)}; found {_show(got)}")


def check_units(model) -> None:
    """Parse every declared unit; check the definitions and equations of the
    :class:`~workbench.kinds.delay_feedback.model.PlantModel` ``model``."""
    spec = model.spec
    units, shown = _declared(spec), {}
    shown.update({f"definitions.{n}": t for n, t in spec.definitions})
    shown.update({f"equations.{s}": t for s, t in zip(spec.state_names, spec.equations)})
    import pint
    try:
        _check(spec, model, units, shown)
    except pint.errors.PintError as exc:    # a safety net: the walk names its key itself
        raise DesignError(spec.path, "<units>", "<pint>", f"units pint can combine "
                          f"({type(exc).__name__}: {str(exc)[:120]})") from None


def _check(spec, model, units, shown) -> None:
    w = _Walker(spec.path, units, shown)
    for name, _ in spec.definitions:
        w.unit(model.definitions[name], f"definitions.{name}")
    per_s = _registry().Quantity(1, "1/s")
    for i, s in enumerate(spec.states):
        key = f"equations.{s.name}"
        got = w.unit(model.f[i], key)
        want = units[s.name] * per_s
        if got is None:          # a constant right-hand side takes the state's unit per second
            continue
        if got.dimensionality != want.dimensionality or not math.isclose(
                got.to(want.units).magnitude, 1.0, rel_tol=_RTOL):
            raise DesignError(spec.path, key, shown[key], f"a right-hand side in the unit of "
                              f"{s.name} per second, {_show(want)}; found {_show(got)}")
