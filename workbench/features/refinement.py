"""Findings on converged numbers only (issue 33, item 4): the claim-level
refinement, one implementation for every kind and paper.

A study whose results depend on a numerical step names it in its
``refine_field`` attribute (the name of a float field of its spec, e.g.
``"dt"``, with its unit in ``refine_unit``). :func:`refine_findings` runs the
study again with that step halved and quartered and checks the metric of
every finding at the three levels with
:func:`workbench.sim.convergence.refinement_check`; :func:`claim_tolerance`
says what tolerance the Richardson estimate must stay below. A finding
whose metric has not converged is INCONCLUSIVE (:mod:`workbench.verify`).
A study that refines its own parameters gives :class:`Levels` per finding,
read by :func:`refine_by_readers` (quantity pattern -> metric reader;
:func:`unstepped_levels` for a metric without a step, :func:`claimed_members`
for the members a claim asks to refine once more).

Also here: :func:`guarded_check` (a sequence whose differences change sign
is not in its asymptotic range), :func:`screen` over several metrics and the
screen of a two-level tolerance over three levels (:func:`screen_levels`,
:func:`screen_reason`), and :func:`share_claim_levels`, a claim on the share
of Monte Carlo runs with an outcome refined over partly refined runs
(:func:`share_levels`).

The control period and every other design variable stay as designed: only
the integration step is refined. ``workbench/features/refinement.py``, which the
committed reports name, re-exports this module.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from ..claims import Claim, ClaimResult, Verdict, check_claim
from ..memo import run_study
from ..report.markdown import fmt
from ..sim.convergence import (CONVERGED, INCONCLUSIVE, LEVELS, NOT_CONVERGED, P_MAX, P_MIN,
                              ROUNDING, Refinement, refinement_check)

__all__ = ["LEVELS", "Levels", "ROUNDING", "RefinementRow", "RefinementTable", "claim_tolerance",
           "claimed_members", "guarded_check", "not_converged_text", "refine_by_readers",
           "refine_findings",
           "refinement_row", "screen", "screen_levels", "screen_reason", "screen_tolerances",
           "share_claim_levels", "share_levels", "share_value", "unstepped_levels"]


@dataclass(frozen=True)
class Levels:
    """A finding's metric at three refinement levels, from a study that
    refines its own numerical parameters (``refine_levels``, see
    :func:`refine_findings`).

    ``values``: (q1, q2, q4), numbers or words; ``parameter``: the name of
    the refined parameter (e.g. ``"dt"``, ``"plant_step"``) and ``step``
    its designed value (the levels are it, its half, its quarter; ``unit``
    its unit); ``reason``: set (and ``values`` empty) when the metric has
    no three-level check, which makes the finding INCONCLUSIVE;
    ``decides``: for word values, the part of each level that must agree
    (e.g. the claim's verdict at that level, where ``values`` also show the
    counts behind it; empty: the values themselves).
    """

    values: tuple
    parameter: str = ""
    step: float | None = None
    unit: str = "s"
    reason: str = ""
    decides: tuple = ()

    @property
    def label(self) -> str:
        """``"name = step unit"`` (empty without a parameter)."""
        if not self.parameter:
            return ""
        return self.parameter + ("" if self.step is None else f" = {fmt(self.step)} {self.unit}")


@dataclass(frozen=True)
class RefinementRow:
    """The three-level check of one finding's metric.

    ``check`` is the numeric :class:`~workbench.sim.convergence.Refinement`
    (None for a word-valued metric, which converges when the three levels
    agree); ``values`` the metric at the three levels; ``reason`` the text
    an unconverged finding shows.
    """

    claim_id: str
    quantity: str
    values: tuple
    tolerance: float | None
    outcome: str
    check: Refinement | None = None
    reason: str = ""
    parameter: str = ""

    @property
    def converged(self) -> bool:
        return self.outcome == CONVERGED


@dataclass(frozen=True)
class RefinementTable:
    """The refined parameter (name, unit, designed value), one row per
    finding, and the guards of the observed order (for the report's text)."""

    field: str
    unit: str
    step: float
    rows: tuple[RefinementRow, ...]
    p_min: float = P_MIN
    p_max: float = P_MAX


def claim_tolerance(c: Claim, got) -> float | None:
    """The largest error of ``got`` that cannot change the claim's verdict.

    ``within``: the claim's tolerance. ``<=`` / ``>=``: the distance from
    ``got`` to the bound (value plus or minus the tolerance), so that the
    estimate cannot carry the metric across it (our choice: the verdict is
    what the finding states). ``==`` on a number: half a unit of the last
    compared digit, or the tolerance. None for a word.
    """
    if isinstance(got, str) or isinstance(c.value, str):
        return None
    got, v = float(got), float(c.value)
    if c.compare == "within":
        return c.tolerance
    if c.compare == "<=":
        return abs(v + c.tolerance - got)
    if c.compare == ">=":
        return abs(got - (v - c.tolerance))
    return 0.5 * 10.0 ** -c.digits if c.digits is not None else c.tolerance


def guarded_check(q1: float, q2: float, q4: float, *, tolerance: float) -> Refinement:
    """:func:`~workbench.sim.convergence.refinement_check`, and a sequence
    whose differences change sign is not in its asymptotic range either.

    ``q1 - q2`` and ``q2 - q4`` of opposite signs (both above the rounding
    floor) is an oscillation, not convergence at an order: the observed
    order of such a sequence is an accident of where the levels fall (a
    braking time of paper 003 reads 85.96 / 86.68 / 86.14 s, order 0.42,
    and under a 3-ulp move of its inputs 87.18 / 86.28 / 86.45 s, order 2.4,
    which the plain check calls converged). Its error is then estimated as
    the plain check does below ``P_MIN``: the larger difference at
    p = ``P_MIN``, CONVERGED when within ``tolerance``, INCONCLUSIVE
    otherwise (our choice: conservative, Roache 1997 treats oscillatory
    convergence as outside the observed-order estimate).

    References
    ----------
    P. J. Roache, "Quantification of uncertainty in computational fluid
    dynamics", Annu. Rev. Fluid Mech. 29, 123-160, 1997.
    """
    r = refinement_check(q1, q2, q4, tolerance=tolerance)
    if r.estimate is None or r.order is None or math.isinf(r.order) or r.order < P_MIN:
        return r
    a, b, c = r.values
    floor = ROUNDING * max(abs(a), abs(b), abs(c))
    d1, d2 = a - b, b - c
    if abs(d1) <= floor or abs(d2) <= floor or d1 * d2 >= 0:
        return r
    est = max(abs(d1), abs(d2)) / (r.ratio ** P_MIN - 1)
    note = (f"differences change sign (observed order {r.order:.2g}): not in the asymptotic "
            f"range; estimate from the larger difference at p = {P_MIN:g}")
    return Refinement(r.values, r.ratio, r.order, est, tolerance,
                      CONVERGED if est <= tolerance else INCONCLUSIVE, note)


def screen(values: dict, tolerances: dict) -> tuple[str | None, tuple[str, ...]]:
    """A convergence claim over several metrics, three levels each.

    Parameters
    ----------
    values : dict
        metric -> (q1, q2, q4) at the step, its half and its quarter.
    tolerances : dict
        metric -> tolerance of its Richardson estimate (the same unit).

    Returns
    -------
    (str or None, tuple of str)
        ``"yes"`` when every metric converged (:func:`guarded_check`; a
        metric not reached at any level, NaN three times, counts as
        converged), else None (the claim is INCONCLUSIVE: not converged is
        not a verdict on the design), and the metrics that did not
        converge, in the order of ``values``.
    """
    bad = []
    for k, vals in values.items():
        if all(isinstance(x, float) and math.isnan(x) for x in vals):
            continue
        if not guarded_check(*vals, tolerance=tolerances[k]).converged:
            bad.append(k)
    return (None if bad else "yes"), tuple(bad)


def _row(c: Claim, values: tuple, field: str, got, parameter: str = "",
         guarded: bool = False, decides: tuple = ()) -> RefinementRow:
    tol = claim_tolerance(c, got)
    levels = f"{field}, {field}/2, {field}/4"
    if parameter:
        name = parameter.split(" = ")[0]
        levels = f"{name}, {name}/2, {name}/4"
    instead = (f"`{c.converged_instead}`" if c.converged_instead else
               "a quantity that converges (the claim's `converged_instead`)")
    row = _check(c, values, levels, tol, instead, guarded, decides)
    return dataclasses.replace(row, parameter=parameter) if parameter else row


def _check(c: Claim, values: tuple, levels: str, tol, instead: str,
           guarded: bool = False, decides: tuple = ()) -> RefinementRow:
    if tol is None or not all(isinstance(x, (int, float)) for x in values):
        same = len({str(x) for x in (decides or values)}) == 1
        return RefinementRow(c.id, c.quantity, values, None, CONVERGED if same else NOT_CONVERGED,
                             None, "" if same else f"not converged: {c.quantity} is "
                             f"{' / '.join(str(x) for x in values)} at {levels}; "
                             f"use {instead} instead")
    if not all(math.isfinite(float(x)) for x in values) and len(set(values)) == 1:
        return RefinementRow(c.id, c.quantity, values, tol, CONVERGED)
    r = (guarded_check if guarded else refinement_check)(*values, tolerance=tol)
    shown = ", ".join(fmt(x, 5) for x in values)
    if r.outcome == CONVERGED:
        reason = ""
    elif r.outcome == NOT_CONVERGED:
        reason = (f"not converged: {c.quantity} estimate {fmt(r.estimate, 2)} > tolerance "
                  f"{fmt(tol, 2)} ({shown} at {levels}, observed order {fmt(r.order, 2)}); "
                  f"use {instead} instead")
    else:
        est = "" if r.estimate is None else f", estimate {fmt(r.estimate, 2)} > tolerance {fmt(tol, 2)}"
        reason = (f"not converged: {c.quantity} {r.note} ({shown} at {levels}{est}); "
                  f"use {instead} instead")
    return RefinementRow(c.id, c.quantity, values, tol, r.outcome, r, reason)


def refine_findings(design, study, quantities: dict,
                    checked: list[ClaimResult], result=None) -> RefinementTable:
    """Three-level refinement of the metric of every finding of ``design``.

    Parameters
    ----------
    design : workbench.design.Design
    study : object
        The design's study, with ``refine_field`` (and ``refine_unit``).
    quantities : dict
        The study's quantities at the designed step.
    checked : list of ClaimResult
        The claims' results at the designed step.
    result : object, optional
        The study's result at the designed step. A study with a
        ``refine_levels(design, result, findings)`` method refines its own
        parameters (it returns ``claim id -> Levels``, reusing the levels it
        has computed); the others are run again at step/2 and step/4.

    Returns
    -------
    RefinementTable
        Empty rows when the design has no finding with a determined metric
        (the study is then not run again).
    """
    field = study.refine_field
    step = float(getattr(design.spec, field))
    finds = [r for r in checked if r.claim.is_finding and r.got is not None]
    if not finds:
        return RefinementTable(field, getattr(study, "refine_unit", ""), step, ())
    if hasattr(study, "refine_levels"):
        own = study.refine_levels(design, result, finds)
        return RefinementTable(field, getattr(study, "refine_unit", ""), step,
                               tuple(_own_row(r, own.get(r.claim.id), field) for r in finds))
    levels = [quantities]
    for k in LEVELS[1:]:
        spec = dataclasses.replace(design.spec, **{field: step / 2 ** k})
        levels.append(study.quantities(run_study(dataclasses.replace(design, spec=spec),
                                                 study.run)))
    rows = tuple(_row(r.claim, tuple(q.get(r.claim.quantity) for q in levels), field, r.got)
                 for r in finds)
    return RefinementTable(field, getattr(study, "refine_unit", ""), step, rows)


def refinement_row(c: Claim, values: tuple, field: str, got) -> RefinementRow:
    """The three-level check of one claim's metric (``values`` at the step,
    its half and its quarter; ``got`` the value the claim compared), with the
    reason an unconverged claim shows: the check :func:`refine_findings`
    applies to each finding, for a kind that refines every claim itself
    (``switched-run``)."""
    return _row(c, values, field, got)


def _own_row(r: ClaimResult, lv: Levels | None, field: str) -> RefinementRow:
    """The row of a finding refined by its study (:class:`Levels`); a
    finding the study does not refine is INCONCLUSIVE."""
    if lv is None or not lv.values:
        why = lv.reason if lv is not None else "its study has no three-level check of it"
        return RefinementRow(r.claim.id, r.claim.quantity, (), None, INCONCLUSIVE, None,
                             f"not converged: no three-level check ({why})",
                             lv.label if lv else "")
    return _row(r.claim, lv.values, field, r.got, lv.label, guarded=True,
                decides=lv.decides)



def refine_by_readers(findings, readers, *context) -> dict:
    """claim id -> :class:`Levels` of every finding, for a study that refines
    its own parameters (its ``refine_levels``).

    Parameters
    ----------
    findings : list of ClaimResult
        The findings and their values.
    readers : sequence of (re.Pattern, callable)
        Quantity pattern and its metric reader, ``(*context, match, finding)
        -> Levels``; the first pattern that matches the start of a finding's
        quantity reads it. A finding no pattern matches has no three-level
        check (INCONCLUSIVE, :func:`refine_findings`).
    *context
        What every reader is given first (the design, the study's result, a
        memo the readers share, say).
    """
    out = {}
    for r in findings:
        qn = r.claim.quantity
        read = next(((m, f) for p, f in readers if (m := p.match(qn))), None)
        out[r.claim.id] = (read[1](*context, read[0], r) if read else
                           Levels((), reason=f"no three-level check of `{qn}` in this study"))
    return out


def claimed_members(claims, pattern: str) -> frozenset:
    r"""The first group of ``pattern`` (a regular expression matching a whole
    quantity, e.g. ``r"cases\[([^\]]+)\]\.converged"``) over the quantities of
    ``claims``: the members (cases, scenarios) a claim speaks of, which a
    study may refine once more."""
    import re
    return frozenset(m.group(1) for c in claims if (m := re.fullmatch(pattern, c.quantity)))


def unstepped_levels(finding, label: str) -> Levels:
    """The :class:`Levels` of a finding whose metric has no step (e.g. a
    certificate at a printed point): its printed value (6 digits) at every
    level; ``label`` says why."""
    v = fmt(finding.got, 6)
    return Levels((v, v, v), label)


def share_value(quantity: str, k: int, n: int) -> float:
    """The value of a Monte Carlo share quantity when k of n runs have its
    outcome: ``<prefix>.fraction.<flag>`` is k / n and
    ``<prefix>.wilson.<outcome>.lo`` / ``.hi`` a bound of the Wilson interval
    (the names of :func:`workbench.features.montecarlo_stats.runs_quantities`)."""
    from .montecarlo import wilson_interval
    if ".wilson." in quantity and quantity.endswith((".lo", ".hi")):
        _, _, _, lo, hi = wilson_interval(k, n)
        return lo if quantity.endswith(".lo") else hi
    if ".fraction." in quantity:
        return k / n
    raise ValueError(f"share_value: {quantity!r} is not a share quantity "
                     "(<prefix>.fraction.<flag> or <prefix>.wilson.<outcome>.lo/.hi)")


def share_claim_levels(claim, whole, half, quarter, word: str, parameter: str,
                       step: float) -> Levels:
    """A claim on a Monte Carlo share (:func:`share_value` of its quantity)
    at ``step``, its half and its quarter, when all N runs ran at ``step``
    (``whole``: N bools of the outcome, named ``word``) and only the first n
    again at the finer levels (``half``, ``quarter``: n bools each):
    :func:`share_levels` (a level decides the
    claim when its verdict is the same over the whole range of counts the
    unrefined runs allow). The claim has converged when the three levels
    decide it the same way (the values show the counts,
    :attr:`Levels.decides` the verdicts); ``parameter`` names the step."""
    vals, dec = share_levels(claim, whole, half, quarter,
                             lambda k, n: share_value(claim.quantity, k, n), word)
    return Levels(vals, parameter, step, decides=dec)


def screen_tolerances(values: dict, rtol: float, atol: dict) -> dict:
    """metric -> the bound of its Richardson estimate: the tolerance of a
    two-level screen, ``atol[metric] + rtol max(|q|)`` over the finite
    values of its levels (``values``: metric -> (q1, q2, q4))."""
    return {k: atol.get(k, 0.0) + rtol * max((abs(x) for x in v if math.isfinite(x)),
                                             default=0.0) for k, v in values.items()}


def screen_levels(values: dict, rtol: float, atol: dict) -> tuple[dict, tuple]:
    """(metric -> converged, metrics not converged) of ``values`` (metric ->
    (q1, q2, q4)): :func:`screen` with :func:`screen_tolerances`, the
    tolerance of a two-level screen, as the bound of each Richardson
    estimate (issue 33 item 4)."""
    _, bad = screen(values, screen_tolerances(values, rtol, atol))
    return {k: k not in bad for k in values}, bad


def screen_reason(values: dict, rtol: float, atol: dict, name_of, instead: dict,
                  otherwise: str) -> str:
    """Why a screen (:func:`screen_levels`) did not converge: every metric of
    ``values`` (metric -> (q1, q2, q4), the metrics that did not converge)
    in the words of :func:`not_converged_text`,
    named ``name_of(metric)``, with its :func:`guarded_check` error and the
    quantity to use instead: the metric ``instead[metric]`` (named
    ``name_of``) unless it did not converge either, else ``otherwise``; ""
    when ``values`` is empty."""
    tol = screen_tolerances(values, rtol, atol)
    use = {k: f"`{name_of(a)}`" for k, a in instead.items() if a not in values}
    parts = [not_converged_text(name_of(k), v, guarded_check(*v, tolerance=tol[k]).estimate,
                                tol[k], use.get(k, otherwise)) for k, v in values.items()]
    return "not converged: " + "; ".join(parts) if parts else ""


def not_converged_text(quantity: str, values, estimate: float | None, tolerance: float,
                       instead: str, levels: str = "dt, dt/2, dt/4") -> str:
    """``<quantity> q1 / q2 / q4 at <levels>, Richardson error X > tol Y;
    use <instead> instead``: what an INCONCLUSIVE claim says of a metric
    that did not converge (issue 33; values to 6 digits, as the convergence
    tables print them, the estimate and tolerance to 2)."""
    err = "not determined (a value is not finite)" if estimate is None else fmt(estimate, 2)
    return (f"{quantity} {' / '.join(fmt(x, 6) for x in values)} at {levels}, Richardson "
            f"error {err} > tol {fmt(tolerance, 2)}; use {instead} instead")


def share_levels(claim, whole, half, quarter, value_of, word: str) -> tuple[tuple, tuple]:
    """A claim on the share of runs with an outcome, at dt, dt/2 and dt/4,
    when all N runs ran at dt (``whole``: N bools) and only the first n
    again at dt/2 and dt/4 (``half``, ``quarter``: n bools each).

    At dt the count k is known. At dt/2 and dt/4 the n refined runs give
    k_n, and the other N - n runs, not run there, may have the outcome or
    not: the count lies in [k_n, k_n + N - n], a bound that holds whatever
    they do. The claim is checked (``value_of(k, N)``: the claimed quantity
    when k of N runs have the outcome) at every count of that range: a
    level *decides* the claim when the verdict is the same over the whole
    range (``holds`` / ``fails``), else it is ``undecided``. n = N refines
    every run and the range is the count itself.

    Returns
    -------
    (values, decides) : tuple of str, tuple of str
        Per level the counts behind it (``word`` names the outcome) and its
        decision; the claim has converged when the three decisions agree.
    """
    big, n = len(whole), len(half)

    def verdict(lo: int, hi: int) -> str:
        got = {check_claim(claim, value_of(k, big)).verdict for k in range(lo, hi + 1)}
        if len(got) != 1:
            return "undecided"
        return {Verdict.PASS: "holds", Verdict.FAIL: "fails"}.get(got.pop(), "undecided")

    k = sum(bool(x) for x in whole)
    vals, dec = [f"{k} of {big} {word}: {verdict(k, k)}"], [verdict(k, k)]
    for level in (half, quarter):
        kn = sum(bool(x) for x in level)
        v = verdict(kn, kn + big - n)
        vals.append(f"{kn} of the first {n}, so {kn}-{kn + big - n} of {big} {word}: {v}"
                    if n < big else f"{kn} of {big} {word}: {v}")
        dec.append(v)
    return tuple(vals), tuple(dec)
