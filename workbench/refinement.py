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
from .sim.convergence import (CONVERGED, NOT_CONVERGED, P_MAX, P_MIN, Refinement,
                              refinement_check)

__all__ = ["LEVELS", "RefinementRow", "RefinementTable", "claim_tolerance", "refine_findings"]

#: Refinement levels: the step divided by 2**k.
LEVELS = (0, 1, 2)


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


def _row(c: Claim, values: tuple, field: str, got) -> RefinementRow:
    tol = claim_tolerance(c, got)
    levels = f"{field}, {field}/2, {field}/4"
    instead = (f"`{c.converged_instead}`" if c.converged_instead else
               "a quantity that converges (the claim's `converged_instead`)")
    if tol is None or not all(isinstance(x, (int, float)) for x in values):
        same = len({str(x) for x in values}) == 1
        return RefinementRow(c.id, c.quantity, values, None, CONVERGED if same else NOT_CONVERGED,
                             None, "" if same else f"not converged: {c.quantity} is "
                             f"{' / '.join(str(x) for x in values)} at {levels}; "
                             f"use {instead} instead")
    if not all(math.isfinite(float(x)) for x in values) and len(set(values)) == 1:
        return RefinementRow(c.id, c.quantity, values, tol, CONVERGED)
    r = refinement_check(*values, tolerance=tol)
    shown = ", ".join(fmt(x, 5) for x in values)
    if r.outcome == CONVERGED:
        reason = ""
    elif r.outcome == NOT_CONVERGED:
        reason = (f"not converged: {c.quantity} estimate {fmt(r.estimate, 2)} > tolerance "
                  f"{fmt(tol, 2)} ({shown} at {levels}, observed order {fmt(r.order, 2)}); "
                  f"use {instead} instead")
    else:
        reason = (f"not converged: {c.quantity} {r.note} ({shown} at {levels}); "
                  f"use {instead} instead")
    return RefinementRow(c.id, c.quantity, values, tol, r.outcome, r, reason)


def refine_findings(design, study, quantities: dict,
                    checked: list[ClaimResult]) -> RefinementTable:
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
