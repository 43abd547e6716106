"""Markdown and figure of a robust gain (:mod:`workbench.features.robust_gain`;
pure rendering): the gain with its certificate, the per-point checks and the
eps search."""
from __future__ import annotations

import math

import numpy as np

from ..report.markdown import Figure, fmt, latex_matrix
from .point_gains import point_table

__all__ = ["eps_search_figure", "robust_gain_section", "robust_method_text"]


def robust_method_text(settings) -> str:
    """How :func:`~workbench.features.robust_gain.run_robust` synthesises and
    checks the gain (a paragraph's sentences; ``settings`` a ``RobustSettings``)."""
    return ("Synthesis: descriptor method with the Jensen inequality, slack P3 = eps P2, "
            "common Y and V (K = V Y^{-1}), Lyapunov-Krasovskii matrices per point "
            "(`workbench.lmi.robust.DescriptorSynthesis`); eps searched automatically "
            "(log grid, then golden section). The certificate holds at the listed points, not "
            "in between. Each gain is then re-checked per point by the exact margin and the "
            f"Bessel-Legendre analysis of order {settings.order}.")


def robust_gain_section(ids, r) -> str:
    """``## Robust gain`` of a :class:`~workbench.features.robust_gain.RobustGain`
    at the points ``ids``."""
    syn, alpha = r.synthesis, r.settings.alpha
    h = syn.bracket.h_certified
    if syn.K is None:
        return ("## Robust gain\n\n**No gain was certified** at these points "
                f"(best eps {fmt(syn.eps, 3)}): {syn.reason or 'no reason recorded'}.")
    g = syn.gain
    return (f"## Robust gain\n\n$K = {latex_matrix(syn.K, g.digits)}$, certified at every point "
            f"with decay rate {fmt(alpha)} 1/s at the delay **h = {fmt(g.h_certified, 3)} s**."
            f"\n\nThe synthesis LMI's bound is the bracket [{fmt(h, 4)}, "
            f"{fmt(syn.bracket.h_refuted, 4)}] s at eps = {fmt(syn.eps, 3)} "
            f"({len(syn.eps_tried)} eps values tried). K is its canonical gain: the "
            f"minimum-norm certificate at {fmt(g.h_design / h, 3)} × the bound (a problem with "
            f"one solution, unlike the degenerate optimum), rounded to {g.digits} significant "
            "digits; h above is what that rounded K certifies on its own (same LMI, V = K Y "
            "fixed).\n\n"
            + point_table(list(ids), r.checks, r.abscissa, r.settings.order)
            + f"\n\nEvery spectral abscissa at h must be <= -alpha = {fmt(-alpha)} "
            "(the decay-rate certificate, cross-checked).")


def eps_search_figure(r) -> Figure:
    """``eps-search.png``: the certified delay of each eps tried."""
    return Figure("eps-search", "Certified delay of the robust synthesis against eps "
                  "(automatic search).", lambda f: _draw_eps(f, r.synthesis))


def _draw_eps(fig, syn) -> None:
    ax = fig.add_subplot(111)
    e, h = np.array(syn.eps_tried).T
    ax.semilogx(e, h, "o")
    ax.axvline(syn.eps, color="k", ls="--", lw=0.8, label="chosen eps")
    ax.set_xlabel("eps")
    ax.set_ylabel("certified h (s)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    if not math.isfinite(float(np.max(h))):
        ax.set_ylim(0, None)
