"""Step-size check of an ``antiskid-run`` design's Monte Carlo runs.

:func:`start_halving` simulates the first n runs of the sweep (the same
draws) as one batch at the design's dt and as one batch at dt / 2, and
compares their metrics and outcomes per run with the design's convergence
tolerances (:class:`~workbench.features.montecarlo_halving.HalvingCheck`;
rendered by :func:`workbench.papers.p003.antiskid_montecarlo_render.halving_section`).
The batches and the check are the general
:func:`workbench.features.montecarlo_halving.start_halving` and the comparison
the general :func:`workbench.features.convergence.compare_steps`; this module
keeps what is paper 003's: which metrics and outcomes of its kernel's runs are
compared and the traction-divergence rule; its batches are the sweep's own
chunk function (:func:`~workbench.papers.p003.antiskid_montecarlo.range_worker`)
at the two steps.
"""
from __future__ import annotations

from functools import partial

import numpy as np

from ...features.montecarlo_halving import HalvingCheck
from ...features.montecarlo_halving import halving_quantity_names as general_names
from ...features.montecarlo_halving import start_halving as start_batches
from ...sim.batch import PendingBatch
from .antiskid_montecarlo import SUMMARY_METRICS, range_runs, range_worker, sweep_inputs
from .antiskid_run_spec import SweepSpec

#: Metrics compared at dt and dt / 2 by :func:`start_halving`.
HALVING_METRICS = SUMMARY_METRICS + ("t_diverged",)

#: Outcomes compared (as booleans) at dt and dt / 2.
HALVING_OUTCOMES = ("diverged", "stopped", "above_lambda_opt")

#: The prefix of the check's quantities.
PREFIX = "montecarlo.halving"


def compare_steps(coarse: dict, fine: dict, rtol: float, atol: dict) -> tuple[dict, dict, dict]:
    """Compare per-run values at dt (``coarse``) and dt / 2 (``fine``).

    Parameters
    ----------
    coarse, fine : dict
        :data:`HALVING_METRICS` -> floats per run, :data:`HALVING_OUTCOMES`
        -> bools per run, and ``phase_diverged`` (phase index where the run
        diverged, NaN if it did not).
    rtol : float
    atol : dict
        Metric -> absolute tolerance (missing: 0).

    Returns
    -------
    (coarse, fine, agree) : dict, dict, dict
        Values (tuples per run) and agree flags, by the general comparison
        :func:`workbench.features.convergence.compare_steps` (a metric by
        :func:`~workbench.features.convergence.agree`: both NaN agree, one
        NaN disagrees; an outcome when it is equal). Paper-specific:
        ``lam_max_over_opt`` is masked (not compared) for a run that
        diverged in a traction phase (``phase_diverged`` < BRAKE_IN) at
        either step: its maximum there is where the divergence test fired,
        as for the nominal cases
        (:func:`~workbench.papers.p003.antiskid_run.case_metrics`).
    """
    from ...controllers.antiskid003_settings import BRAKE_IN
    from ...features.convergence import compare_steps as compare
    traction = (np.asarray(coarse["phase_diverged"], float) < BRAKE_IN) | (
        np.asarray(fine["phase_diverged"], float) < BRAKE_IN)
    return compare(coarse, fine, rtol, atol, HALVING_METRICS, HALVING_OUTCOMES,
                   masked={"lam_max_over_opt": traction})


def _step_values(metrics: dict, viol: dict) -> dict:
    """Per-run metrics and outcomes of one step, as :func:`compare_steps` takes them."""
    return {**metrics, **viol, "stopped": ~np.asarray(viol["not_stopped"], bool)}


def start_halving(design, n: int, *, K: tuple | None = None, pool: bool = True,
                  coarse: bool = True, kernel: str | None = None) -> PendingBatch:
    """Start the step-halving check of the first ``n`` runs of an
    ``antiskid-run`` design's sweep (its ``[montecarlo]`` seed and draws):
    the general :func:`~workbench.features.montecarlo_halving.start_halving`
    on this paper's kernel batches. ``result()`` returns the
    :class:`~workbench.features.montecarlo_halving.HalvingCheck` (``atol`` 0
    where the design gives none), or with ``coarse=False`` a function of the
    sweep's :class:`SweepResult` that makes it. ``K``: as
    :func:`~workbench.papers.p003.antiskid_montecarlo.start_sweep`; ``kernel``: as
    there (default: compiled when numba is installed).
    """
    from .antiskid_kernel import default_kernel
    from .antiskid_run_spec import gain_for
    kernel = kernel or default_kernel()
    spec = design.spec
    ms: SweepSpec = spec.montecarlo
    if not n >= 1:
        raise ValueError(f"halving check of {n} runs: need at least 1")
    K = tuple(gain_for(spec)[0] if K is None else K)
    inp = sweep_inputs(design, n, ms.seed, K)
    atol = {k: spec.conv_atol.get(k, 0.0) for k in HALVING_METRICS}

    def check(at_dt: dict, at_half: dict, seconds: float, n_workers: int) -> HalvingCheck:
        c, f, agree = compare_steps(at_dt, at_half, spec.conv_rtol, atol)
        return HalvingCheck(inp["dt"], spec.conv_rtol, atol, c, f, agree, ms.case, ms.seed,
                            {k: tuple(v.tolist()) for k, v in inp["draws"].items()},
                            seconds, n_workers)

    return start_batches(range_worker, lambda step: {"design": design, "K": K, "seed": ms.seed,
                                                     "i0": 0, "i1": n, "kernel": kernel,
                                                     "step": step},
                         lambda out: range_runs(out, spec.scenario["t_brake"]), _step_values,
                         check, inp["dt"], n, coarse=coarse, pool=pool)


#: Quantities of the check under :data:`PREFIX`: runs checked, runs whose every
#: metric and outcome agrees, and their fraction (:meth:`StepComparison.quantities`).
halving_quantity_names = partial(general_names, PREFIX)
halving_quantities = partial(HalvingCheck.quantities, prefix=PREFIX)
