"""The step-size check of a Monte Carlo sweep's runs (issue 35): the first n
runs of a sweep (the same draws) simulated again as one batch at dt / 2 and
compared, run by run, with the same runs at the sweep's dt.

Nothing here knows what a run is. A study gives the batch run function
(payload -> output, module-level when it runs in a pool), the payload of the
first n runs at a step, how a batch's output becomes per-run metrics and
outcome flags (as :class:`~workbench.features.montecarlo_stats.RunsResult`
holds them), which of them are compared, and the comparison itself
(typically :func:`workbench.features.convergence.compare_steps`, with the
study's own rules). The dt side is either run here too or taken from the
sweep's first n runs (each run of a batch follows its single-run trajectory,
so a run's values do not depend on its chunk). :func:`sweep_share_levels`
refines a finding on the share of a sweep's runs with an outcome over the
sweep's runs at dt and the first n at dt/2 and dt/4.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from .convergence import StepComparison

__all__ = ["HalvingCheck", "halving_quantity_names", "start_halving", "sweep_share_levels"]


@dataclass(frozen=True)
class HalvingCheck(StepComparison):
    """The first ``n`` runs of a sweep at dt and at dt / 2: the general
    :class:`~workbench.features.convergence.StepComparison`, and the sweep's
    ``case`` (what its runs simulate), ``seed`` and ``draws`` (sample name ->
    tuple of the n draws); ``seconds`` (wall time) and ``workers``
    (processes) are not compared."""

    case: str
    seed: int
    draws: dict
    seconds: float = field(default=math.nan, compare=False)
    workers: int = field(default=1, compare=False)


def start_halving(run: Callable, payload_at: Callable, runs_of: Callable, values: Callable,
                  check: Callable, dt: float, n: int, *, coarse: bool = True,
                  pool: bool = True):
    """Start the step-halving check of the first ``n`` runs of a sweep.

    Parameters
    ----------
    run : callable
        ``run(payload) -> output``: one batch of runs.
    payload_at : callable
        ``payload_at(step)``: the payload of the first n runs at that step.
    runs_of : callable
        ``runs_of(output) -> (metrics, violations)``: per-run metric and flag
        arrays of a batch.
    values : callable
        ``values(metrics, violations) -> dict``: the per-run values compared.
    check : callable
        ``check(at_dt, at_half, seconds, workers)``: the result (e.g. a
        :class:`HalvingCheck`) of the values at the two steps.
    dt : float
        The sweep's step.
    n : int
    coarse : bool
        Run the dt batch too; else ``result()`` returns a function of the
        sweep's :class:`~workbench.features.montecarlo_stats.RunsResult`,
        whose first n runs are the dt side.
    pool : bool
        Run the batches in a process pool now (the caller can work
        meanwhile), else in-process in ``result()``.

    Returns
    -------
    workbench.sim.batch.PendingBatch
    """
    from ..sim.batch import PendingBatch
    payloads = ([payload_at(dt)] if coarse else []) + [payload_at(dt / 2)]

    def collect(outs: list, seconds: float, n_workers: int):
        steps = [values(*runs_of(o)) for o in outs]
        if coarse:
            return check(*steps, seconds, n_workers)

        def with_sweep(res):
            if res.n < n:
                raise ValueError(f"the sweep has {res.n} runs; the check needs its first {n}")
            first = values({k: v[:n] for k, v in res.metrics.items()},
                           {k: v[:n] for k, v in res.violations.items()})
            return check(first, steps[0], seconds, n_workers)
        return with_sweep

    return PendingBatch(run, payloads, collect, len(payloads) if pool else 1, pool)


def halving_quantity_names(prefix: str) -> set[str]:
    """Quantities of a check's :meth:`StepComparison.quantities` under
    ``prefix``: runs checked, runs whose every metric and outcome agrees,
    and their fraction."""
    return {f"{prefix}.runs", f"{prefix}.agree", f"{prefix}.fraction_agree"}


def sweep_share_levels(finding, at_dt: Callable, check, outcomes: dict, at_quarter: Callable,
                       prefix: str):
    """A finding on the share of a sweep's runs with an outcome at the
    sweep's dt, dt/2 and dt/4: all N runs at dt (``at_dt(outcome)``: its N
    flags, e.g. of the sweep's
    :class:`~workbench.features.montecarlo_stats.RunsResult`), the first n
    at dt/2 (``check``, the :class:`HalvingCheck`; None: the design has
    none) and at dt/4 (``at_quarter()``: outcome -> n bools, called only
    when needed), by
    :func:`workbench.features.refinement.share_claim_levels`.

    ``outcomes``: share quantity -> the outcome behind it (a flag of the
    sweep and of the check); ``prefix``: of the sweep's quantities (its
    ``<prefix>.halving.fraction_agree`` compares two steps and is not
    refined; the levels are named ``<prefix>.dt``).
    """
    from .refinement import Levels, share_claim_levels
    qn = finding.claim.quantity
    if check is None:
        return Levels((), reason="the design has no step check of its Monte Carlo runs")
    if qn == f"{prefix}.halving.fraction_agree":
        return Levels((), reason="a comparison of two steps, not a metric of the runs; the "
                      "outcomes behind the Monte Carlo findings are refined three levels in "
                      "the rows of the share findings (first runs at dt, dt/2, dt/4)")
    key = outcomes[qn]
    return share_claim_levels(finding.claim, at_dt(key), check.fine[key],
                              at_quarter()[key], key.replace("_", " "), f"{prefix}.dt", check.dt)
