"""Follower laws of a ``platoon`` design: expressions of the design file, read
with the project's expression reader, unit-checked, and evaluated in the
order written.

A follower law is stateless (a function of what the follower sees now), so a
design writes it as an expression (``[[laws]]``) instead of naming code:

``e`` (m)
    spacing error as the follower sees it, gap - desired gap;
``de`` (m/s)
    its rate (predecessor's speed - own speed);
``a_pred`` (m/s^2)
    the predecessor's acceleration of the previous step, as communicated;
``u1`` (N)
    the nominal resistance and gradient force the law may cancel;
``m`` (kg)
    the nominal mass; ``G_w``, ``G_d`` (N): the ``[uncertainty]`` bounds;

plus the design's ``[constants]`` and the law's own ``definitions`` (in
order). The law is the commanded force (N); ``surface`` names a definition
recorded as the law's sliding variable (a sliding-mode law's s).

Text is parsed by :func:`workbench.expr.check_expression` (Python's
:mod:`ast` against a whitelist: never ``eval``) and unit-checked with pint
(:func:`workbench.kinds.delay_feedback.units.check_expression_units`). The
checked tree is then evaluated by :func:`compile_expression`, a small
interpreter over numpy that performs the operations in the order written
(left to right, as Python would), folding the parts without a signal once.
It does not go through sympy's ``lambdify``, which reorders sums and
products: written in the order of a hand-coded law, an expression gives
the same bits (``tests/test_platoon_kind.py`` compares paper 001's eq 13).
"""
from __future__ import annotations

import ast
from dataclasses import dataclass
from typing import Callable

import numpy as np

__all__ = ["Law", "SIGNALS", "compile_expression", "compile_law", "read_constants",
           "read_laws"]

#: Names a law sees besides the constants: name -> unit.
SIGNALS = {"e": "m", "de": "m/s", "a_pred": "m/s^2", "u1": "N", "m": "kg", "G_w": "N",
           "G_d": "N"}
#: The unit of a law (a force command).
LAW_UNIT = "N"


@dataclass(frozen=True)
class Law:
    """One ``[[laws]]`` entry: name, label, force expression, definitions (in
    order), and the definition recorded as the sliding variable (or None)."""

    name: str
    label: str
    law: str
    definitions: tuple[tuple[str, str], ...] = ()
    surface: str | None = None


def read_constants(root, taken) -> dict:
    """``[constants]``: name -> :class:`~workbench.reader.Quantity` (unit parsed by pint)."""
    from ...reader import Quantity
    from ..delay_feedback import NAME_PATTERN
    from ..delay_feedback.units import parse_unit
    out = {}
    if not root.has("constants"):
        return out
    t = root.table("constants")
    for k in list(t.data):
        if k in taken or not NAME_PATTERN.match(k) or not isinstance(t.data[k], dict):
            raise t.fail(k, t.data[k], "a new name with { value, unit, source } (not "
                         + ", ".join(sorted(taken)) + ")")
        sub = t.table(k)
        unit = sub.string("unit")
        parse_unit(unit, root.path, t.key(k) + ".unit")
        raw = sub.raw("value")
        value = sub.number("value", lo=-1e15, hi=1e15)
        # a whole number stays an int (an odd root's exponent, as the hand-written laws)
        out[k] = Quantity(raw if isinstance(raw, int) else value, unit, sub.string("source"))
        sub.finish()
    t.finish()
    return out


def read_laws(root, constants: dict) -> tuple[Law, ...]:
    """``[[laws]]``: checked against the names a law sees, then unit-checked."""
    from ...expr import check_expression
    from ..delay_feedback import NAME_PATTERN
    tables = root.tables("laws")
    if not tables:
        raise root.fail("laws", [], "at least one [[laws]] table")
    base = set(SIGNALS) | set(constants)
    out, seen = [], set()
    for t in tables:
        name = t.string("name")
        if not NAME_PATTERN.match(name) or name in seen:
            raise t.fail("name", name, "a new law name of letters, digits and _")
        seen.add(name)
        label = t.string("label", default=name)
        known, defs = set(base), []
        dt = t.table("definitions", default=None)
        for k in list(dt.data):
            if k in known or not NAME_PATTERN.match(k):
                raise dt.fail(k, dt.data[k], "a new name (not a signal, constant or earlier "
                              "definition)")
            text = dt.raw(k)
            check_expression(text, known, path=root.path, key=dt.key(k))
            defs.append((k, text))
            known.add(k)
        dt.finish()
        law = t.raw("law")
        check_expression(law, known, path=root.path, key=t.key("law"))
        surface = t.string("surface", default=None)
        if surface is not None and surface not in dict(defs):
            raise t.fail("surface", surface, "one of the law's definitions: "
                         + (", ".join(k for k, _ in defs) or "(none)"))
        t.finish()
        out.append(Law(name, label, law, tuple(defs), surface))
    _check_units(root.path, constants, out)
    return tuple(out)


def _check_units(path: str, constants: dict, laws) -> None:
    """Every law in N, every definition of consistent units (pint)."""
    import sympy as sp
    from types import SimpleNamespace as NS

    from ...errors import DesignError
    from ...expr import parse_expression
    from ..delay_feedback.units import check_expression_units
    units = dict(SIGNALS) | {k: q.unit for k, q in constants.items()} | {"force": LAW_UNIT}
    plant = NS(path=path, states=(), inputs=(),
               parameters={k: NS(unit=u) for k, u in units.items()})
    # dimensionless constants enter as their values, so that a power such as
    # abs(de)**(b/a) has a numeric exponent pint can raise a unit to
    plain = {k: sp.Rational(q.value) if isinstance(q.value, int) else sp.Float(q.value)
             for k, q in constants.items() if q.unit == "1"}
    for i, c in enumerate(laws):
        syms = {k: sp.Symbol(k, real=True) for k in units} | plain
        items = []
        for k, text in c.definitions:
            key = f"laws[{i}].definitions.{k}"
            syms[k] = parse_expression(text, syms, path=path, key=key)
            items.append((key, text, syms[k], None))
        key = f"laws[{i}].law"
        items.append((key, c.law, parse_expression(c.law, syms, path=path, key=key), "force"))
        for key, text, e, _ in items:
            if e.has(sp.I, sp.zoo, sp.oo, -sp.oo, sp.nan):
                raise DesignError(path, key, text, "a real, finite expression (this one has "
                                  "a complex, infinite or undefined constant)")
        check_expression_units(plant, items)


_BIN = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
        ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b,
        ast.Pow: lambda a, b: a ** b}
_CMP = {ast.Lt: np.less, ast.LtE: np.less_equal, ast.Gt: np.greater, ast.GtE: np.greater_equal}
_FUN = {"exp": np.exp, "log": np.log, "sqrt": np.sqrt, "sin": np.sin, "cos": np.cos,
        "tanh": np.tanh, "atan": np.arctan, "abs": np.abs, "sign": np.sign}


class _Const:
    """A folded value (a Python number, as the hand-written code computes it)."""

    def __init__(self, value):
        self.value = value


def _fold(node, env: dict):
    """A checked tree -> a :class:`_Const` or a function of the signals."""
    if isinstance(node, ast.Constant):
        return _Const(node.value)
    if isinstance(node, ast.Name):
        v = env[node.id]
        return v if callable(v) else _Const(v)
    if isinstance(node, ast.UnaryOp):
        x = _fold(node.operand, env)
        if isinstance(node.op, ast.UAdd):
            return x
        return _Const(-x.value) if isinstance(x, _Const) else (lambda s, f=x: -f(s))
    if isinstance(node, (ast.BinOp, ast.Compare)):
        if isinstance(node, ast.BinOp):
            op, left, right = _BIN[type(node.op)], node.left, node.right
        else:
            op, left, right = _CMP[type(node.ops[0])], node.left, node.comparators[0]
        a, b = _fold(left, env), _fold(right, env)
        if isinstance(a, _Const) and isinstance(b, _Const):
            return _Const(op(a.value, b.value))
        fa = (lambda s, v=a.value: v) if isinstance(a, _Const) else a
        fb = (lambda s, v=b.value: v) if isinstance(b, _Const) else b
        return lambda s: op(fa(s), fb(s))
    args = [_fold(a, env) for a in node.args]
    fs = [(lambda s, v=a.value: v) if isinstance(a, _Const) else a for a in args]
    name = node.func.id
    if name == "where":
        return lambda s: np.where(fs[0](s), fs[1](s), fs[2](s))
    if name == "piecewise":
        conds, vals = fs[0:-1:2], fs[1:-1:2]
        return lambda s: np.select([c(s) for c in conds], [v(s) for v in vals], fs[-1](s))
    if name in ("min", "max"):
        red = np.minimum if name == "min" else np.maximum
        def minmax(s):
            out = fs[0](s)
            for f in fs[1:]:
                out = red(out, f(s))
            return out
        return minmax
    fn = _FUN[name]
    if all(isinstance(a, _Const) for a in args):
        x = fn(args[0].value)
        return _Const(float(x) if np.ndim(x) == 0 else x)
    return lambda s: fn(fs[0](s))


def compile_expression(text: str, names: dict, *, path: str, key: str) -> Callable:
    """``f(signals) -> value``: the expression ``text`` over ``names``
    (name -> a number, or a function of the signals dict), checked by
    :func:`workbench.expr.check_expression` and evaluated in the order written."""
    from ...expr import check_expression
    tree = check_expression(text, names, path=path, key=key)
    f = _fold(tree.body, names)
    return (lambda s, v=f.value: v) if isinstance(f, _Const) else f


def compile_law(law: Law, constants: dict, extra: dict, *, path: str, index: int):
    """``law(e, de, u1, a_pred) -> (u, s)`` of :func:`workbench.sim.platoon.simulate_platoon`:
    the force (N) and the sliding variable (zeros without ``surface``). ``extra``:
    the values of ``m``, ``G_w``, ``G_d``."""
    env = {k: q.value for k, q in constants.items()} | dict(extra)
    for k in ("e", "de", "u1", "a_pred"):
        env[k] = (lambda s, k=k: s[k])
    steps = []
    for k, text in law.definitions:
        f = compile_expression(text, env, path=path, key=f"laws[{index}].definitions.{k}")
        steps.append((k, f))
        env[k] = (lambda s, k=k: s[k])
    force = compile_expression(law.law, env, path=path, key=f"laws[{index}].law")
    surface = law.surface

    def run(e, de, u1, a_pred):
        sig = {"e": e, "de": de, "u1": u1, "a_pred": a_pred}
        for k, f in steps:
            sig[k] = f(sig)
        u = force(sig)
        s = sig[surface] if surface is not None else np.zeros_like(e)
        return u, s
    return run

