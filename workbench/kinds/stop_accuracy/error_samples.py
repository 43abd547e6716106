"""Samples of stop errors (repeats, draws) per controller, rendered: the
share within a stopping window with its Wilson 95 % interval, box plots per
group (e.g. per section), the distribution of |error|, and the tables of the
per-section statistics of the repeats (pure rendering).

Each takes ``series``, a sequence of ``(label, errors)`` (one per controller,
errors in one unit, the window in the same) or ``(label, cells)`` (the
:class:`~.sections.CellStats` of each section), so a report passes its own
labels and unit.
"""
from __future__ import annotations

import numpy as np

from ...features.montecarlo import within_rate
from ...report.markdown import fmt, md_table
from .render import plot_ecdf

__all__ = ["plot_abs_ecdf", "plot_grouped_boxes", "ride_table", "section_table", "within_rows"]


def within_rows(series, window: float) -> list:
    """Per ``(label, errors)`` of ``series``: the label, the stops within
    ±``window`` ("k / n"), their share, its Wilson 95 % interval
    (:func:`~workbench.features.montecarlo.within_rate`) and the 95th
    percentile of |error|."""
    rows = []
    for label, e in series:
        k, n, p, lo, hi = within_rate(e, window)
        rows.append([label, f"{k} / {n}", fmt(p, 3), f"[{fmt(lo, 3)}, {fmt(hi, 3)}]",
                     fmt(float(np.percentile(np.abs(e), 95)), 3)])
    return rows


def plot_abs_ecdf(ax, series, window: float, *, window_label: str, unit: str,
                  linthresh: float) -> None:
    """The empirical distribution of |error| of each ``(label, errors)`` of
    ``series`` on ``ax`` (symlog axis, linear within ``linthresh``), the
    window dashed (legend ``window_label``); errors in ``unit``."""
    for k, (label, e) in enumerate(series):
        plot_ecdf(ax, np.abs(e), color=f"C{k}", label=label)
    ax.axvline(window, color="k", ls="--", lw=0.8, label=window_label)
    ax.set_xscale("symlog", linthresh=linthresh)
    ax.set_xlim(left=0.0)              # an |error| axis has no negative ticks
    ax.set_xlabel(f"|stop error| ({unit})")
    ax.set_ylabel("fraction of stops")
    ax.legend(fontsize=8)


def plot_grouped_boxes(ax, series, *, xlabel: str, ylabel: str) -> None:
    """Box plots of the errors of every group (numbered 1, 2, ... on the x
    axis), a box per ``(label, [errors of group 1, of group 2, ...])`` of
    ``series`` side by side, zero marked, the series' legend above the axes."""
    groups = len(series[0][1])
    for k, (label, data) in enumerate(series):
        pos = np.arange(groups) + 1 + (k - (len(series) - 1) / 2) * 0.2
        b = ax.boxplot(data, positions=pos, widths=0.17, patch_artist=True, showfliers=True,
                       flierprops={"markersize": 2})
        for patch in b["boxes"]:
            patch.set_facecolor(f"C{k}")
            patch.set_alpha(0.6)
        ax.plot([], [], "s", color=f"C{k}", label=label)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xticks(np.arange(groups) + 1)
    ax.set_xticklabels([str(i + 1) for i in range(groups)])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.legend(ncol=len(series), loc="lower center", bbox_to_anchor=(0.5, 1.0),
              fontsize=8, frameon=False)


def section_table(series) -> str:
    """Per section (a row each, numbered from 1) the mean |error|, signed mean
    and variance of each ``(label, cells)`` of ``series``, and a last row with
    each controller's mean over the sections of the mean |error| (bold)."""
    rows = [[i + 1] + [fmt(x, 3) for _, cells in series
                       for x in (cells[i].mean_abs, cells[i].mean, cells[i].var)]
            for i in range(len(series[0][1]))]
    rows.append(["all"] + sum(([f"**{fmt(float(np.mean([c.mean_abs for c in cells])), 3)}**",
                                "", ""] for _, cells in series), []))
    head = ["#"] + [f"{label} {h}" for label, _ in series for h in ("mean abs", "mean", "var")]
    return md_table(head, rows, "r" * len(head))


def ride_table(series, planned: float) -> str:
    """Ride quality and time of each ``(label, cells)`` of ``series`` over the
    sections: mean and largest |jerk|, mean command rate, mean run time, and
    the ``planned`` braking time (s)."""
    rows = [[label, fmt(np.mean([c.jerk_mean for c in cells]), 3),
             fmt(np.max([c.jerk_max for c in cells]), 3),
             fmt(np.mean([c.command_rate for c in cells]), 3),
             fmt(np.mean([c.run_time for c in cells]), 4), fmt(planned, 4)]
            for label, cells in series]
    return md_table(["controller", "mean |jerk| (m/s³)", "max |jerk| (m/s³)",
                     "mean |dc/dt| of the command (m/s³)", "mean run time (s)", "planned (s)"],
                    rows, "lrrrrr")
