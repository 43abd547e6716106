"""Rendering of a Monte Carlo sweep's runs (pure): the summary and outcome
tables, the outcome rates with their Wilson intervals, and histograms of the
summarised metrics of a :class:`~workbench.features.montecarlo_stats.RunsResult`,
and the tables of a step-halving check of its runs
(:class:`~workbench.features.montecarlo_halving.HalvingCheck`). A study
supplies only its words (outcome labels, units, marked values, draw labels)."""
from __future__ import annotations

import math

import numpy as np

from ..report.markdown import fmt, md_table

__all__ = ["draw_histograms", "draw_rates", "halving_tables", "rate_text", "summary_tables"]


def rate_text(k: int, n: int, lo: float, hi: float) -> str:
    """"k / n = p % [lo, hi] %" (one decimal; the interval's ends rounded
    outwards, so the printed interval contains the computed one)."""
    down = math.floor(1000 * lo) / 10
    up = math.ceil(1000 * hi) / 10
    return f"{k} / {n} = {100 * k / n:.1f} % [{down:.1f}, {up:.1f}] %"


def summary_tables(res, sig: int, labels: dict) -> str:
    """Markdown: the summary statistics of ``res.SUMMARY`` and the outcome
    rates (``sig`` significant digits); ``labels``: outcome -> its words."""
    stats = md_table(["metric", "n finite", "min", "median", "95 %", "max"],
                     [[f"`{r[0]}`", r[1]] + [fmt(x, sig) for x in r[2:]]
                      for r in res.summary_rows()], "lrrrrr")
    viol = md_table(["outcome", "runs", "fraction", "rate [Wilson 95 % interval]"],
                    [[labels[o], k, fmt(p, 3), rate_text(k, n, lo, hi)]
                     for o, k, n, p, lo, hi in res.outcome_rates()], "lrrr")
    return stats + "\n\n" + viol


def halving_tables(hc, metrics, outcomes, labels, sig: int = 3) -> str:
    """Markdown of a step-halving check ``hc``: a row per metric of
    ``metrics`` (its atol, runs finite at both steps, runs that agree,
    largest |difference| over the runs finite at both), a row per outcome of
    ``outcomes`` (runs with it at each step, runs that agree), and the runs
    that disagree with their draws (``labels``: (draw, column label) pairs)
    and values (``sig`` significant digits)."""
    n = hc.n
    rows = []
    for m in metrics:
        a, b = np.asarray(hc.coarse[m], float), np.asarray(hc.fine[m], float)
        both = np.isfinite(a) & np.isfinite(b)
        diff = float(np.max(np.abs(a[both] - b[both]))) if both.any() else None
        rows.append([f"`{m}`", fmt(hc.atol[m]), int(both.sum()), sum(hc.agree[m]),
                     fmt(diff, 2)])
    text = md_table(["metric", "atol", "finite at both", f"agree (of {n})",
                     "largest |difference|"], rows, "lrrrr")
    text += "\n\n" + md_table(
        ["outcome", "runs at dt", "runs at dt / 2", f"agree (of {n})"],
        [[f"`{o}`", sum(hc.coarse[o]), sum(hc.fine[o]), sum(hc.agree[o])]
         for o in outcomes], "lrrr")
    bad = [[i] + [fmt(hc.draws[d][i], 4) for d, _ in labels]
           + [f"`{key}`", fmt(hc.coarse[key][i], sig), fmt(hc.fine[key][i], sig)]
           for i in range(n) for key in hc.agree if not hc.agree[key][i]]
    text += "\n\nRuns that disagree:"
    if not bad:
        return text + " none."
    return text + "\n\n" + md_table(["run"] + [lab for _, lab in labels]
                                    + ["metric or outcome", "at dt", "at dt / 2"],
                                    bad, "r" * (1 + len(labels)) + "lrr")


def draw_histograms(fig, res, units: dict, marks: dict | None = None) -> None:
    """A histogram of each metric of ``res.SUMMARY`` over its finite values;
    ``units``: metric -> unit (x label), ``marks``: metric -> (x, label) of a
    dashed reference line."""
    marks = marks or {}
    axes = fig.subplots(1, len(res.SUMMARY))
    for ax, k in zip(axes, res.SUMMARY):
        x = np.asarray(res.metrics[k], float)
        x = x[np.isfinite(x)]
        if x.size:
            ax.hist(x, bins=int(np.clip(2 * np.sqrt(x.size), 5, 30)), color="tab:blue")
        if k in marks:
            ax.axvline(marks[k][0], color="k", ls="--", lw=0.8, label=marks[k][1])
            ax.legend(fontsize=7)
        ax.set_title(f"{k} (n = {x.size})", fontsize=8)
        ax.set_xlabel(f"{k} ({units[k]})")


def draw_rates(fig, res) -> None:
    """Each outcome's rate (percent of the runs) with its Wilson 95 %
    interval."""
    ax = fig.subplots()
    rows = res.outcome_rates()
    y = np.arange(len(rows))[::-1]
    p = np.array([100 * r[3] for r in rows])
    lo, hi = np.array([100 * r[4] for r in rows]), np.array([100 * r[5] for r in rows])
    ax.errorbar(p, y, xerr=[p - lo, hi - p], fmt="o", color="tab:blue", capsize=4)
    ax.set_yticks(y, [r[0] for r in rows], fontsize=8)
    ax.set_xlim(-2, 102)
    ax.set_xlabel(f"runs with the outcome (%) of {res.n}, Wilson 95 % interval")
    ax.grid(alpha=0.3)
