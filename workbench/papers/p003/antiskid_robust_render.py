"""Markdown and figure of the ``antiskid-robust`` study (pure rendering): paper
003's problem wording and its note on the gain designed to requirements; the
rest is :func:`workbench.kinds.delay_feedback.robust_points_render.robust_points_report`
(requirements, robust gain, compared gains, eps figure)."""
from __future__ import annotations

from ...features.robust_gain_render import robust_method_text
from ...kinds.delay_feedback.robust_points_render import robust_points_report
from ...report.markdown import Rendered, fmt, md_table


def render(design, res) -> Rendered:
    rg, pts = res.robust, res.spec.points
    prob = ("## Problem\n\nOne state-feedback gain K for the cruise error system "
            "E' = A_i E + B_i K E(t - h) of paper 003 (eq 32) at every operating point i below "
            f"(rail x cruise speed x mass factor; {len(pts)} points, each linearised at its own "
            "solved lambda_d), with exponential decay rate "
            f"alpha = {fmt(rg.settings.alpha)} 1/s certified at the delay h (stability for every "
            "constant delay in [0, h] and beyond follows from the exact margins below). "
            + robust_method_text(rg.settings) + "\n\n"
            + md_table(["point", "rail", "v_d (m/s)", "mass factor", "lambda_d"],
                       [[f"`{p.id}`", p.rail, fmt(p.v_d), fmt(p.mass_factor), fmt(p.lambda_d, 4)]
                        for p in pts], "llrrr"))
    return robust_points_report(res, prob, "robust K (this design)", (
        "The sections below are the earlier *largest certified delay* synthesis (maximise h "
        "at a decay rate certified at h only), kept as a comparison: its gain has almost no "
        "creep feedback."))
