"""Seeded falsification search: the second, independent check of every claim.

Samples the symbols of a claim's residual in a box, keeps the points where
the hypotheses hold, evaluates the residual numerically (numpy, lambdify) and
re-checks the worst point with 30-digit arithmetic at rounded values before
it is reported as a counterexample.
"""
from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
import sympy as sp

#: Seed of the falsification search (fixed: same claims, same counterexamples).
SEED = 20260
N_SAMPLES = 1000


class _Hyp(NamedTuple):
    symbol: sp.Symbol
    op: str
    bound: sp.Expr


def elements(x) -> list:
    """Entries of a Matrix, or ``[x]``."""
    return list(x) if isinstance(x, sp.MatrixBase) else [x]


def apply_given(expr, given):
    """Substitute the equalities ``given`` ((symbol, expression), in order)."""
    for s, e in given:
        expr = expr.subs(s, e)
    return expr


def _box(claim, symbols) -> dict:
    box = {s: (lo, hi) for s, lo, hi in claim.sample}
    out = {}
    for s in symbols:
        if s in box:
            out[s] = box[s]
        elif s.is_positive or s.is_nonnegative:
            out[s] = (0.1, 3.0)
        else:
            out[s] = (-3.0, 3.0)
    return out


_OPS = {">=": lambda a, b: a >= b, ">": lambda a, b: a > b,
        "<=": lambda a, b: a <= b, "<": lambda a, b: a < b}


def _violation(v, kind: str):
    """How much a residual value breaks the claim (0 where it holds); values
    that are not real (outside the expression's domain) count as 0."""
    v = np.asarray(v, complex)
    real = np.isfinite(v) & (np.abs(v.imag) <= 1e-12 * (1 + np.abs(v)))
    amount = np.abs(v.real) if kind == "zero" else np.maximum(-v.real, 0.0)
    amount = np.where(real, amount, 0.0)
    return np.where(amount > 1e-9 * (1 + np.abs(v)), amount, 0.0)


def _holds(h, vals: dict, prec: int) -> bool:
    lhs, rhs = sp.N(h.symbol.subs(vals), prec), sp.N(h.bound.subs(vals), prec)
    return bool(_OPS[h.op](float(lhs), float(rhs)))


def _round(x: float) -> float:
    return float(f"{x:.4g}")


def falsify(claim, residual, *, kind: Literal["zero", "nonneg"],
            n: int = N_SAMPLES) -> tuple[tuple | None, float | None, int]:
    """Seeded search for a point where ``residual`` is nonzero / negative.

    ``residual`` is evaluated after ``claim.given``; the hypotheses filter the
    samples. Returns (counterexample or None, violation, points used).
    """
    # DiracDelta (from d/dx sign(x)) vanishes off a null set: zero for sampling
    residual = [apply_given(sp.sympify(r), claim.given).replace(
        sp.DiracDelta, lambda *a: sp.Integer(0)) for r in elements(residual)]
    hyps = [_Hyp(h.symbol, h.op, apply_given(h.bound, claim.given)) for h in claim.hypotheses]
    free = set().union(*(r.free_symbols for r in residual), *(h.bound.free_symbols | {h.symbol}
                                                               for h in hyps))
    symbols = sorted(free, key=lambda s: s.name)
    if not symbols:  # constants: the claim fails (or holds) for every value
        for r in residual:
            viol = float(_violation(complex(sp.N(r, 30)), kind))
            if viol:
                return (), viol, 1
        return None, None, 0
    box = _box(claim, symbols)
    rng = np.random.default_rng(np.random.SeedSequence([SEED, sum(map(ord, claim.id))]))
    X = {s: rng.uniform(*box[s], n) for s in symbols}
    keep = np.ones(n, bool)
    for h in hyps:
        f = sp.lambdify(symbols, sp.Add(h.symbol, -h.bound), "numpy")
        d = np.broadcast_to(np.asarray(f(*[X[s] for s in symbols]), float), (n,))
        keep &= _OPS[h.op](d, 0)
    used = int(keep.sum())
    if not used:
        return None, None, 0
    worst, worst_i, worst_r = 0.0, None, None
    for r in residual:
        f = sp.lambdify(symbols, r, "numpy")
        with np.errstate(all="ignore"):
            val = np.broadcast_to(np.asarray(f(*[X[s] for s in symbols]), complex), (n,))
        bad = np.where(keep, _violation(val, kind), 0.0)
        i = int(np.argmax(bad))
        if bad[i] > worst:
            worst, worst_i, worst_r = bad[i], i, r
    if worst_i is None:
        return None, None, used
    point = {s: float(X[s][worst_i]) for s in symbols}
    for candidate in ({s: _round(v) for s, v in point.items()}, point):
        vals = {s: sp.Float(v, 30) for s, v in candidate.items()}
        if not all(_holds(h, vals, 30) for h in hyps):
            continue
        viol = float(_violation(complex(sp.N(worst_r.subs(vals), 30)), kind))
        if viol:
            shown = worst_r.free_symbols.union(*(h.bound.free_symbols | {h.symbol}
                                                 for h in hyps))
            cex = tuple((sp.latex(s), candidate[s]) for s in symbols if s in shown)
            derived = tuple((sp.latex(s), float(sp.N(apply_given(s, claim.given).subs(vals), 15)))
                            for s, _ in claim.given if s not in candidate)
            return cex + derived, float(viol), used
    return None, None, used
