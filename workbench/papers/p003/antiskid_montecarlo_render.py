"""Rendering of the Monte Carlo sweep and its step-halving check (pure): the
paper's words, units and figures; the tables (summary, outcome rates,
step-halving), rates and histograms are :mod:`workbench.features.montecarlo_render`."""
from __future__ import annotations

import numpy as np

from ...features.montecarlo_halving import HalvingCheck
from ...features.montecarlo_render import draw_histograms as general_histograms
from ...features.montecarlo_render import draw_rates  # noqa: F401  (the report's figure)
from ...features.montecarlo_render import halving_tables
from ...features.montecarlo_render import summary_tables as general_tables
from ...report.markdown import fmt
from .antiskid_halving import HALVING_METRICS, HALVING_OUTCOMES
from .antiskid_montecarlo import SUMMARY_METRICS, VIOLATIONS, SweepResult


#: Column labels of the draws in :func:`halving_section`.
_DRAW_LABELS = (("mass", "mass factor"), ("adhesion", "adhesion s"), ("h", "h (s)"),
                ("v0", "v(0) (m/s)"))


def refined_runs_text(n: int, big: int | None) -> str:
    """What the three-level refinement of the Monte Carlo findings covers
    when only the first ``n`` of ``big`` runs are run at dt/2 and dt/4
    (:func:`workbench.features.refinement.share_claim_levels`; empty
    when every run is)."""
    if big is None or n >= big:
        return ""
    return (f" **Refinement of the Monte Carlo findings.** A finding on the share of an "
            f"outcome is checked at the sweep's dt (all {big} runs), dt / 2 (the first {n}: "
            f"this check) and dt / 4 (the first {n} once more; see the refinement of the "
            f"findings). The other {big - n} runs are not run at dt / 2 and dt / 4 but bounded: "
            f"if k of the first {n} have the outcome there, between k and k + {big - n} of the "
            f"{big} runs have it, whatever the others do. A level decides a finding when its "
            f"verdict is the same at every count of that range; the finding has converged "
            f"when dt, dt / 2 and dt / 4 decide it the same way, and is INCONCLUSIVE otherwise "
            f"(the refinement table shows each level's count and verdict). A claim that no "
            f"run has the outcome is decided by one refined run that has it at every level; a "
            f"bound on the rate (a Wilson interval's end) may need more of the {big} runs than "
            f"the {n} refined, and is then INCONCLUSIVE.")


def halving_section(hc: HalvingCheck, spec=None, sig: int = 3) -> str:
    """Markdown (no heading) of a :class:`HalvingCheck`: what was done, a
    row per metric (runs finite at both steps, runs that agree, largest
    |difference| over the runs finite at both), a row per outcome, and the
    disagreeing runs (``sig`` significant digits for their values).
    ``spec``: the design's ``RunSpec``, for the size of the sweep (optional;
    the tolerances are the check's own)."""
    n, k = hc.n, sum(hc.run_agree)
    of = "the sweep's runs" if spec is None or spec.montecarlo is None else \
        f"the sweep's {spec.montecarlo.samples} runs"
    tol = ", ".join(f"`{m}` {fmt(a)}" for m, a in hc.atol.items() if a > 0) or "none"
    text = (f"The first {n} of {of} (seed {hc.seed}, case `{hc.case}`, the same draws), "
            f"run at the sweep's dt = {fmt(hc.dt)} s, were simulated again as one batch at "
            f"dt / 2 (each run of a batch follows its single-run trajectory, so a run's "
            f"values do not depend on its chunk). A metric agrees when "
            f"|a − b| <= atol + rtol max(|a|, |b|), rtol = {fmt(hc.rtol)}, atol: {tol} "
            f"(else 0); two missing values agree, a missing and a finite one do not; "
            f"`lam_max_over_opt` is not compared for a run that diverged in traction at "
            f"either step. An outcome agrees when it is the same at both steps. "
            f"**{k} of {n} runs agree in every metric and outcome.**")
    text += refined_runs_text(n, None if spec is None or spec.montecarlo is None else
                              spec.montecarlo.samples) + "\n\n"
    labels = tuple(("delay_period", "h(t) period (s)") if d == "h" and "delay_period" in hc.draws
                   else (d, lab) for d, lab in _DRAW_LABELS)    # the h draw unused then
    return text + halving_tables(hc, HALVING_METRICS, HALVING_OUTCOMES, labels, sig)


def draw_histograms(fig, res: SweepResult) -> None:
    """Histograms of the summary metrics, lambda_opt marked (pure)."""
    general_histograms(fig, res, {k: "-" if k == "lam_max_over_opt" else "s"
                                  for k in SUMMARY_METRICS},
                       {"lam_max_over_opt": (1.0, "lambda_opt")})


def draw_outcomes(fig, res: SweepResult) -> None:
    """Each run at its (adhesion s, true delay h) and (mass factor, v0),
    marked by its outcome: stopped, diverged, or neither, with the count of
    each in the legend; a diverged run is coloured by the time it diverged
    (colour bar), so that a sweep where every run diverges still shows where
    the draws make it diverge early or late (pure)."""
    d = {k: np.asarray(v, float) for k, v in res.samples.items()}
    t_div = np.asarray(res.metrics.get("t_diverged", [np.nan] * res.n), float)
    div = np.asarray(res.violations["diverged"], bool)
    stuck = np.asarray(res.violations["not_stopped"], bool) & ~div
    groups = (("stopped", ~div & ~stuck, "tab:blue", "o"),
              ("diverged", div, "tab:red", "x"),
              ("not stopped, not diverged", stuck, "tab:gray", "s"))
    delay = (("delay_period", "period of the varying delay h(t) (s)") if "delay_period" in d
             else ("h", "true input delay h (s)"))
    for ax, (kx, ky, lx, ly) in zip(fig.subplots(1, 2), (
            ("adhesion", delay[0], "adhesion s (0 wet, 1 dry)", delay[1]),
            ("mass", "v0", "plant mass / nominal", "v(0) (m/s)"))):
        for label, sel, color, marker in groups:
            if not sel.any():
                continue
            if label == "diverged" and np.isfinite(t_div[sel]).all():
                sc = ax.scatter(d[kx][sel], d[ky][sel], s=16, c=t_div[sel], cmap="plasma",
                                marker=marker, label=f"{label}: {int(sel.sum())} of {res.n}")
                fig.colorbar(sc, ax=ax, label="diverged at t (s)")
            else:
                ax.scatter(d[kx][sel], d[ky][sel], s=14, c=color, marker=marker,
                           label=f"{label}: {int(sel.sum())} of {res.n}")
        ax.set_xlabel(lx)
        ax.set_ylabel(ly)
    fig.axes[0].legend(fontsize=7)


def summary_tables(res: SweepResult, sig: int) -> str:
    """Markdown: the summary statistics and the violation fractions (``sig``
    significant digits), as printed by ``workbench sweep`` and in reports."""
    return general_tables(res, sig, {**VIOLATIONS, "ok": "ok: none of the above"})
