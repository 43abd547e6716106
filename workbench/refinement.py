"""Findings on converged numbers only (issue 33, item 4).

A study whose results depend on a numerical step names it in its
``refine_field`` attribute (the name of a float field of its spec, e.g.
``"dt"``, with its unit in ``refine_unit``). :func:`refine_findings` runs the
study again with that step halved and quartered and checks the metric of
every finding at the three levels with
:func:`workbench.sim.convergence.refinement_check`; :func:`claim_tolerance`
says what tolerance the Richardson estimate must stay below. A finding
whose metric has not converged is INCONCLUSIVE (:mod:`workbench.verify`).

The control period and every other design variable stay as designed: only
the integration step is refined.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from .claims import Claim, ClaimResult
from .memo import run_study
from .report.markdown import fmt
from .sim.convergence import (CONVERGED, INCONCLUSIVE, NOT_CONVERGED, P_MAX, P_MIN,
                              Refinement, refinement_check)

__all__ = ["LEVELS", "Levels", "RefinementRow", "RefinementTable", "claim_tolerance",
           "ROUNDING", "guarded_check", "refine_findings", "refinement_row", "screen"]

#: Differences at or below this times the largest |value| are rounding noise
#: (the default floor of :func:`~workbench.sim.convergence.refinement_check`).
ROUNDING = 64 * 2.0 ** -52

#: Refinement levels: the step divided by 2**k.
LEVELS = (0, 1, 2)


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

