"""Rendering of the Monte Carlo sweep and its step-halving check (pure): the
paper's words, units and figures; the tables (summary, outcome rates,
step-halving), the text of the check, rates, histograms and the scatter of
the runs are :mod:`workbench.features.montecarlo_render`. What stays here is
paper 003's: the labels of the antiskid draws and outcomes, lambda_opt on
the histogram of `lam_max_over_opt`, the time a run diverged as its
colour."""
from __future__ import annotations

import numpy as np

from ...features.montecarlo_halving import HalvingCheck
from ...features.montecarlo_render import draw_histograms as general_histograms
from ...features.montecarlo_render import draw_outcome_scatter
from ...features.montecarlo_render import halving_section as general_halving_section
from ...features.montecarlo_render import summary_tables as general_tables
from .antiskid_halving import HALVING_METRICS, HALVING_OUTCOMES
from .antiskid_montecarlo import SUMMARY_METRICS, VIOLATIONS, SweepResult


#: Column labels of the draws in :func:`halving_section`.
_DRAW_LABELS = (("mass", "mass factor"), ("adhesion", "adhesion s"), ("h", "h (s)"),
                ("v0", "v(0) (m/s)"))


def halving_section(hc: HalvingCheck, spec=None, sig: int = 3) -> str:
    """Markdown (no heading) of a :class:`HalvingCheck` of the antiskid
    sweep (:func:`workbench.features.montecarlo_render.halving_section`).
    ``spec``: the design's ``RunSpec``, for the size of the sweep (optional;
    the tolerances are the check's own)."""
    labels = tuple(("delay_period", "h(t) period (s)") if d == "h" and "delay_period" in hc.draws
                   else (d, lab) for d, lab in _DRAW_LABELS)    # the h draw unused then
    return general_halving_section(
        hc, HALVING_METRICS, HALVING_OUTCOMES, labels,
        None if spec is None or spec.montecarlo is None else spec.montecarlo.samples,
        " (each run of a batch follows its single-run trajectory, so a run's values do not "
        "depend on its chunk)",
        "; `lam_max_over_opt` is not compared for a run that diverged in traction at either "
        "step", sig)


def draw_histograms(fig, res: SweepResult) -> None:
    """Histograms of the summary metrics, lambda_opt marked (pure)."""
    general_histograms(fig, res, {k: "-" if k == "lam_max_over_opt" else "s"
                                  for k in SUMMARY_METRICS},
                       {"lam_max_over_opt": (1.0, "lambda_opt")})


def draw_outcomes(fig, res: SweepResult) -> None:
    """Each run at its (adhesion s, true delay h) and (mass factor, v0),
    marked by its outcome: stopped, diverged, or neither; a diverged run is
    coloured by the time it diverged (pure;
    :func:`workbench.features.montecarlo_render.draw_outcome_scatter`)."""
    t_div = np.asarray(res.metrics.get("t_diverged", [np.nan] * res.n), float)
    div = np.asarray(res.violations["diverged"], bool)
    stuck = np.asarray(res.violations["not_stopped"], bool) & ~div
    delay = (("delay_period", "period of the varying delay h(t) (s)")
             if "delay_period" in res.samples else ("h", "true input delay h (s)"))
    draw_outcome_scatter(
        fig, res.samples, (("adhesion", delay[0], "adhesion s (0 wet, 1 dry)", delay[1]),
                           ("mass", "v0", "plant mass / nominal", "v(0) (m/s)")),
        (("stopped", ~div & ~stuck, "tab:blue", "o"), ("diverged", div, "tab:red", "x"),
         ("not stopped, not diverged", stuck, "tab:gray", "s")),
        res.n, ("diverged", t_div, "diverged at t (s)"))


def summary_tables(res: SweepResult, sig: int) -> str:
    """Markdown: the summary statistics and the violation fractions (``sig``
    significant digits), as printed by ``workbench sweep`` and in reports."""
    return general_tables(res, sig, {**VIOLATIONS, "ok": "ok: none of the above"})
