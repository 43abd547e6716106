"""The requirements table of a design to requirements (issue 31): pure rendering
of a :class:`workbench.requirements.RequirementResult` (Markdown)."""
from __future__ import annotations

import math

import numpy as np

from ...printed_grid import sig_round
from ...report.markdown import fmt, fmt_floor, md_table
from ...report.synthesis_text import gain_text

__all__ = ["gain_text", "requirements_rows", "requirements_section", "requirements_table",
           "varying_section"]


_WHAT = {
    "delay": ("certified: the largest cap H such that the rounded gain is certified stable for "
              "every constant delay in [0, H] (s, rounded down); exact: the worst decay rate on "
              "the range (1/s, > 0: stable)"),
    "decay": ("certified: decay rate of the rounded gain for every constant delay in the range "
              "and every vertex, Bessel-Legendre (N = 2) cells over the range (1/s, rounded "
              "down); exact: the worst rightmost root on a 61-point delay grid, with no "
              "crossing of Re s = −certified between grid points"),
    "l2_gain": ("certified: bounded-real descriptor LMI with P2, P3 free, every constant delay "
                "in [0, h_max] (rounded up); exact: the largest H-infinity norm of the delayed "
                "loop on the delay grid"),
    "input_limit": ("certified: 1 when an invariant ellipsoid contains the box of constant "
                    "initial histories and keeps |u_k| ≤ u_max,k; exact: peak |u_k| / u_max,k "
                    "of linear simulations from the box's vertices at h_min, mid-range and "
                    "h_max"),
}


def _ceil(x, sig: int = 2) -> str:
    """A positive upper bound rounded *up* to ``sig`` significant digits."""
    if x is None or not math.isfinite(x) or x <= 0:
        return fmt(x)
    return fmt(sig_round(x, sig, math.ceil, -1e-12), sig)


def requirements_table(spec, r) -> str:
    """The requirements table: required, certified, exact, verdict (Markdown)."""
    return requirements_rows(spec.requirements, r, spec.synthesis.settings.gain_digits)


def requirements_rows(req, r, digits: int) -> str:
    """The table of :func:`requirements_table` from a RequirementsSpec ``req``."""
    rows = []
    for row in r.rows:
        cert = row.certified
        if cert is not None:
            cert = (_ceil(cert) if row.name == "l2_gain" else
                    "yes" if row.name == "input_limit" else fmt_floor(cert, 2))
        rows.append([row.name, row.required, cert if cert is not None else "—",
                     fmt(row.exact, 3), f"**{row.verdict}**", req.sources.get(row.name, "")])
    K = gain_text(r.K, digits)
    return (md_table(["requirement", "required", "certified", "exact", "verdict", "source"],
                     rows, "llrrll") + f"\n\nGain (rounded, the gain every row is about): "
            f"K = {K}" + (f". No gain: {r.reason}" if r.K is None else "")
            + ".\n\n" + "\n".join(f"- *{k}*: {v}" for k, v in _what(r).items()
                                   if any(row.name == k for row in r.rows)))


def _what(r) -> dict:
    """The notes under the table (with a rate the decay is the descriptor's)."""
    mu = getattr(r, "rate", None)
    if mu is None:
        return _WHAT
    return _WHAT | {"delay": (
        "certified: the largest cap H such that the rounded gain is certified stable for every "
        f"delay function h(t) in [0, H] with |h′(t)| ≤ {fmt(mu)} (s, rounded down); exact: the "
        "worst decay rate over the constant delays of the range (1/s, > 0: stable)"), "decay": (
        "certified: decay rate of the rounded gain for every delay function h(t) in "
        f"[0, h_max] with |h′(t)| ≤ {fmt(mu)} and every vertex: the exponentially weighted "
        "descriptor LMI with the (1 − μ) factor, P2, P3 free (1/s, rounded down); exact: the "
        "worst rightmost root over the constant delays of the range (a special case, so it "
        "must be ≥ the certified value), 61-point grid with no crossing of Re s = −certified "
        "between grid points")}


def requirements_section(spec, r) -> str:
    """The section that opens the report of a design with ``[requirements]``."""
    q = spec.requirements
    box = ("" if q.box is None else " Input limit from the box of initial deviations "
           + ", ".join(f"|δ{k}| ≤ {fmt(v)}" for k, v in q.box.items())
           + " (constant initial history, w = 0).")
    rate = getattr(q, "rate", None)
    delays = (f"every constant delay in [{fmt(q.delay[0])}, {fmt(q.delay[1])}] s" if rate is None
              else f"every time-varying delay h(t) in [{fmt(q.delay[0])}, {fmt(q.delay[1])}] s "
              f"with |h′(t)| ≤ {fmt(rate)}. With this rate every certificate is the descriptor "
              f"LMI with the (1 − μ) factor and covers every delay function h(t) in "
              f"[0, {fmt(q.delay[1])}] s with |h′(t)| ≤ {fmt(rate)} (constant delays "
              "included); the exact checks are on constant delays, a special case (h′ = 0): "
              "a certified value must not exceed them")
    return (f"## Requirements\n\nObjective: **{q.objective}**, subject to the others; "
            f"delays: {delays}."
            + box + "\n\n" + requirements_table(spec, r))


def varying_section(spec, r):
    """The time-varying-delay simulation of a rate requirement: (Markdown, figures)."""
    from ...report.markdown import Figure
    run, q = r.varying, spec.requirements
    if run is None:
        return None, []
    a_c = r.design.certificate.alpha_certified if r.design.certificate else None
    norm = np.linalg.norm(run.x, axis=0)
    fig = Figure("requirements-varying-delay",
                 "Linear loop (operating point) under a triangle-wave delay",
                 lambda f: _plot_varying(f, run, a_c))
    md = ("## Time-varying delay\n\nThe linear loop δx' = A δx + B K δx(t − h(t)) at the "
          f"operating point, from δx = (1, …, 1) held on [−{fmt(q.delay[1])}, 0] s, with h(t) a "
          f"triangle wave from {fmt(q.delay[0])} to {fmt(q.delay[1])} s of slope ±{fmt(q.rate)} "
          f"(`workbench/sim/varying_delay.py`, Heun, dt = {fmt(run.dt, 3)} s): one delay "
          "function of the certified set, an illustration, not a proof. |δx(t)| / |δx(0)| at "
          f"t = {fmt(float(run.t[-1]), 3)} s: {fmt(float(norm[-1] / norm[0]), 2)}"
          + ("" if a_c is None else f"; the certified rate alone bounds the envelope by "
             f"e^(−{fmt_floor(a_c, 2)} t) times a constant (the functional's conditioning)")
          + ".\n\n![" + fig.caption + "]({figdir}/" + fig.name + ".png)")
    return md, [fig]


def _plot_varying(fig, run, alpha):
    ax = fig.add_subplot(2, 1, 1)
    norm = np.linalg.norm(run.x, axis=0)
    ax.semilogy(run.t, norm / norm[0], label="|δx(t)| / |δx(0)|")
    if alpha:
        ax.semilogy(run.t, np.exp(-alpha * run.t), "--", label="e^(−α t), α certified")
    ax.set_ylabel("relative norm")
    ax.legend(loc="upper right", fontsize=8)
    ax2 = fig.add_subplot(2, 1, 2, sharex=ax)
    ax2.plot(run.t, run.h)
    ax2.set_ylabel("h(t) (s)")
    ax2.set_xlabel("t (s)")
