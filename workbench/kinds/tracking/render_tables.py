"""Tables of a ``tracking`` design's results for a report that words them
itself (an ``[analysis]`` module): the rows per reading and controller, each
controller the reading has (a missing one is left out), and the comfort/edge
section; pure rendering.

A cell holding both controllers' values joins them "MFAC / PID" in the order
of :attr:`~.run.ReadingResult.tunings`.
"""
from __future__ import annotations

import numpy as np

from ...controllers.mfac import RESET_CONDITIONS
from ...report.markdown import fmt, md_table
from ...tuning.pareto import dominated_share
from .mfac import most_sensitive
from .render_general import params_text
from .spec import OBJECTIVES

__all__ = ["best_rows", "comfort_section", "compare_rows", "dominated_rows", "line_rows",
           "pct", "ppd_rows", "reset_rows", "sensitivity_rows", "span", "tuning_rows"]


def pct(x) -> str:
    """A share as a percentage to 3 digits ("—" for None)."""
    return "—" if x is None else f"{fmt(100 * x, 3)} %"


def span(rates) -> str:
    """Range of shares as percentages ("—" when there are none)."""
    rates = np.asarray(rates, float)
    return f"{pct(float(rates.min()))} … {pct(float(rates.max()))}" if rates.size else "—"


def _name(r) -> str:
    return f"`{r.reading.name}`"


def tuning_rows(res, symbol: dict | None = None) -> list:
    """Per reading: per controller its runs, not reproducible runs, front size
    and chosen point (parameters by ``symbol``)."""
    return [[_name(r)] + [x for _, t in r.tunings for x in (
        str(len(t.cost)), str(int((~t.reproducible).sum())), str(int(t.front.sum())),
        params_text(t, symbol))] for r in res.readings]


def comfort_section(spec, res) -> str:
    """Peak jerk of the chosen points against the constraint, and whether a
    chosen point lies on its grid's edge (issue 33, items 2 and 4)."""
    lim = spec.peak_jerk
    rows = []
    for r in res.readings:
        for c, tun in r.tunings:
            pj = r.main.value(c, "peak_jerk")
            ok = "—" if lim is None or not np.isfinite(pj) else (
                "yes" if pj <= lim.value else "**no**")
            rows.append([_name(r), c, fmt(pj, 3), ok, ", ".join(tun.edges) or "none"])
    con = ("No peak-jerk constraint is set (`[tuning] peak_jerk`)." if lim is None else
           f"Comfort is a **peak constraint**: only runs whose jerk over any 1 s window stays "
           f"within {fmt(lim.value)} m/s³ ({lim.source}) may be chosen (a grid with no such "
           "run keeps the stop requirement alone, and the table says no).")
    return (
        f"{con} A chosen point whose value of a parameter is the first or last of that "
        "parameter's grid has not been shown to be an optimum inside the grid: the design "
        "point is then INCONCLUSIVE until the grid is extended in that parameter.\n\n"
        + md_table(["reading", "controller", "peak |jerk| (m/s³)", "within the limit",
                    "on the grid's edge in"], rows, "llrll")
        + "\n\n![jerk against its limit]({figdir}/jerk.png)")


def compare_rows(res) -> list:
    """Per reading and controller the objectives, RMS speed error and cost of
    the chosen point on the main pair; with two controllers, a row of the
    winner per objective and the verdict."""
    rows = []
    for r in res.readings:
        m = r.main
        for c, _ in r.tunings:
            rows.append([_name(r), c]
                        + [fmt(m.value(c, i), 3) for i in (*OBJECTIVES, "rms_speed_error")]
                        + [fmt(r.cost(c), 3)])
        if len(r.tunings) == 2:
            rows.append([_name(r), "**winner**"] + [m.winner(i) for i in OBJECTIVES]
                        + ["", f"**{r.verdict}**"])
    return rows


def best_rows(res) -> list:
    """Per reading the best value of each objective in each controller's grid."""
    return [[_name(r)] + [" / ".join(fmt(t.best(i), 3) for _, t in r.tunings)
                          for i in OBJECTIVES] for r in res.readings]


def dominated_rows(res) -> list:
    """Per reading with two controllers: the share of the second's front that
    the first's dominates, and the other way round."""
    rows = []
    for r in res.readings:
        if len(r.tunings) == 2:
            (_, a), (_, b) = r.tunings
            fa, fb = a.objectives[a.front], b.objectives[b.front]
            rows.append([_name(r), pct(dominated_share(fa, fb)), pct(dominated_share(fb, fa))])
    return rows


def line_rows(res) -> list:
    """Per reading and section of the line: its distance, gradients (‰) and
    each objective of the chosen points."""
    return [[_name(r), c.section.name, fmt(c.section.route.distance, 5),
             " ".join(fmt(x * 1000, 3) for x in c.section.route.grade)]
            + [" / ".join(fmt(c.value(n, i), 3) for n, _ in r.tunings) for i in OBJECTIVES]
            for r in res.readings for c in r.line]


def ppd_rows(res) -> list:
    """Per reading with an MFAC: plant gain and time constant, the estimate's
    range, the realised PPD's statistics and the frozen-PPD loop."""
    return [[_name(r), fmt(r.dc_gain, 3), fmt(r.time_constant, 3),
             f"{fmt(s.phi_min, 2)} … {fmt(s.phi_max, 3)}", str(s.updates),
             pct(s.data_sign_agreement), fmt(s.data_median, 3), fmt(s.data_p95, 3),
             fmt(r.frozen_gain, 3), fmt(r.frozen_radius, 3)]
            for r in res.readings if (s := r.ppd) is not None]


def sensitivity_rows(res, keys, symbol: dict) -> list:
    """Per reading with an MFAC: the sensitivity to each of ``keys`` ("—": no
    reproducible neighbour) and the most sensitive parameter, by ``symbol``."""
    return [[_name(r)] + ["—" if np.isnan(r.sensitivity[k]) else fmt(r.sensitivity[k], 3)
                          for k in keys] + [symbol[most_sensitive(r.sensitivity)]]
            for r in res.readings if r.ppd is not None]


def reset_rows(res) -> list:
    """Per reading with an MFAC: the chosen run's samples, its reset rate, the
    share of each reset condition and of a command at a limit, and the range of
    reset rates over the grid's reproducible runs."""
    return [[_name(r), str(s.samples), pct(s.reset_rate)]
            + [pct(s.by_condition[k]) for k in (*RESET_CONDITIONS, "at_limit")]
            + [pct(s.saturated), span(r.mfac.reset_rate[r.mfac.reproducible])]
            for r in res.readings if (s := r.ppd) is not None]
