"""The step-size check of a Monte Carlo sweep's runs (issue 35): the first n
runs of a sweep (the same draws) simulated again as one batch at dt / 2 and
compared, run by run, with the same runs at the sweep's dt.

Nothing here knows what a run is. A study gives the batch run function
(payload -> output, module-level when it runs in a pool), the payload of the
first n runs at a step, how a batch's output becomes per-run metrics and
outcome flags (as :class:`~workbench.features.montecarlo_stats.RunsResult`
holds them) and which of them are compared, with the study's own rule of
what is not compared (:class:`Compared`, by
:func:`workbench.features.convergence.compare_steps`). The dt side is either
run here too or taken from the sweep's first n runs (each run of a batch follows its single-run trajectory,
so a run's values do not depend on its chunk). :func:`sweep_share_levels`
refines a finding on the share of a sweep's runs with an outcome over the
sweep's runs at dt and the first n at dt/2 and dt/4.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from .convergence import StepComparison, compare_steps

__all__ = ["Compared", "HalvingCheck", "halving_quantities", "start_halving",
           "sweep_share_levels"]


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


@dataclass(frozen=True)
class Compared:
    """What a study compares per run at dt and dt / 2: ``metrics`` (numbers)
    and ``outcomes`` (flags); ``masked(coarse, fine)`` -> metric -> per-run
    flags of the runs whose metric is not compared (e.g. a value a run did
    not determine at one step; default: none)."""

    metrics: tuple
    outcomes: tuple
    masked: Callable = lambda coarse, fine: {}

    def compare(self, coarse: dict, fine: dict, rtol: float, atol: dict) -> tuple:
        """(coarse, fine, agree) of
        :func:`workbench.features.convergence.compare_steps` on these names."""
        return compare_steps(coarse, fine, rtol, atol, self.metrics, self.outcomes,
                             self.masked(coarse, fine))


def start_halving(run: Callable, payload_at: Callable, runs_of: Callable, values: Callable,
                  compared: Compared, dt: float, n: int, *, rtol: float, atol: dict,
                  case: str, seed: int, draws: dict, coarse: bool = True, pool: bool = True):
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
    compared : Compared
        The names compared and the study's mask.
    dt : float
        The sweep's step.
    n : int
    rtol : float
    atol : dict
        Metric -> absolute tolerance (missing: 0).
    case, seed, draws
        As :class:`HalvingCheck` (``draws``: name -> the n runs' draws).
    coarse : bool
        Run the dt batch too; else ``result()`` returns a function of the
        sweep's :class:`~workbench.features.montecarlo_stats.RunsResult`,
        whose first n runs are the dt side.
    pool : bool
        Run the batches in a process pool now (the caller can work
        meanwhile), else in-process in ``result()``.

    Raises
    ------
    ValueError
        ``n`` < 1.

    Returns
    -------
    workbench.sim.batch.PendingBatch
        ``result()``: the :class:`HalvingCheck`, or with ``coarse=False``
        a function of the sweep's result that makes it.
    """
    from ..sim.batch import PendingBatch
    if not n >= 1:
        raise ValueError(f"halving check of {n} runs: need at least 1")
    payloads = ([payload_at(dt)] if coarse else []) + [payload_at(dt / 2)]
    atol = {k: atol.get(k, 0.0) for k in compared.metrics}
    draws = {k: tuple(v.tolist()) for k, v in draws.items()}

    def check(at_dt: dict, at_half: dict, seconds: float, n_workers: int) -> HalvingCheck:
        return HalvingCheck(dt, rtol, atol, *compared.compare(at_dt, at_half, rtol, atol), case,
                            seed, draws, seconds, n_workers)

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


def halving_quantities(prefix: str) -> tuple:
    """The check's quantities, declared once
    (:class:`~workbench.features.quantities.Declared`, reading a
    :class:`HalvingCheck`; a study puts them in a
    :class:`~workbench.features.quantities.Part` of its result):
    ``<prefix>.runs`` (runs checked), ``.agree`` (runs whose every metric
    and outcome agrees) and ``.fraction_agree``
    (:meth:`~workbench.features.convergence.StepComparison.quantities`)."""
    from .quantities import Declared
    return (Declared(prefix + ".{q}", "1", lambda hc, q: hc.quantities(prefix)[f"{prefix}.{q}"],
                     over=lambda spec: [{"q": q} for q in ("runs", "agree", "fraction_agree")]),)


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
