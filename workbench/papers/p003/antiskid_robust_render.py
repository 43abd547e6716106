"""Markdown and figure of the ``antiskid-robust`` study (pure rendering); the
per-point and compared-gain tables are :mod:`workbench.features.point_gains`'."""
from __future__ import annotations

import math

import numpy as np

from ...features.point_gains import compare_section, point_table
from ...report.markdown import Figure, Rendered, fmt, latex_matrix, md_table


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
            + requirements_rows(q, r, spec.gain_digits)
            + "\n\nThe sections below are the earlier *largest certified delay* synthesis "
            "(maximise h at a decay rate certified at h only), kept as a comparison: its gain "
            "has almost no creep feedback.")


def render(design, res) -> Rendered:
    syn = res.synthesis
    h = syn.bracket.h_certified
    pts = res.points
    prob = ("## Problem\n\nOne state-feedback gain K for the cruise error system "
            "E' = A_i E + B_i K E(t - h) of paper 003 (eq 32) at every operating point i below "
            f"(rail x cruise speed x mass factor; {len(pts)} points, each linearised at its own "
            "solved lambda_d), with exponential decay rate "
            f"alpha = {fmt(res.alpha)} 1/s certified at the delay h (stability for every "
            "constant delay in [0, h] and beyond follows from the exact margins below). "
            "Synthesis: descriptor method with the Jensen inequality, slack P3 = eps P2, "
            "common Y and V (K = V Y^{-1}), Lyapunov-Krasovskii matrices per point "
            "(`workbench.lmi.robust.DescriptorSynthesis`); eps searched automatically "
            "(log grid, then golden section). The certificate holds at the listed points, not "
            "in between. Each gain is then re-checked per point by the exact margin and the "
            f"Bessel-Legendre analysis of order {res.order}.\n\n"
            + md_table(["point", "rail", "v_d (m/s)", "mass factor", "lambda_d"],
                       [[f"`{p.id}`", p.rail, fmt(p.v_d), fmt(p.mass_factor), fmt(p.lambda_d, 4)]
                        for p in pts], "llrrr"))
    if res.requirements is not None:
        prob = _requirements(design.spec, res) + "\n\n" + prob
    if syn.K is None:
        return Rendered((prob, "## Robust gain\n\n**No gain was certified** at these points "
                         f"(best eps {fmt(syn.eps, 3)}): {syn.reason or 'no reason recorded'}."))
    g = syn.gain
    gain = (f"## Robust gain\n\n$K = {latex_matrix(syn.K, g.digits)}$, certified at every point "
            f"with decay rate {fmt(res.alpha)} 1/s at the delay **h = {fmt(g.h_certified, 3)} s**."
            f"\n\nThe synthesis LMI's bound is the bracket [{fmt(h, 4)}, "
            f"{fmt(syn.bracket.h_refuted, 4)}] s at eps = {fmt(syn.eps, 3)} "
            f"({len(syn.eps_tried)} eps values tried). K is its canonical gain: the "
            f"minimum-norm certificate at {fmt(g.h_design / h, 3)} × the bound (a problem with "
            f"one solution, unlike the degenerate optimum), rounded to {g.digits} significant "
            "digits; h above is what that rounded K certifies on its own (same LMI, V = K Y "
            "fixed).\n\n"
            + point_table([p.id for p in pts], res.checks, res.abscissa, res.order)
            + f"\n\nEvery spectral abscissa at h must be <= -alpha = {fmt(-res.alpha)} "
            "(the decay-rate certificate, cross-checked).")
    cmp_ = compare_section([p.id for p in pts], res.compare, res.compared, res.checks,
                           "robust K (this design)")
    fig = Figure("eps-search", "Certified delay of the robust synthesis against eps "
                 "(automatic search).", lambda f: _draw_eps(f, res))
    return Rendered((prob, gain, cmp_, f"## eps search\n\n![eps]({{figdir}}/{fig.name}.png)"),
                    (fig,))


def _draw_eps(fig, res) -> None:
    ax = fig.add_subplot(111)
    e, h = np.array(res.synthesis.eps_tried).T
    ax.semilogx(e, h, "o")
    ax.axvline(res.synthesis.eps, color="k", ls="--", lw=0.8, label="chosen eps")
    ax.set_xlabel("eps")
    ax.set_ylabel("certified h (s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    if not math.isfinite(float(np.max(h))):
        ax.set_ylim(0, None)

