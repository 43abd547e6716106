"""Mechanical checking of the derivation steps of papers: three-valued proofs.

A :class:`Claim` is built from sympy objects by a module of ``proofs/`` (never
from text: nothing here calls ``eval`` or ``sympify`` on strings). It asserts
one of five things:

``identity``
    ``lhs == rhs`` (scalars or matrices), possibly under equalities ``given``
    (substitutions ``symbol := expression``).
``inequality``
    ``lhs <= rhs`` under hypotheses ``symbol op bound``. Checked the way papers
    argue: ``rhs - lhs`` is written as a sum of ``terms`` (identity checked),
    and every term is shown sign-definite (``>= 0``) after replacing each
    hypothesis by a slack variable (``eta = D + s``, ``s >= 0``) and splitting
    into cases on the signs of the symbols inside ``Abs`` / ``sign``.
``minimiser``
    ``law = argmin_u J(u)``: the stationary point is *derived* (solved from
    dJ/du = 0, it must be unique), compared with the law, and convexity
    (d2J/du2 > 0) is shown as for inequalities.
``solution``
    ``x(t)`` (closed form) solves ``x' = f(x, t)`` with ``x(t0) = x0`` and,
    optionally, reaches ``x(T) = x_T`` (e.g. a reaching time).
``value``
    a worked number: an exact expression equals a printed value at its
    printed decimals.

Every claim but ``value`` also gets a second, independent check: a seeded
falsification search (:mod:`workbench.symbolic.falsify`) samples the symbols
in a box, keeps the points satisfying the hypotheses, and evaluates the
residual numerically (for ``minimiser``: J at perturbed laws; for
``solution``: the ODE, initial and terminal residuals). A failure found is
re-evaluated with 30-digit arithmetic at rounded values before it is
reported as a counterexample.

Verdicts form a closed set (like sympy's ``is_stable``: True / False / None):
PROVED, REFUTED (with a counterexample), INCONCLUSIVE (with what remains to
be shown).
"""
from __future__ import annotations

import enum
from dataclasses import dataclass
from decimal import Decimal
from typing import Literal

import sympy as sp

from ..jsonable import json_method
from .falsify import apply_given, falsify
from .positivity import is_identically_zero, prove_nonnegative, tex, with_slacks

KINDS = ("identity", "inequality", "minimiser", "solution", "value")
OPS = (">=", ">", "<=", "<")


class Verdict(str, enum.Enum):
    PROVED = "PROVED"
    REFUTED = "REFUTED"
    INCONCLUSIVE = "INCONCLUSIVE"


@dataclass(frozen=True)
class Hypothesis:
    """``symbol op bound`` (op in ``>=, >, <=, <``): an assumption a proof may use.

    The sign prover replaces ``symbol`` by ``bound + s`` (or ``bound - s``)
    with a fresh slack ``s >= 0`` (``> 0`` for strict relations), in the order
    the hypotheses are given; this covers every point where the hypothesis
    holds, so a proof in the slack variables is a proof under the hypothesis
    (a hypothesis whose symbol an earlier one eliminated is simply not used).
    The falsification search keeps only the sample points where all hold.
    """

    symbol: sp.Symbol
    op: str
    bound: sp.Expr

    def __post_init__(self):
        if self.op not in OPS:
            raise ValueError(f"hypothesis op = {self.op!r}; expected one of {OPS}")

    @property
    def relational(self) -> sp.Basic:
        return {">=": sp.Ge, ">": sp.Gt, "<=": sp.Le, "<": sp.Lt}[self.op](
            self.symbol, self.bound, evaluate=False)

    def latex(self) -> str:
        return sp.latex(self.relational)


def hyp(symbol: sp.Symbol, op: str, bound) -> Hypothesis:
    """Shorthand for :class:`Hypothesis`."""
    return Hypothesis(symbol, op, sp.sympify(bound) if isinstance(bound, (int, float)) else bound)


def time_derivative(expr, flows: dict) -> sp.Expr:
    """d/dt of ``expr`` along x' = flows[x] (chain rule over the flow's symbols)."""
    return sp.Add(*(sp.diff(expr, x) * f for x, f in flows.items()))


def sig(x: sp.Expr, p: sp.Expr) -> sp.Expr:
    """Sign-preserving power sign(x) |x|^p (odd-ratio powers of papers 001)."""
    return sp.sign(x) * sp.Abs(x) ** p


@dataclass(frozen=True)
class Claim:
    """One checkable step of a paper (see the module docstring for ``kind``).

    Attributes
    ----------
    id, paper, equations, statement : str
        Identifier, paper number ("000".."004"), equation numbers, plain words.
    kind : str
        One of :data:`KINDS`.
    lhs, rhs : sympy expression or Matrix
        Both sides (``minimiser``: lhs = criterion J, rhs = the law;
        ``solution``: lhs = x(t), rhs = f(x, t) with ``state`` standing for x;
        ``value``: lhs = exact expression, rhs = printed value).
    variable : sympy.Symbol, optional
        ``minimiser``: decision variable; ``solution``: time.
    state : sympy.Symbol, optional
        ``solution``: symbol standing for x in ``rhs``.
    initial, terminal : (time, value), optional
        ``solution``: x(t0) = x0 and x(T) = x_T.
    hypotheses : tuple of Hypothesis
    given : tuple of (Symbol, Expr)
        Equalities used as substitutions (applied in order).
    terms : tuple of Expr
        ``inequality``: decomposition of ``rhs - lhs`` into terms to show >= 0.
    sample : tuple of (Symbol, lo, hi)
        Falsification box; other symbols use [0.1, 3] (positive) or [-3, 3].
    digits : int
        ``value``: printed decimals.
    nonzero : tuple of Symbol
        Symbols assumed nonzero (their zero sign case is not split).
    expect : "proved" | "refuted"
        "refuted" marks the as-printed half of an erratum pair.
    display : str
        LaTeX shown for the claim instead of ``lhs = rhs`` (for large
        matrices; display only, never parsed).
    note : str
        Erratum / remark shown in the report.
    origin : "paper" | "workbench"
        "paper": a step as the paper states it (or the printed half of an
        erratum); "workbench": a corrected form or a repair the workbench adds.
    severity : str, optional
        How much an erratum (``expect = "refuted"``) matters, one of
        :data:`workbench.claims.SEVERITIES` (checked by :mod:`workbench.prove`);
        None: not assessed.
    severity_reason : str
        One line saying why (required with a severity).
    """

    id: str
    paper: str
    equations: str
    statement: str
    kind: Literal["identity", "inequality", "minimiser", "solution", "value"]
    lhs: object
    rhs: object
    variable: sp.Symbol | None = None
    state: sp.Symbol | None = None
    initial: tuple | None = None
    terminal: tuple | None = None
    hypotheses: tuple[Hypothesis, ...] = ()
    given: tuple[tuple[sp.Symbol, sp.Expr], ...] = ()
    terms: tuple[sp.Expr, ...] = ()
    sample: tuple[tuple[sp.Symbol, float, float], ...] = ()
    digits: int | None = None
    nonzero: tuple[sp.Symbol, ...] = ()
    display: str = ""
    expect: Literal["proved", "refuted"] = "proved"
    note: str = ""
    origin: Literal["paper", "workbench"] = "paper"
    severity: str | None = None
    severity_reason: str = ""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.id}: kind = {self.kind!r}; expected one of {KINDS}")
        if self.expect not in ("proved", "refuted"):
            raise ValueError(f"claim {self.id}: expect = {self.expect!r}")
        if self.origin not in ("paper", "workbench"):
            raise ValueError(f"claim {self.id}: origin = {self.origin!r}")


@dataclass(frozen=True)
class Step:
    """One checked step: what, its LaTeX, and whether it went through."""

    what: str
    latex: str
    ok: bool | None


@dataclass(frozen=True)
class ProofResult:
    """Outcome of :func:`check_claim`.

    Attributes
    ----------
    verdict : Verdict
    steps : tuple of Step
    counterexample : tuple of (name, float), optional
        Symbol values where the claim fails (REFUTED only), re-checked with
        30-digit arithmetic; ``violation`` is the amount it fails by there.
    remaining : str
        What is left to show (INCONCLUSIVE only).
    samples : int
        Points of the falsification search that satisfied the hypotheses.
    severity_holds : bool
        False when the claim's severity was checked against the result and
        does not hold (:func:`workbench.prove.check_proof_claim`: a
        ``rounding`` erratum more than a rounding off); the claim is then not ok.
    """

    claim: Claim
    verdict: Verdict
    steps: tuple[Step, ...]
    counterexample: tuple[tuple[str, float], ...] | None = None
    violation: float | None = None
    remaining: str = ""
    samples: int = 0
    severity_holds: bool = True

    @property
    def ok(self) -> bool:
        """PROVED, or REFUTED for a claim declared expected-refuted (and its
        severity, where checked, holds)."""
        want = Verdict.REFUTED if self.claim.expect == "refuted" else Verdict.PROVED
        return self.verdict is want and self.severity_holds

    #: The JSON of a proof claim's result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"id": "claim.id", "paper": "claim.paper", "equations": "claim.equations",
                   "statement": "claim.statement", "kind": "claim.kind",
                   "expect": "claim.expect", "origin": "claim.origin",
                   "severity": "claim.severity", "verdict": "verdict", "ok": "ok",
                   "counterexample": lambda r: (None if r.counterexample is None
                                                else dict(r.counterexample)),
                   "violation": "violation", "remaining": "remaining", "samples": "samples",
                   "steps": "steps"}
    to_json = json_method


# -- symbolic helpers ---------------------------------------------------------------
# -- the checks ---------------------------------------------------------------------------
def _verdict(claim, steps, symbolic_ok: bool, remaining: str, residual, kind) -> ProofResult:
    """Combine the symbolic argument and the falsification search."""
    cex, viol, used = falsify(claim, residual, kind=kind)
    if cex is not None:
        steps = steps + (Step("falsification search: counterexample found, re-checked with "
                              "30 digits", ", ".join(f"{n} = {v:.6g}" for n, v in cex)
                              or r"\text{any values}", False),)
        if symbolic_ok:  # both cannot be right: never claim a proof then
            return ProofResult(claim, Verdict.INCONCLUSIVE, steps, cex, viol,
                               "the symbolic argument and a numeric counterexample disagree",
                               used)
        return ProofResult(claim, Verdict.REFUTED, steps, cex, viol, "", used)
    steps = steps + (Step(f"falsification search: no counterexample in {used} seeded points "
                          "satisfying the hypotheses", "", True if used else None),)
    if symbolic_ok:
        return ProofResult(claim, Verdict.PROVED, steps, samples=used)
    return ProofResult(claim, Verdict.INCONCLUSIVE, steps, remaining=remaining, samples=used)


def _hyp_step(claim) -> tuple[Step, ...]:
    if not claim.hypotheses and not claim.given:
        return ()
    parts = [h.latex() for h in claim.hypotheses] + [
        f"{sp.latex(s)} = {tex(e)}" for s, e in claim.given]
    return (Step("hypotheses", r",\quad ".join(parts), None),)


def _check_identity(c: Claim) -> ProofResult:
    diff = sp.Matrix(c.lhs) - sp.Matrix(c.rhs) if isinstance(c.lhs, sp.MatrixBase) else \
        sp.sympify(c.lhs) - sp.sympify(c.rhs)
    d = with_slacks(apply_given(diff, c.given), c.hypotheses)
    ok, rest = is_identically_zero(d, c.nonzero)
    steps = _hyp_step(c) + (Step("identity (both sides simplified, sign cases split)",
                                 c.display or f"{tex(c.lhs)} = {tex(c.rhs)}", ok),)
    if not ok:
        steps += (Step("difference left by simplification (lhs - rhs)", rest, False),)
    return _verdict(c, steps, ok, "show " + rest if rest else "", diff, "zero")


def _check_inequality(c: Claim) -> ProofResult:
    margin = apply_given(sp.sympify(c.rhs) - sp.sympify(c.lhs), c.given)
    terms = c.terms or (margin,)
    steps = _hyp_step(c) + (Step("claim", rf"{tex(c.lhs)} \leq {tex(c.rhs)}", None),)
    ok, remaining = True, ""
    if c.terms:
        same, rest = is_identically_zero(sp.Add(*terms) - margin, c.nonzero)
        steps += (Step("decomposition of the margin into terms",
                       rf"{tex(c.rhs)} - \left({tex(c.lhs)}\right) = "
                       + " + ".join(rf"\left({tex(t)}\right)" for t in terms), same),)
        if not same:
            ok, remaining = False, "the terms do not add up to the margin: " + rest
    for t in terms:
        t_ok, rest = prove_nonnegative(t, c.hypotheses, nonzero=c.nonzero)
        steps += (Step("term is nonnegative (hypotheses as slacks, sign cases split)",
                       rf"{tex(t)} \geq 0", t_ok),)
        if not t_ok and ok:
            ok, remaining = False, "show " + rest
    return _verdict(c, steps, ok, remaining, sp.sympify(c.rhs) - sp.sympify(c.lhs), "nonneg")


def _check_minimiser(c: Claim) -> ProofResult:
    J, law, u = sp.sympify(c.lhs), sp.sympify(c.rhs), c.variable
    dJ = sp.diff(J, u)
    sols = sp.solve(dJ, u)
    steps = _hyp_step(c) + (Step("criterion", f"J({sp.latex(u)}) = {tex(J)}", None),
                            Step(f"stationarity dJ/d{u} = 0, solved for {u}",
                                 r",\; ".join(f"{sp.latex(u)} = {tex(s)}" for s in sols) or
                                 r"\text{no solution}", len(sols) == 1))
    if len(sols) != 1:
        return _verdict(c, steps, False, f"dJ/d{u} = 0 has {len(sols)} solutions",
                        sp.Integer(0), "zero")
    same, rest = is_identically_zero(sols[0] - law)
    steps += (Step("the derived minimiser is the stated law",
                   f"{tex(sols[0])} = {tex(law)}", same),)
    d2 = sp.simplify(sp.diff(J, u, 2))
    convex, rest2 = prove_nonnegative(d2, c.hypotheses, strict=True)
    steps += (Step("strict convexity", rf"\frac{{d^2J}}{{d{sp.latex(u)}^2}} = {tex(d2)} > 0",
                   convex),)
    remaining = ("show " + rest) if not same else ("show " + rest2 if not convex else "")
    # falsification: J(law) <= J(law + delta) for a few perturbations delta
    residual = [J.subs(u, law + dl) - J.subs(u, law) for dl in (-1, sp.Rational(-1, 10),
                                                                sp.Rational(1, 10), 1)]
    return _verdict(c, steps, same and convex, remaining, sp.Matrix(residual), "nonneg")


def _check_solution(c: Claim) -> ProofResult:
    x, t, f = sp.sympify(c.lhs), c.variable, sp.sympify(c.rhs)
    ode = sp.diff(x, t) - f.subs(c.state, x)
    parts = [("solves the ODE", ode, rf"\frac{{d}}{{d{sp.latex(t)}}}\left({tex(x)}\right) = "
              + tex(f.subs(c.state, x)))]
    for label, tv in (("initial value", c.initial), ("reaches the target", c.terminal)):
        if tv:
            parts.append((label, x.subs(t, tv[0]) - tv[1],
                          f"x({tex(tv[0])}) = {tex(x.subs(t, tv[0]))} = {tex(tv[1])}"))
    steps, ok, remaining = _hyp_step(c), True, ""
    for label, resid, latex in parts:
        r = apply_given(resid, c.given)
        r_ok, rest = is_identically_zero(r, c.nonzero)
        steps += (Step(label, latex, r_ok),)
        if not r_ok and ok:
            ok, remaining = False, f"{label}: show {rest}"
    return _verdict(c, steps, ok, remaining, sp.Matrix([p[1] for p in parts]), "zero")


def _check_value(c: Claim) -> ProofResult:
    exact = sp.sympify(c.lhs)
    got = sp.N(exact, 30)
    num, den = Decimal(repr(float(c.rhs))).as_integer_ratio()  # the printed decimal
    printed = sp.Rational(num, den)
    half = sp.Rational(1, 2) * sp.Rational(10) ** (-c.digits)
    ok = bool(abs(got - printed) <= half)
    steps = (Step(f"exact value, compared at the printed {c.digits} decimals",
                  f"{tex(exact)} = {sp.N(exact, 10)} "
                  + (r"\approx " if ok else r"\not\approx ") + str(c.rhs), ok),)
    if ok:
        return ProofResult(c, Verdict.PROVED, steps)
    return ProofResult(c, Verdict.REFUTED, steps, (("computed", float(got)),),
                       float(abs(got - printed)))


_CHECKS = {"identity": _check_identity, "inequality": _check_inequality,
           "minimiser": _check_minimiser, "solution": _check_solution, "value": _check_value}


def check_claim(claim: Claim) -> ProofResult:
    """PROVED / REFUTED / INCONCLUSIVE for one claim (see the module docstring).

    Parameters
    ----------
    claim : Claim

    Returns
    -------
    ProofResult
        With the LaTeX of every checked step, the counterexample of a
        refuted claim and what remains of an inconclusive one.
    """
    return _CHECKS[claim.kind](claim)
