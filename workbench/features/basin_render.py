"""Markdown and figure of a delay-feedback design's basin check (pure
rendering of :class:`~workbench.features.basin.DelayFeedbackBasin`)."""
from __future__ import annotations

import numpy as np

from ..report.markdown import Figure, fmt
from ..roa.render import fmt_level, render_basin_markdown
from .basin import BOUNDARY, N_INSIDE, RADAU_RTOL
from .basin_plot import FATE_COLOR, BasinPlotStyle, basin_figure

_STYLE = BasinPlotStyle(point_label="scenario {label}: {outcome}")
_OUTCOME = {
    "CERTIFIED": "**CERTIFIED**: V' < 0 is proven on the whole of {0 < V <= c_search}",
    "REFUTED": "**REFUTED**: a point of {V <= c_search} has V' >= 0 (c_refuted <= c_search); "
               "the basin estimate is the level set {V <= c_certified}",
    "INCONCLUSIVE": "**INCONCLUSIVE**: neither proven nor refuted between c_certified and "
                    "c_search",
}


def render_basin_section(spec, res, basin) -> tuple[str, tuple]:
    """(Markdown section, figures) of the basin check of a delay-feedback design."""
    est = basin.check.estimate
    names = basin.names
    if basin.domain:
        dom = ", ".join(f"{k} in [{fmt(lo, 6)}, {fmt(hi, 6)}]" for k, (lo, hi)
                        in basin.domain.items())
        how = (f"the largest ellipsoid {{V <= c}} whose bounding box lies in the design's "
               f"domain ({dom}; states not named are unbounded)")
    else:
        how = "4 x the largest level of the scenarios' initial states (no domain given)"
    predictor = [s.name for s in spec.scenarios if s.predictor]
    scope = ("Scenarios with the predictor (" + ", ".join(f"`{n}`" for n in predictor)
             + ") run this loop from t = h on when the prediction is exact."
             if predictor else "No scenario of this design uses the predictor: the verdicts "
             "below say whether its initial state lies in the basin of the delay-free loop, "
             "not that the delayed run converges (that is the simulation's claim).")
    head = (
        "## Region of attraction of the delay-free loop\n\n"
        "Loop: x' = f(x, u* + K (x − x*)), the plant equations above with the canonical gain K "
        "and **no input delay**. Under exact prediction (a scenario with `predictor = true`: "
        "paper 003, Lemma 1 and Theorems 2-3) the input applied at t >= h is "
        "u* + K (x(t) − x*), so this is the predictor loop after its first h seconds; without "
        "the predictor the delayed loop is another system, whose local stability is the "
        "subject of the delay certificate above, not of this basin. Neither a prediction "
        "error nor a mismatch between model and plant is covered. " + scope + "\n\n"
        "V = (x − x*)' P (x − x*) with P the solution of the Lyapunov equation "
        "(A + BK)' P + P (A + BK) = −I (Q = I in the design's units, P rounded to 10 "
        "significant digits). Not the certificate's P: the delay LMI's P belongs to a "
        "Lyapunov-Krasovskii functional of the delayed loop (for Bessel-Legendre an "
        "augmented matrix), not to a Lyapunov function of the delay-free loop.\n\n"
        f"Searched level c_search = {fmt_level(est.c_search)}: {how}. "
        f"Outcome at c_search: {_OUTCOME[basin.outcome]}.\n\n")
    body = render_basin_markdown(basin.check, heading="### Certified level set")
    if basin.inside_ok is None:
        inside = "Nothing is certified: no trajectory is started on a certified level."
    else:
        inside = (f"**Check independent of the falsifier**: {N_INSIDE} delay-free trajectories "
                  "started on the boundary of the certified level set, {V = "
                  f"{fmt(BOUNDARY)} c_certified}} (seeded directions; Radau, rtol "
                  f"{fmt(RADAU_RTOL)}, over {fmt(basin.horizon, 3)} s = "
                  "10 / |slowest eigenvalue of A + BK|): V never rises along any of them and "
                  "each ends below 1 % of its start: "
                  + ("**yes**." if basin.inside_ok else "**no** (see the claims)."))
    n = len(names)
    if n == 1:
        plane = f"x = {names[0]} against time"
    else:
        i, j = basin.plane
        plane = (f"the ({names[i]}, {names[j]}) plane"
                 + ("" if n == 2 else f", a 2-D slice through x* (the other {n - 2} states at "
                    "their operating-point values; trajectories, which move in all states, "
                    "are drawn projected)"))
    labels = tuple(f"{v.name} ({v.unit})" for v in spec.plant.states)
    fig = Figure("basin", "Certified level set of the delay-free loop, sampled trajectories.",
                 lambda f, b=basin: plot_basin(f, b, labels), (7.0, 5.0))
    text = (head + body + "\n" + inside + "\n\n"
            f"![basin]({{figdir}}/basin.png)\n\nThe figure shows {plane}: the certified level "
            "set (solid), the refuted level (dashed) and its counterexample (*), delay-free "
            "trajectories from seeded starts in the plotted box (green: converge, i.e. enter "
            "the certified set; red: leave the domain, or go 100 times the searched "
            "ellipsoid's half-width away where no domain bounds a state; grey: neither "
            "within the horizon), and "
            "each scenario's initial state marked by its verdict (o CERTIFIED, s "
            "INCONCLUSIVE, X REFUTED).\n")
    return text, (fig,)


def plot_basin(fig, basin, names) -> None:
    """Level sets, counterexample, sampled trajectories and scenario states
    (``names``: axis labels, one per state; :func:`.basin_plot.basin_figure`)."""
    est = basin.check.estimate
    P, x_eq = np.array(est.P), np.array(est.x_eq)
    lo, hi = np.array(basin.box[0]), np.array(basin.box[1])
    if len(names) == 1:
        ax = fig.add_subplot(111)
        for tr in basin.sampled:
            t = np.linspace(0, 1, len(tr.path))
            ax.plot(t, tr.path[:, 0], color=FATE_COLOR[tr.fate], lw=0.8)
        r = np.sqrt(est.c_certified / P[0, 0])
        ax.axhspan(x_eq[0] - r, x_eq[0] + r, color="tab:green", alpha=0.15,
                   label="certified level set")
        ax.set_xlabel("fraction of each trajectory's time")
        ax.set_ylabel(names[0])
        ax.legend(fontsize=7)
        return
    i, j = basin.plane
    pad_i, pad_j = 0.05 * (hi[i] - lo[i]), 0.05 * (hi[j] - lo[j])
    basin_figure(fig, est, basin.check.points, basin.sampled, (i, j), _STYLE, (names[i], names[j]),
                 xlim=(lo[i] - pad_i, hi[i] + pad_i), ylim=(lo[j] - pad_j, hi[j] + pad_j),
                 extra=lambda ax: ax.plot(x_eq[i], x_eq[j], "k+", ms=10,
                                          label="operating point x*"))
