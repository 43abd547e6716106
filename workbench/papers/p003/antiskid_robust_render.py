"""Markdown and figure of the ``antiskid-robust`` study (pure rendering): paper
003's problem and requirements wording. The robust gain's section, the
compared gains and the eps figure are
:func:`workbench.kinds.delay_feedback.robust_points_render.robust_points_sections`."""
from __future__ import annotations

from ...features.robust_gain_render import robust_method_text
from ...kinds.delay_feedback.robust_points_render import robust_points_sections
from ...report.markdown import Rendered, fmt, md_table


def _requirements(spec, res) -> str:
    """The requirements section (issue 31) that opens the report."""
    from ...kinds.delay_feedback.requirements_render import requirements_rows
    r, q = res.requirements, spec.requirements
    return ("## Requirements\n\nOne gain for every operating point below, designed to "
            f"requirements: objective **{q.objective}**, every constant delay in "
            f"[{fmt(q.delay[0])}, {fmt(q.delay[1])}] s "
            "(`workbench/requirements.py`: exponentially weighted descriptor synthesis, the "
            "rounded gain's decay certified by Bessel-Legendre cells over the range, exact "
            "rightmost roots on a delay grid).\n\n"
            + requirements_rows(q, r, spec.settings.gain_digits)
            + "\n\nThe sections below are the earlier *largest certified delay* synthesis "
            "(maximise h at a decay rate certified at h only), kept as a comparison: its gain "
            "has almost no creep feedback.")


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
    if res.requirements is not None:
        prob = _requirements(design.spec, res) + "\n\n" + prob
    sections, figs = robust_points_sections(res, "robust K (this design)")
    return Rendered((prob, *sections), figs)
