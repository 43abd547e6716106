"""The antiskid sweep's words for the general Monte Carlo rendering
(:class:`workbench.features.montecarlo_render.SweepWords`: the summary,
outcome-rate and step-halving tables, histograms and the scatter of the
runs). What stays here is paper 003's: the labels of the antiskid draws and
outcomes, lambda_opt on the histogram of `lam_max_over_opt`, the time a run
diverged as its colour, the varying delay's period in place of the h draw."""
from __future__ import annotations

from ...features.montecarlo_render import SweepWords
from .antiskid_halving import HALVING_METRICS, HALVING_OUTCOMES
from .antiskid_montecarlo import SUMMARY_METRICS, VIOLATIONS

#: The antiskid sweep's tables and figures (``WORDS.tables(res, sig)`` is what
#: ``workbench sweep`` prints and the report shows).
WORDS = SweepWords(
    outcomes={**VIOLATIONS, "ok": "ok: none of the above"},
    units={k: "-" if k == "lam_max_over_opt" else "s" for k in SUMMARY_METRICS},
    marks={"lam_max_over_opt": (1.0, "lambda_opt")},
    halving_metrics=HALVING_METRICS, halving_outcomes=HALVING_OUTCOMES,
    draws=(("mass", "mass factor"), ("adhesion", "adhesion s"), ("h", "h (s)"),
           ("v0", "v(0) (m/s)")),
    batch_note=" (each run of a batch follows its single-run trajectory, so a run's values "
               "do not depend on its chunk)",
    not_compared="; `lam_max_over_opt` is not compared for a run that diverged in traction "
                 "at either step",
    panels=(("adhesion", "h", "adhesion s (0 wet, 1 dry)", "true input delay h (s)"),
            ("mass", "v0", "plant mass / nominal", "v(0) (m/s)")),
    groups=(("stopped", (), ("diverged", "not_stopped"), "tab:blue", "o"),
            ("diverged", ("diverged",), (), "tab:red", "x"),
            ("not stopped, not diverged", ("not_stopped",), ("diverged",), "tab:gray", "s")),
    shade=("diverged", "t_diverged", "diverged at t (s)"),
    # with a varying delay h(t) the constant h draw is not used
    alternates={"h": ("delay_period", "h(t) period (s)", "period of the varying delay h(t) (s)")})
