"""Sign and zero tests of sympy expressions, the way papers argue them.

:func:`is_identically_zero` simplifies in every sign case of the symbols
inside ``Abs`` / ``sign`` / ``Piecewise``; :func:`prove_nonnegative` replaces
each hypothesis ``x op b`` by a slack variable (``x = b + s``, ``s >= 0``),
splits into the same sign cases and asks sympy's assumptions (after a few
rewritings) whether each case is non-negative. Both answer (True, "") or
(False, LaTeX of what remains to be shown); neither ever evaluates text.
Used by :mod:`workbench.symbolic.proof`.
"""
from __future__ import annotations

import itertools
from typing import Sequence

import sympy as sp

from .falsify import elements

#: Longest LaTeX printed for an expression (longer: a size note).
LATEX_LIMIT = 700


def tex(expr) -> str:
    """LaTeX of an expression, or a size note when it is too long to read."""
    s = sp.latex(expr)
    if len(s) > LATEX_LIMIT:
        return rf"\text{{(expression of {sp.count_ops(expr)} operations, not shown)}}"
    return s


def _sign_atoms(expr) -> list[sp.Symbol]:
    """Real symbols of unknown sign inside Abs / sign / Piecewise conditions."""
    out = set()
    inside = [f.args[0] for f in expr.atoms(sp.Abs, sp.sign)]
    inside += [cond for pw in expr.atoms(sp.Piecewise) for _, cond in pw.args]
    for a in inside:
        for s in a.free_symbols:
            if s.is_positive is None and s.is_negative is None:
                out.add(s)
    return sorted(out, key=lambda s: s.name)


def _cases(expr, nonzero=()):
    """Yield (description, expression) over the sign cases of ``_sign_atoms``
    (symbols in ``nonzero`` get no zero case)."""
    atoms = _sign_atoms(expr)
    if not atoms:
        yield "", expr
        return
    pos = {s: sp.Symbol(s.name + "_+", positive=True) for s in atoms}
    for signs in itertools.product(*[(1, -1) if s in nonzero else (1, -1, 0) for s in atoms]):
        sub = {s: sg * pos[s] for s, sg in zip(atoms, signs)}
        desc = ", ".join(f"{sp.latex(s)} {'>' if sg > 0 else '<' if sg < 0 else '='} 0"
                         for s, sg in zip(atoms, signs))
        yield desc, expr.subs(sub)


#: Points tried by :func:`_nonzero_somewhere` (rational coordinates from a
#: fixed seed: the same expression always meets the same points). One: a
#: non-zero expression vanishes at a random rational point with probability 0.
PROBE_POINTS = 1
#: Digits of the probe's evaluation; a value above PROBE_FLOOR is not rounding.
PROBE_DIGITS, PROBE_FLOOR = 30, 1e-15


def _probe_value(s: sp.Symbol, rng) -> sp.Rational | None:
    """A rational value allowed by ``s``'s assumptions (None: none known)."""
    v = sp.Integer(rng.randint(2, 9)) if s.is_integer else \
        sp.Rational(rng.randint(11, 97), rng.randint(11, 97))
    if s.is_negative or s.is_nonpositive:
        v = -v
    ok = all(getattr(v, "is_" + k, None) == val for k, val in s.assumptions0.items())
    return v if ok else None


def _nonzero_somewhere(e) -> bool:
    """True when ``e`` is provably not identically zero: at an exact rational
    point allowed by every symbol's assumptions it evaluates (sympy's evalf,
    which raises its working precision through cancellation) to a number of
    magnitude above :data:`PROBE_FLOOR`. False means "not shown", never
    "zero". It spares :func:`sympy.simplify` the refuted identities, where
    it can run for minutes (the factoring inside ``trigsimp``; seen on a
    printed erratum of paper 001, eq 5, in a check worker, round 3)."""
    import random
    syms = sorted(e.free_symbols, key=lambda x: x.name)
    rng = random.Random(20260)
    for _ in range(PROBE_POINTS):
        point = {s: _probe_value(s, rng) for s in syms}
        if any(v is None for v in point.values()):
            return False
        try:
            exact = e.xreplace(point)
            if exact.is_Rational:          # a rational function: decided exactly
                if exact != 0:
                    return True
                continue
            val = sp.N(exact, PROBE_DIGITS)
        except Exception:  # pragma: no cover - sympy internals
            continue
        if val.is_number and val.is_finite and abs(val) > PROBE_FLOOR:
            return True
    return False


def _is_zero(e) -> bool:
    if e == 0:
        return True
    if _nonzero_somewhere(e):
        return False
    for f in (sp.expand, sp.cancel, lambda x: sp.expand(sp.powdenest(x)), sp.simplify):
        try:
            r = f(e)
        except Exception:  # pragma: no cover - sympy internals
            continue
        if r == 0:
            return True
        e = r
    return False


def is_identically_zero(expr, nonzero=()) -> tuple[bool, str]:
    """(True, "") when ``expr`` simplifies to 0 in every sign case, else
    (False, LaTeX of the first case that did not)."""
    entries = elements(expr)
    for i, e in enumerate(entries):
        for desc, ce in _cases(sp.sympify(e), nonzero):
            if not _is_zero(ce):
                where = (f"entry ({i // expr.cols + 1}, {i % expr.cols + 1}) "
                         if len(entries) > 1 else "") + (desc + ": " if desc else "")
                return False, where + tex(sp.simplify(ce)) + r" \overset{?}{=} 0"
    return True, ""


def with_slacks(expr, hypotheses):
    """Replace each hypothesis ``x op b`` (a :class:`~workbench.symbolic.proof.Hypothesis`)
    by ``x = b +/- s`` with a slack s >= 0 (s > 0 for a strict one)."""
    slacks = []
    for i, h in enumerate(hypotheses):
        s = sp.Symbol(f"s_{i + 1}", nonnegative=True) if h.op in (">=", "<=") else \
            sp.Symbol(f"s_{i + 1}", positive=True)
        expr = expr.subs(h.symbol, h.bound + s if h.op in (">=", ">") else h.bound - s)
        slacks.append(s)
    return expr


def _exp_bounded(e):
    """Replace exp(x), x <= 0, by 1 - p with a fresh p >= 0 (sound: it only
    forgets that exp(x) > 0)."""
    reps = {f: 1 - sp.Symbol(f"p_{i + 1}", nonnegative=True)
            for i, f in enumerate(sorted(e.atoms(sp.exp), key=sp.default_sort_key))
            if f.args[0].is_nonpositive}
    return e.subs(reps) if reps else None


def _nonneg(e) -> bool:
    if e.is_nonnegative:
        return True
    bounded = _exp_bounded(e)
    if bounded is not None and _nonneg(bounded):
        return True
    for f in (sp.expand, sp.factor, sp.simplify, lambda x: sp.powsimp(sp.expand(x), force=False)):
        try:
            if f(e).is_nonnegative:
                return True
        except Exception:  # pragma: no cover
            continue
    return False


def prove_nonnegative(expr, hypotheses: Sequence = (), *, strict=False,
                      nonzero=()) -> tuple[bool, str]:
    """Show ``expr >= 0`` (``> 0`` if strict) from symbol assumptions and
    hypotheses (:class:`~workbench.symbolic.proof.Hypothesis`).

    Returns (True, "") or (False, LaTeX of what remains to be shown).
    """
    e = with_slacks(sp.sympify(expr), hypotheses)
    for desc, ce in _cases(e, nonzero):
        ok = (ce.is_positive or bool(sp.simplify(ce).is_positive)) if strict else _nonneg(ce)
        if not ok:
            rel = ">" if strict else r"\geq"
            return False, (desc + ": " if desc else "") + f"{tex(sp.simplify(ce))} {rel} 0"
    return True, ""
