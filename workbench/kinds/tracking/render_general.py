"""The general report of a ``tracking`` design (one without an ``[analysis]``
module): problem, target profile, tuning per reading and controller, the
chosen points on the main pair and the line; pure rendering.
"""
from __future__ import annotations

import numpy as np

from ...features.reproducible import NUDGE, RTOL
from ...report.markdown import Figure, Rendered, fmt, md_table
from ...report.param_table import param_table
from . import figures as F
from .spec import OBJECTIVE_UNITS, OBJECTIVES

__all__ = ["DOC", "LABEL", "line_figure", "pareto_links", "params_text",
           "ppd_figure", "profile_text", "render", "scale_rows", "scale_table", "tuning_figures"]

H_TUNE = "Tuning per reading and controller"
H_MAIN = "Chosen points on the main pair"
H_LINE = "Line"
DOC = {"f": "static map gain", "e": "static map offset", "delay": "pure delay",
       "lag": "lag time constant", "c0": "Davis, constant (per mass)",
       "c1": "Davis, linear (per mass)", "c2": "Davis, quadratic (per mass)", "g": "gravity"}
LABEL = {"stop_error": "stop error (m)", "punctuality": "punctuality (s)",
         "comfort": "RMS jerk (m/s³)", "energy": "energy (J/kg)",
         "rms_speed_error": "RMS speed error (m/s)"}


def _problem(spec) -> str:
    secs = (spec.main, *spec.line)
    rows = [[s.name, fmt(s.route.distance, 5), fmt(s.run_time, 4), fmt(s.v_limit * 3.6, 3),
             ", ".join(f"{fmt(g)} from {fmt(x)} m" for x, g in
                       zip(s.route.grade_from, s.route.grade))] for s in secs]
    return (
        "## Problem\n\nStation pairs (the first is the main pair, where the gains are tuned):"
        "\n\n" + md_table(["pair", "distance (m)", "planned (s)", "limit (km/h)",
                           "gradients"], rows, "lrrrl")
        + "\n\nTrain (`[train]`, model `delay-lag-002` of `workbench/plants/train002.py`: "
        "command → demanded acceleration → delay → lag → speed, Davis resistance and "
        "gravity):\n\n" + param_table(spec.train, DOC, 5)
        + f"\n\nCommand limits {fmt(spec.u_limits[0])} … {fmt(spec.u_limits[1])}. Control "
        f"cycle Ts = {fmt(spec.Ts)} s, plant step {fmt(spec.dt)} s. Target profile: "
        f"{profile_text(spec)} (`workbench/profiles.py`).")


def profile_text(spec) -> str:
    """The target profile's limits: "acceleration … m/s², braking … m/s², jerk … m/s³"."""
    p = spec.profile
    return (f"acceleration {fmt(p['accel'])} m/s², braking {fmt(p['brake'])} m/s², "
            f"jerk {fmt(p['jerk'])} m/s³")


def params_text(tun, symbol: dict | None = None) -> str:
    """The chosen point of a tuning, each parameter by its ``symbol`` (default its name)."""
    return ", ".join(f"{(symbol or {}).get(k, k)} = {fmt(v, 3)}"
                     for k, v in tun.chosen_params().items())


def scale_rows(spec) -> list:
    """Per objective: its name, scale s_j with unit, weight w_j and the scale's source."""
    return [[k, f"{fmt(spec.scales[k].value)} {OBJECTIVE_UNITS[k]}", fmt(w),
             spec.scales[k].source] for k, w in zip(OBJECTIVES, spec.weights)]


def scale_table(spec, why: str = "source") -> str:
    """The table of :func:`scale_rows`; ``why`` heads the sources' column."""
    return md_table(["objective", "scale s_j", "weight w_j", why], scale_rows(spec), "lrrl")


def pareto_links(res) -> str:
    """The Markdown images of every reading's Pareto fronts."""
    return "\n\n".join(f"![Pareto fronts, {r.reading.name}]"
                       f"({{figdir}}/pareto-{r.reading.name}.png)" for r in res.readings)


def _tuning(spec, res) -> str:
    rows = []
    for r in res.readings:
        for c, tun in r.tunings:
            pj = r.main.value(c, "peak_jerk")
            rows.append([f"`{r.reading.name}`", c, str(len(tun.cost)),
                         str(int((~tun.reproducible).sum())), str(int(tun.front.sum())),
                         params_text(tun), fmt(pj, 3), ", ".join(tun.edges) or "none"])
    lim = spec.peak_jerk
    con = ("No peak-jerk constraint is set." if lim is None else
           f"Comfort is a peak constraint: only runs whose jerk over any 1 s window stays "
           f"within {fmt(lim.value)} m/s³ may be chosen (when any does).")
    return (
        f"## {H_TUNE}\n\nEvery combination of each controller's grid is simulated on the "
        "main pair. The design point is the run with the smallest weighted sum Σ w_j J_j / s_j "
        f"among the runs that stop within {fmt(res.stop_tolerance)} m. {con} Only "
        f"reproducible runs take part: the grid is run again with the train moved by "
        f"±{fmt(NUDGE)} (relative); a run whose objectives move by more than {fmt(RTOL)} is "
        "no result. A chosen value at the first or last of its grid is not shown to be an "
        "optimum inside the grid.\n\n"
        + scale_table(spec)
        + "\n\n" + md_table(["reading", "controller", "runs", "not reproducible",
                             "on front", "chosen", "peak |jerk| (m/s³)",
                             "on the grid's edge in"], rows, "llrrrlrl")
        + "\n\n" + pareto_links(res) + "\n\n![jerk against its limit]({figdir}/jerk.png)")


def _main(res) -> str:
    rows = []
    for r in res.readings:
        for c, _ in r.tunings:
            rows.append([f"`{r.reading.name}`", c]
                        + [fmt(r.main.value(c, i), 3) for i in (*OBJECTIVES,
                                                                 "rms_speed_error")])
    return (f"## {H_MAIN}\n\n" + md_table(["reading", "controller"]
                                          + [LABEL[i] for i in (*OBJECTIVES,
                                                                "rms_speed_error")],
                                          rows, "llrrrrr")
            + "\n\n![speed error and acceleration]({figdir}/tracking.png)")


def _line(res) -> str:
    if not res.readings[0].line:
        return ""
    rows = []
    for r in res.readings:
        for c, _ in r.tunings:
            for x in (r.main, *r.line):
                e = x.value(c, "stop_error")
                ok = "—" if not np.isfinite(e) else ("yes" if e <= res.stop_tolerance
                                                     else "**no**")
                rows.append([f"`{r.reading.name}`", c, x.section.name, fmt(e, 3),
                             fmt(x.value(c, "punctuality"), 3), ok])
    return (f"## {H_LINE}\n\nThe chosen gains of the main pair on every pair:\n\n"
            + md_table(["reading", "controller", "pair", "stop error (m)",
                        "punctuality (s)", f"within {fmt(res.stop_tolerance)} m"], rows,
                       "lllrrl")
            + "\n\n![stop error per pair]({figdir}/line.png)")


def render(design, res) -> Rendered:
    """The general report of a ``tracking`` design (see the module docstring)."""
    spec = design.spec
    sections = [_problem(spec), _tuning(spec, res), _main(res), _line(res)]
    figs = tuning_figures(spec, res) + line_figure(res, "Stop error per pair.")
    anchors = ((r"reading\[[^\]]+\]\.line", H_LINE),
               (r"reading\[[^\]]+\]\.(best|[a-z]+\.(grid_edge|front_size|peak_jerk))", H_TUNE),
               (r"reading\[[^\]]+\]\.", H_MAIN), (r"profile\.", H_MAIN))
    return Rendered(tuple(s for s in sections if s), tuple(figs), anchors)


def tuning_figures(spec, res) -> list:
    """The figures every tracking report has: each reading's Pareto fronts,
    the tracking and the jerk of the chosen points against the comfort limit."""
    figs = [Figure(f"pareto-{r.reading.name}",
                   f"Pareto fronts (two projections), reading {r.reading.name}.",
                   lambda fig, r=r: F.plot_pareto(fig, r), (8.0, 3.8)) for r in res.readings]
    return figs + [Figure("tracking", "Speed error and acceleration at the chosen points.",
                          lambda fig: F.plot_tracking(fig, res), (8.0, 5.0)),
                   Figure("jerk", "Jerk (1 s windows) of the chosen points against the comfort "
                          "limit.", lambda fig: F.plot_jerk(
                              fig, res, None if spec.peak_jerk is None else spec.peak_jerk.value),
                          (8.0, 3.2))]


def ppd_figure(res) -> list:
    """The figure of the chosen MFAC runs' PPD estimate and realised PPD (none
    unless every reading has an MFAC)."""
    return [Figure("ppd", "PPD estimate and realised PPD of the chosen MFAC runs.",
                   lambda fig: F.plot_ppd(fig, res), (8.0, 3.8))] if all(
        r.ppd is not None for r in res.readings) else []


def line_figure(res, caption: str) -> list:
    """The figure of the stop error per pair (none without a line)."""
    return [Figure("line", caption, lambda fig: F.plot_line(fig, res), (8.0, 4.0))] if (
        res.readings[0].line) else []
