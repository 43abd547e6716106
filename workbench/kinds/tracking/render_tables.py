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
from ...features.reproducible import NUDGE, RTOL, count_text
from ...report.markdown import fmt, md_table
from ...tuning.pareto import TIE_REL, dominated_share
from .mfac import most_sensitive
from .render_general import LABEL, params_text
from .spec import OBJECTIVES

__all__ = ["RESET_LABELS", "admissible_text", "best_rows", "best_table", "comfort_section",
           "compare_rows", "compare_table", "dominated_rows", "dominated_table", "dominated_text",
           "edges_text", "end_error_text", "line_rows", "line_table", "pct", "ppd_rows",
           "ppd_table", "ppd_text", "readings_table", "reproducible_text", "reset_rows",
           "reset_table", "roots_text", "sensitivity_rows", "sensitivity_table", "span",
           "tuning_rows", "tuning_table"]

#: The reset conditions of the MFAC estimate (``"at_limit"`` and
#: :data:`~workbench.controllers.mfac.RESET_CONDITIONS`) as column headings.
RESET_LABELS = {"small_phi": "|φ(k)| ≤ ε", "small_du": "|Δu(k−1)| ≤ ε",
                "sign_change": "sign φ(k) ≠ sign φ(1)",
                "at_limit": "|Δu(k−1)| ≤ ε, u at a limit"}


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


# -- the tables of the rows above, headed (controllers named as in the first reading) ---------
def _controllers(res) -> list[str]:
    return [c for c, _ in res.readings[0].tunings]


def _table(head: list, rows: list, first: str = "l") -> str:
    """A table whose first column(s) ``first`` are left-aligned, the rest right-aligned."""
    return md_table(head, rows, first + "r" * (len(head) - len(first)))


def reproducible_text() -> str:
    """Why a tuning keeps only its reproducible runs, and how it finds them
    (:mod:`workbench.features.reproducible`; RTOL / NUDGE = 1e6)."""
    return (
        "**Reproducible runs only.** Each grid is simulated again with every parameter of the "
        f"train but its delay (whole plant steps) moved by +{fmt(NUDGE)} and −{fmt(NUDGE)} "
        f"(relative). A run whose objectives move by more than {fmt(RTOL)} (relative) between "
        "the three amplifies its inputs' differences more than a million times: a switching "
        "(relay-like) loop turns a last-bit difference, as between two CPUs, into another "
        "trajectory, so its stop error, jerk and energy are not results. Such runs are counted "
        "(column \"not reproducible\") and take no part in the fronts, the choice, the "
        "counts, the bests and the utopia point (our choice).")


def readings_table(spec) -> str:
    """The plant readings of a design: name, model and source."""
    return md_table(["reading", "model", "what it is, where it comes from"],
                    [[f"`{r.name}`", f"`{r.model}`", r.source] for r in spec.readings], "lll")


def edges_text(r) -> str:
    """Per controller of a reading's result ``r``, the parameters whose chosen
    value lies on its grid's edge ("" when none does)."""
    return "; ".join(f"{c} in {', '.join(t.edges)}" for c, t in r.tunings if t.edges)


def tuning_table(res, symbol: dict | None = None) -> str:
    """The table of :func:`tuning_rows`: per controller its runs, not
    reproducible runs, front size and chosen point."""
    cs = _controllers(res)
    return md_table(["reading"] + [h for c in cs for h in (f"{c} runs", "not reproducible",
                                                           "on front", f"{c} chosen")],
                    tuning_rows(res, symbol), "l" + "rrrl" * len(cs))


def compare_table(res) -> str:
    """The table of :func:`compare_rows`."""
    return _table(["reading", "controller"] + [LABEL[i] for i in (*OBJECTIVES, "rms_speed_error")]
                  + ["cost"], compare_rows(res), "ll")


def best_table(res) -> str:
    """The table of :func:`best_rows`."""
    return _table(["reading"] + [LABEL[i] for i in OBJECTIVES], best_rows(res))


def dominated_table(res) -> str:
    """The table of :func:`dominated_rows` (a design with two controllers)."""
    a, b = _controllers(res)
    return _table(["reading", f"{b} front dominated by {a}", f"{a} front dominated by {b}"],
                  dominated_rows(res))


def dominated_text() -> str:
    """What :func:`dominated_table` counts (:func:`~workbench.tuning.pareto.dominated_share`)."""
    return ("Weight-free comparison of the fronts: the share of one controller's front that "
            "a point of the other's front dominates (better or equal in all four, better in "
            f"one; values within {fmt(TIE_REL)} relative of each other count as equal, so "
            "that no share rests on the last bits of two near-equal runs):")


def line_table(res) -> str:
    """The table of :func:`line_rows`."""
    return md_table(["reading", "section", "S (m)", "gradients (‰)"]
                    + [LABEL[i] for i in OBJECTIVES], line_rows(res), "llrlrrrr")


def ppd_table(res) -> str:
    """The table of :func:`ppd_rows`."""
    return md_table(["reading", "DC gain ((m/s) per unit)", "slowest time constant (s)",
                     "estimate range", "samples with |Δu| > ε", "realised PPD: sign of φ(1)",
                     "median", "95th pct", "frozen G", "frozen-loop spectral radius"],
                    ppd_rows(res), "lrrlrrrrrr")


def ppd_text() -> str:
    """What the first columns of :func:`ppd_table` hold (one sentence)."""
    return ("Each reading, at the chosen MFAC run: the plant's steady-state gain and "
            "slowest time constant at the cruise speed (from the sympy model), the range of the "
            "estimate in use, and the *realised* PPD Δy(k+1)/Δu(k) of the run on the samples "
            "where |Δu(k)| > ε (where the estimator learns): the share with the sign of φ(1), "
            "its median and 95th percentile magnitude.")


def sensitivity_table(res, keys, symbol: dict) -> str:
    """The table of :func:`sensitivity_rows`."""
    return md_table(["reading"] + [symbol[k] for k in keys] + ["most sensitive"],
                    sensitivity_rows(res, keys, symbol), "l" + "r" * len(keys) + "l")


def reset_table(res) -> str:
    """The table of :func:`reset_rows`, the conditions headed by :data:`RESET_LABELS`."""
    return _table(["reading", "samples", "reset"]
                  + [RESET_LABELS[k] for k in (*RESET_CONDITIONS, "at_limit")]
                  + ["command at a limit", "grid range"], reset_rows(res))


def admissible_text(tun, tolerance: float) -> str:
    """How many of an MFAC tuning's reproducible runs stop within
    ``tolerance`` (m; a range when some are undecided, their stop error within
    its band of the limit), and the span of their reset rates."""
    ok = (tun.stops == -1) & tun.reproducible
    near = int(((tun.stops == 0) & tun.reproducible).sum())
    n = int(tun.reproducible.sum())
    if not ok.any():
        return f"None of its {n} reproducible MFAC runs stops within {fmt(tolerance)} m"
    return (f"Of its {n} reproducible MFAC runs, {count_text(int(ok.sum()), near)} stop "
            f"within {fmt(tolerance)} m"
            + (f" ({near} with a stop error within its band of the limit: undecided)"
               if near else "") + f"; their reset rates span {span(tun.reset_rate[ok])}")


def roots_text(z) -> str:
    """The first two roots ``z`` of a real polynomial: "a ± b j" or "a and b".
    A real part below 1e-9 |z| is printed as 0 (it is the rounding of an exact
    0, e.g. 2 - G Ts = 0 of a frozen integrator loop)."""
    re = [0.0 if abs(x.real) < 1e-9 * abs(x) else x.real for x in z[:2]]
    return (f"{fmt(re[0], 3)} ± {fmt(abs(z[0].imag), 2)} j" if abs(z[0].imag) > 1e-6
            else f"{fmt(re[0], 3)} and {fmt(re[1], 3)}")


def end_error_text(prof) -> str:
    """A profile's end position error to 1 nm: below, it is rounding of the
    closed-form integration whose digits move under a few-ulp change of the
    inputs."""
    e = round(abs(prof.s[-1] - prof.spec.distance), 9)
    return "below 1 nm" if e == 0.0 else f"{fmt(e, 2)} m"
