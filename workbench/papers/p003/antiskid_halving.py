"""Step-size check of an ``antiskid-run`` design's Monte Carlo runs.

:func:`start_halving` simulates the first n runs of the sweep (the same
draws) as one batch at the design's dt and as one batch at dt / 2, and
compares their metrics and outcomes per run with the design's convergence
tolerances (:class:`~workbench.features.montecarlo_halving.HalvingCheck`;
rendered by :data:`workbench.papers.p003.antiskid_montecarlo_render.WORDS`).
The batches and the check are the general
:func:`workbench.features.montecarlo_halving.start_halving` and the comparison
:class:`~workbench.features.montecarlo_halving.Compared`; this module
keeps what is paper 003's: which metrics and outcomes of its kernel's runs are
compared and the traction-divergence rule; its batches are the sweep's own
chunk function (:func:`~workbench.papers.p003.antiskid_montecarlo.range_worker`)
at the two steps.
"""
from __future__ import annotations

import numpy as np

from ...features.montecarlo_halving import Compared, halving_quantities
from ...features.montecarlo_halving import start_halving as start_batches
from ...features.quantities import Part
from ...sim.batch import PendingBatch
from .antiskid_montecarlo import RUNS, SUMMARY_METRICS, draw_samples, range_payload, range_worker


def _in_traction(coarse: dict, fine: dict) -> dict:
    """Paper-specific: ``lam_max_over_opt`` is not compared for a run that
    diverged in a traction phase (``phase_diverged`` < BRAKE_IN, NaN: did
    not diverge) at either step: its maximum there is where the divergence
    test fired, as for the nominal cases
    (:func:`~workbench.papers.p003.antiskid_run.case_metrics`)."""
    from ...controllers.antiskid003_settings import BRAKE_IN
    return {"lam_max_over_opt": (np.asarray(coarse["phase_diverged"], float) < BRAKE_IN) | (
        np.asarray(fine["phase_diverged"], float) < BRAKE_IN)}


#: Metrics compared at dt and dt / 2 by :func:`start_halving`.
HALVING_METRICS = SUMMARY_METRICS + ("t_diverged",)
#: Outcomes compared (as booleans) at dt and dt / 2.
HALVING_OUTCOMES = ("diverged", "stopped", "above_lambda_opt")
#: The comparison (``COMPARED.compare(coarse, fine, rtol, atol)`` of per-run
#: values with ``phase_diverged``).
COMPARED = Compared(HALVING_METRICS, HALVING_OUTCOMES, _in_traction)


def _step_values(metrics: dict, viol: dict) -> dict:
    """Per-run metrics and outcomes of one step, as :data:`COMPARED` takes them."""
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
    spec, ms = design.spec, design.spec.montecarlo
    payload = range_payload(design, ms.seed, K, kernel)[2]
    return start_batches(range_worker, lambda step: payload(0, n, step),
                         lambda out: RUNS.runs(out, spec.scenario["t_brake"]), _step_values,
                         COMPARED, ms.dt or spec.dt, n, rtol=spec.conv_rtol,
                         atol=spec.conv_atol, case=ms.case, seed=ms.seed,
                         draws=draw_samples(n, ms.seed, ms), coarse=coarse, pool=pool)


#: The check's quantities (``montecarlo.halving.runs``, ``.agree``, ``.fraction_agree``).
QUANTITIES = (Part(halving_quantities("montecarlo.halving"), lambda spec: (
    spec.montecarlo is not None and bool(spec.montecarlo.halving)), lambda r: r.halving),)
