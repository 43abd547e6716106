"""Interval evaluation of sympy expressions, vectorised over boxes, with
outward rounding.

A sympy expression tree is compiled once (after common-subexpression
elimination) into nested closures; a call evaluates it on N boxes at once,
each box given by the arrays ``lo[:, i] <= x_i <= hi[:, i]``. Every result
interval *encloses* the expression's range on the box:

* ``+``, ``*``, ``1/x`` and ``sqrt`` are correctly rounded in IEEE 754, so
  one step of ``np.nextafter`` outwards after each operation is enough;
* ``exp`` and ``log`` are not correctly rounded: numpy documents an error
  below 1 ulp for its float64 ``exp`` / ``log``; the result is widened by
  two ulps outwards (``tanh``, ``atan``, ``sinh``, ``asinh``: increasing,
  ``sin``, ``cos``: their extrema added where the interval may hold one,
  widened by four ulps);
* a constant that is not exactly a float (a Rational, a Float of higher
  precision, ``pi``) is enclosed by the floats on either side of it;
* an operation outside its domain (a division by an interval holding 0, a
  log of a non-positive number) gives ``[-inf, inf]``, which no proof can use;
  NaN bounds are replaced by the infinite bound on their side;
* a ``Piecewise`` whose condition is undetermined on a box returns the hull
  of the branches that may apply, and the box is flagged as *ambiguous*
  (arguments that need smoothness, such as the Hessian bound of
  :mod:`workbench.roa.certify`, refuse ambiguous boxes).

References
----------
.. [Moore] R. E. Moore, R. B. Kearfott, M. J. Cloud, *Introduction to
   Interval Analysis*, SIAM 2009: natural interval extension (ch. 5),
   mean-value form (ch. 6).
"""
from __future__ import annotations

from collections import OrderedDict
from typing import Callable, NamedTuple, Sequence

import numpy as np
import sympy as sp

_INF = np.inf
#: Compiled stages of :class:`IntervalFunction`, least recently used dropped first.
_STAGE_CACHE: OrderedDict = OrderedDict()
_STAGE_CACHE_SIZE = 256


class Interval(NamedTuple):
    """Arrays of lower and upper bounds (same shape)."""

    lo: np.ndarray
    hi: np.ndarray


class UnsupportedExpression(TypeError):
    """The expression uses a function the interval evaluator does not know."""


def _down(x):
    return np.nextafter(x, -_INF)


def _up(x):
    return np.nextafter(x, _INF)


def _fix(lo, hi) -> Interval:
    """NaN bounds become the infinite bound on their side."""
    return Interval(np.where(np.isnan(lo), -_INF, lo), np.where(np.isnan(hi), _INF, hi))


def iadd(a: Interval, b: Interval) -> Interval:
    return _fix(_down(a.lo + b.lo), _up(a.hi + b.hi))


def imul(a: Interval, b: Interval) -> Interval:
    # The hull of the four end-point products. np.minimum / np.maximum
    # propagate a NaN product (0 * inf), which _fix turns into the infinite
    # bound on its side: the whole real line, as for any undefined product.
    with np.errstate(invalid="ignore", over="ignore"):
        p1, p2, p3, p4 = a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi
    lo = np.minimum(np.minimum(p1, p2), np.minimum(p3, p4))
    hi = np.maximum(np.maximum(p1, p2), np.maximum(p3, p4))
    return _fix(_down(lo), _up(hi))


def irecip(a: Interval) -> Interval:
    ok = (a.lo > 0) | (a.hi < 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        lo, hi = _down(1.0 / a.hi), _up(1.0 / a.lo)
    return _fix(np.where(ok, lo, -_INF), np.where(ok, hi, _INF))


def iabs(a: Interval) -> Interval:
    lo = np.where(a.lo >= 0, a.lo, np.where(a.hi <= 0, -a.hi, 0.0))
    return Interval(lo, np.maximum(np.abs(a.lo), np.abs(a.hi)))


def _ipow_nonneg(a: Interval, n: int) -> Interval:
    """a**n for n >= 1 on a >= 0 by repeated rounded multiplication."""
    out, base = None, a
    while n:
        if n & 1:
            out = base if out is None else imul(out, base)
        n >>= 1
        if n:
            base = imul(base, base)
    return Interval(np.maximum(out.lo, 0.0), out.hi)


def ipow_int(a: Interval, n: int) -> Interval:
    """a**n for an integer n (the even powers are >= 0, the odd ones monotone)."""
    if n == 0:
        return Interval(np.ones_like(a.lo), np.ones_like(a.hi))
    if n < 0:
        return irecip(ipow_int(a, -n))
    if n == 1:
        return a
    even = _ipow_nonneg(iabs(a), n)
    if n % 2 == 0:
        return even
    return imul(a, _ipow_nonneg(iabs(a), n - 1))


def iexp(a: Interval) -> Interval:
    with np.errstate(over="ignore"):
        lo, hi = np.exp(a.lo), np.exp(a.hi)
    return _fix(np.maximum(_down(_down(lo)), 0.0), _up(_up(hi)))


def _widen(x, k: int, direction):
    for _ in range(k):
        x = np.nextafter(x, direction)
    return x


def imonotone(fn, a: Interval, lo_bound: float = -_INF, hi_bound: float = _INF) -> Interval:
    """An increasing libm function (tanh, atan, sinh, asinh) on an interval,
    widened by 4 ulps each way (their libm error is below that) and clipped
    to the function's range."""
    with np.errstate(over="ignore", invalid="ignore"):
        lo, hi = _widen(fn(a.lo), 4, -_INF), _widen(fn(a.hi), 4, _INF)
    return _fix(np.maximum(lo, lo_bound), np.minimum(hi, hi_bound))


def _holds(a: Interval, c: float, period: float) -> np.ndarray:
    """Whether [a.lo, a.hi] may hold a point c + k period (k integer); errs
    towards True (then the caller widens to the extremum, which is sound)."""
    with np.errstate(invalid="ignore", over="ignore"):
        k = np.ceil((a.lo - c) / period - 1e-9)
        near = c + k * period <= a.hi + 1e-9 * (1.0 + np.abs(a.hi))
    return near | ~np.isfinite(a.lo) | ~np.isfinite(a.hi)


def isincos(a: Interval, phase: float) -> Interval:
    """sin (phase 0) or cos (phase pi/2: cos x = sin(x + pi/2)) on an interval:
    the end values widened by 4 ulps (libm's error is below 1 ulp), and +-1
    where the interval may hold a maximum / minimum (tested with a margin, so
    a near miss gives the wider, still enclosing, interval)."""
    fn = np.sin if phase == 0 else np.cos
    with np.errstate(invalid="ignore"):
        e1, e2 = fn(a.lo), fn(a.hi)
    lo = _widen(np.minimum(e1, e2), 4, -_INF)
    hi = _widen(np.maximum(e1, e2), 4, _INF)
    two_pi = 2.0 * np.pi
    top = _holds(a, np.pi / 2 - phase, two_pi)
    bottom = _holds(a, -np.pi / 2 - phase, two_pi)
    lo = np.where(bottom | np.isnan(lo), -1.0, np.maximum(lo, -1.0))
    hi = np.where(top | np.isnan(hi), 1.0, np.minimum(hi, 1.0))
    return Interval(lo, hi)


def istep(a: Interval, below: float, above: float, at: tuple[float, float]) -> Interval:
    """A step function: ``below`` for x < 0, ``above`` for x > 0, within
    ``at`` at 0 (sign: -1, 1, (0, 0); Heaviside: 0, 1, (0, 1); DiracDelta's
    support: 0, 0, (0, inf))."""
    lo = np.where(a.lo > 0, above, np.where(a.hi < 0, below, min(below, above, at[0])))
    hi = np.where(a.lo > 0, above, np.where(a.hi < 0, below, max(below, above, at[1])))
    return Interval(lo.astype(float), hi.astype(float))


def ilog(a: Interval) -> Interval:
    with np.errstate(divide="ignore", invalid="ignore"):
        lo = np.where(a.lo > 0, _down(_down(np.log(np.maximum(a.lo, 0.0)))), -_INF)
        hi = np.where(a.hi > 0, _up(_up(np.log(np.maximum(a.hi, 1e-320)))), _INF)
    bad = ~(a.hi > 0)
    return _fix(lo, np.where(bad, _INF, hi))


def isqrt(a: Interval) -> Interval:
    ok = a.lo >= 0
    lo = np.where(ok, _down(np.sqrt(np.maximum(a.lo, 0.0))), -_INF)
    hi = np.where(ok, _up(np.sqrt(np.maximum(a.hi, 0.0))), _INF)
    return _fix(np.maximum(lo, np.where(ok, 0.0, -_INF)), hi)


def constant(x: sp.Expr) -> tuple[float, float]:
    """The floats enclosing the number ``x`` (equal when ``x`` is a float)."""
    v = float(x)
    if not np.isfinite(v):
        raise UnsupportedExpression(f"constant {x} is not a finite real number")
    exact = isinstance(x, (sp.Integer, sp.Rational, sp.Float)) and sp.Rational(v) == sp.Rational(x)
    return (v, v) if exact else (float(_down(v)), float(_up(v)))


_REL = (sp.GreaterThan, sp.StrictGreaterThan, sp.LessThan, sp.StrictLessThan)


class IntervalFunction:
    """Interval enclosure of sympy expressions over a box.

    Parameters
    ----------
    exprs : sequence of sympy.Expr
        Expressions in ``symbols`` only (every other symbol must have been
        substituted by a number).
    symbols : sequence of sympy.Symbol
        Order of the box coordinates.
    stages : sequence of sequences of (Symbol, Expr), optional
        Intermediate quantities, defined in order (each stage may use the
        box coordinates and earlier stages); the expressions may use them.
        An enclosure of a stage's symbol is the enclosure of its expression.

    Raises
    ------
    UnsupportedExpression
        For a function without an interval rule (supported: +, *, integer,
        rational and real powers, exp, log, sin, cos, tanh, atan, sinh, asinh, Abs, sign,
        Heaviside, DiracDelta, Max, Min, Piecewise with
        relational conditions, and/or).
    """

    def __init__(self, exprs: Sequence[sp.Expr], symbols: Sequence[sp.Symbol],
                 stages: Sequence[Sequence[tuple]] = ()):
        self.symbols = tuple(symbols)
        known = set(self.symbols)
        self._steps = []
        for stage in (*stages, [(None, e) for e in exprs]):
            stage = list(stage)
            free = set().union(set(), *(sp.sympify(e).free_symbols for _, e in stage)) - known
            if free:
                raise UnsupportedExpression(
                    f"expressions depend on {sorted(map(str, free))}, not only on "
                    f"{[str(s) for s in self.symbols]}")
            steps, outs = self._compile_stage(stage, len(self._steps))
            self._steps += steps
            if stage and stage[0][0] is None:
                self._outs = [fn for _, fn in outs]
            else:
                self._steps += outs
                known |= {s for s, _ in stage}

    def __call__(self, lo: np.ndarray, hi: np.ndarray) -> tuple[list[Interval], np.ndarray]:
        """Enclosures on the N boxes ``lo <= x <= hi`` ((N, n) arrays).

        Returns
        -------
        (list of Interval, ambiguous)
            One enclosure per expression, and a (N,) bool array: true where a
            Piecewise condition was undetermined on the box.
        """
        lo, hi = np.atleast_2d(np.asarray(lo, float)), np.atleast_2d(np.asarray(hi, float))
        env = {s: Interval(lo[:, i].copy(), hi[:, i].copy()) for i, s in enumerate(self.symbols)}
        state = {"amb": np.zeros(lo.shape[0], bool), "n": lo.shape[0]}
        for s, fn in self._steps:
            env[s] = fn(env, state)
        return [fn(env, state) for fn in self._outs], state["amb"]

    # --- compilation -----------------------------------------------------------------------
    def _compile_stage(self, stage: list, at: int) -> tuple[list, list]:
        """(cse steps, outputs) of one stage, each a list of (Symbol, closure).

        The closures depend on the stage's expressions only (no instance
        state), so a stage met again, such as the model stage of a basin
        problem tried with several Lyapunov matrices, is compiled once per
        process (:data:`_STAGE_CACHE`, keyed by the expressions and the
        position that names the cse symbols)."""
        key = (at, tuple(stage))
        hit = _STAGE_CACHE.get(key)
        if hit is not None:
            _STAGE_CACHE.move_to_end(key)
            return hit
        repl, reduced = sp.cse([e for _, e in stage], optimizations=None,
                               symbols=sp.numbered_symbols(f"_cse{at}_"))
        out = ([(s, self._compile(e)) for s, e in repl],
               [(s, self._compile(e)) for (s, _), e in zip(stage, reduced)])
        _STAGE_CACHE[key] = out
        if len(_STAGE_CACHE) > _STAGE_CACHE_SIZE:
            _STAGE_CACHE.popitem(last=False)
        return out

    def _compile(self, e) -> Callable:
        if isinstance(e, sp.Symbol):
            return lambda env, st, s=e: env[s]
        if isinstance(e, (sp.logic.boolalg.Boolean, sp.core.relational.Relational)):
            cond = self._cond(e)             # a condition pulled out by cse
            return lambda env, st: ("cond",) + tuple(cond(env, st))
        if e.is_Number or isinstance(e, sp.NumberSymbol):
            clo, chi = constant(e)
            return lambda env, st: Interval(np.full(st["n"], clo), np.full(st["n"], chi))
        args = [self._compile(a) for a in e.args] if not isinstance(e, sp.Piecewise) else None
        if isinstance(e, sp.Add):
            return self._fold(args, iadd)
        if isinstance(e, sp.Mul):
            return self._fold(args, imul)
        if isinstance(e, sp.Pow):
            return self._pow(e, args[0])
        if isinstance(e, sp.exp):
            return lambda env, st, f=args[0]: iexp(f(env, st))
        if isinstance(e, sp.log) and len(e.args) == 1:
            return lambda env, st, f=args[0]: ilog(f(env, st))
        if isinstance(e, sp.tanh):
            return lambda env, st, f=args[0]: imonotone(np.tanh, f(env, st), -1.0, 1.0)
        if isinstance(e, sp.atan):
            return lambda env, st, f=args[0]: imonotone(np.arctan, f(env, st), -2.0, 2.0)
        if isinstance(e, sp.sinh):
            return lambda env, st, f=args[0]: imonotone(np.sinh, f(env, st))
        if isinstance(e, sp.asinh):
            return lambda env, st, f=args[0]: imonotone(np.arcsinh, f(env, st))
        if isinstance(e, (sp.sin, sp.cos)):
            ph = 0.0 if isinstance(e, sp.sin) else np.pi / 2
            return lambda env, st, f=args[0], ph=ph: isincos(f(env, st), ph)
        if isinstance(e, sp.sign):
            return lambda env, st, f=args[0]: istep(f(env, st), -1.0, 1.0, (0.0, 0.0))
        if isinstance(e, sp.Heaviside):           # Heaviside(x, H0): H0 at x = 0
            h0 = constant(e.args[1]) if len(e.args) > 1 else (0.0, 1.0)
            at = (min(0.0, h0[0]), max(1.0, h0[1]))
            return lambda env, st, f=args[0], at=at: istep(f(env, st), 0.0, 1.0, at)
        if isinstance(e, sp.DiracDelta) and len(e.args) == 1:
            return lambda env, st, f=args[0]: istep(f(env, st), 0.0, 0.0, (0.0, _INF))
        if isinstance(e, sp.Abs):
            return lambda env, st, f=args[0]: iabs(f(env, st))
        if isinstance(e, (sp.Max, sp.Min)):
            pick = np.maximum if isinstance(e, sp.Max) else np.minimum

            def mm(env, st, fs=args, pick=pick):
                vals = [f(env, st) for f in fs]
                lo, hi = vals[0]
                for v in vals[1:]:
                    lo, hi = pick(lo, v.lo), pick(hi, v.hi)
                return Interval(lo, hi)
            return mm
        if isinstance(e, sp.Piecewise):
            return self._piecewise(e)
        raise UnsupportedExpression(f"no interval rule for {type(e).__name__} in {e}")

    @staticmethod
    def _fold(fs, op):
        def run(env, st):
            acc = fs[0](env, st)
            for f in fs[1:]:
                acc = op(acc, f(env, st))
            return acc
        return run

    def _pow(self, e, base):
        ex = e.exp
        if ex.is_Integer:
            n = int(ex)
            return lambda env, st: ipow_int(base(env, st), n)
        if ex == sp.Rational(1, 2):
            return lambda env, st: isqrt(base(env, st))
        if ex == sp.Rational(-1, 2):
            return lambda env, st: irecip(isqrt(base(env, st)))
        fexp = self._compile(ex)   # x**y = exp(y log x), x > 0
        return lambda env, st: iexp(imul(fexp(env, st), ilog(base(env, st))))

    def _cond(self, c):
        """Compile a condition to (env, st) -> (surely true, surely false)."""
        if isinstance(c, sp.Symbol):          # a cse replacement of a condition
            return lambda env, st: env[c][1:]
        if c is sp.true:
            return lambda env, st: (np.ones(st["n"], bool), np.zeros(st["n"], bool))
        if c is sp.false:
            return lambda env, st: (np.zeros(st["n"], bool), np.ones(st["n"], bool))
        if isinstance(c, (sp.And, sp.Or)):
            parts = [self._cond(a) for a in c.args]
            conj = isinstance(c, sp.And)

            def logic(env, st):
                tf = [p(env, st) for p in parts]
                ts, fs = [t for t, _ in tf], [f for _, f in tf]
                if conj:
                    return np.logical_and.reduce(ts), np.logical_or.reduce(fs)
                return np.logical_or.reduce(ts), np.logical_and.reduce(fs)
            return logic
        if isinstance(c, _REL):
            d = self._compile(c.lhs - c.rhs)
            strict = isinstance(c, (sp.StrictGreaterThan, sp.StrictLessThan))
            greater = isinstance(c, (sp.GreaterThan, sp.StrictGreaterThan))

            def rel(env, st):
                lo, hi = d(env, st)
                if not greater:
                    lo, hi = -hi, -lo
                if strict:
                    return lo > 0, hi <= 0
                return lo >= 0, hi < 0
            return rel
        raise UnsupportedExpression(f"no interval rule for the condition {c}")

    def _piecewise(self, e):
        branches = [(self._compile(x), self._cond(c)) for x, c in e.args]

        def run(env, st):
            n = st["n"]
            lo, hi = np.full(n, _INF), np.full(n, -_INF)
            alive = np.ones(n, bool)          # no earlier condition is surely true
            count = np.zeros(n, int)          # branches that may apply
            for f, cond in branches:
                t, fl = cond(env, st)
                possible = alive & ~fl
                if possible.any():
                    v = f(env, st)
                    lo = np.where(possible, np.minimum(lo, v.lo), lo)
                    hi = np.where(possible, np.maximum(hi, v.hi), hi)
                    count += possible
                alive &= ~t
            st["amb"] = st["amb"] | (count > 1) | alive
            return _fix(np.where(alive, -_INF, lo), np.where(alive, _INF, hi))
        return run
