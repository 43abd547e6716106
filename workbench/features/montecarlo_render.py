"""Rendering of a Monte Carlo sweep's runs (pure): the summary and outcome
tables, the outcome rates with their Wilson intervals, and histograms of the
summarised metrics of a :class:`~workbench.features.montecarlo_stats.RunsResult`,
and the tables of a step-halving check of its runs
(:class:`~workbench.features.montecarlo_halving.HalvingCheck`) with what it
covers, the runs at their draws marked by outcome, and the figures of a sweep
in a report. A study supplies only its words (outcome labels, units, marked
values, draw labels, what its kernel guarantees), as one table:
:class:`SweepWords`.

Used by the ``antiskid-run`` study (paper 003);
``tests/test_montecarlo_framework.py`` renders a toy sweep with it."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..report.markdown import Figure, fmt, md_table

__all__ = ["DRAWS_TEXT", "SweepWords", "draw_histograms", "draw_outcome_scatter", "draw_rates",
           "halving_section", "halving_tables", "montecarlo_figures", "rate_text",
           "rates_text", "refined_runs_text", "summary_tables"]

#: Markdown of the histograms and outcome figures of :func:`montecarlo_figures`.
DRAWS_TEXT = ("![Monte Carlo histograms]({figdir}/montecarlo-histograms.png)\n\n"
              "Histograms of the summary metrics (finite values only).\n\n"
              "![Monte Carlo outcomes]({figdir}/montecarlo-outcomes.png)\n\n"
              "Each run at its draws, marked by its outcome.")


def rate_text(k: int, n: int, lo: float, hi: float) -> str:
    """"k / n = p % [lo, hi] %" (one decimal; the interval's ends rounded
    outwards, so the printed interval contains the computed one)."""
    down = math.floor(1000 * lo) / 10
    up = math.ceil(1000 * hi) / 10
    return f"{k} / {n} = {100 * k / n:.1f} % [{down:.1f}, {up:.1f}] %"


def rates_text(n: int) -> str:
    """Markdown under :func:`summary_tables` of ``n`` runs: how its rates'
    intervals are computed and printed, and the rates figure of
    :func:`montecarlo_figures`."""
    return ("Each outcome's rate is given with its Wilson 95 % score interval (the "
            f"{n} runs as independent trials; the interval's ends rounded outwards).\n\n"
            "![Monte Carlo rates]({figdir}/montecarlo-rates.png)")


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


def refined_runs_text(n: int, big: int | None) -> str:
    """What the three-level refinement of a sweep's findings covers when
    only the first ``n`` of ``big`` runs are run at dt/2 and dt/4
    (:func:`workbench.features.refinement.share_claim_levels`; empty when
    every run is)."""
    if big is None or n >= big:
        return ""
    return (f" **Refinement of the Monte Carlo findings.** A finding on the share of an "
            f"outcome is checked at the sweep's dt (all {big} runs), dt / 2 (the first {n}: "
            f"this check) and dt / 4 (the first {n} once more; see the refinement of the "
            f"findings). The other {big - n} runs are not run at dt / 2 and dt / 4 but bounded: "
            f"if k of the first {n} have the outcome there, between k and k + {big - n} of the "
            f"{big} runs have it, whatever the others do. A level decides a finding when its "
            f"verdict is the same at every count of that range; the finding has converged "
            f"when dt, dt / 2 and dt / 4 decide it the same way, and is INCONCLUSIVE otherwise "
            f"(the refinement table shows each level's count and verdict). A claim that no "
            f"run has the outcome is decided by one refined run that has it at every level; a "
            f"bound on the rate (a Wilson interval's end) may need more of the {big} runs than "
            f"the {n} refined, and is then INCONCLUSIVE.")


def halving_section(hc, metrics, outcomes, labels, samples: int | None = None,
                    batch_note: str = "", not_compared: str = "", sig: int = 3) -> str:
    """Markdown (no heading) of a step-halving check ``hc``: what was done
    and the agreement rule, the refinement it covers (``samples``: the size
    of the sweep, None when not known; :func:`refined_runs_text`), then
    :func:`halving_tables` (``metrics``, ``outcomes``, ``labels``, ``sig``).
    The study's words: ``batch_note`` (what a batch guarantees, after "one
    batch at dt / 2"), ``not_compared`` (values left out of the comparison,
    after the missing-value rule)."""
    n, k = hc.n, sum(hc.run_agree)
    of = "the sweep's runs" if samples is None else f"the sweep's {samples} runs"
    tol = ", ".join(f"`{m}` {fmt(a)}" for m, a in hc.atol.items() if a > 0) or "none"
    text = (f"The first {n} of {of} (seed {hc.seed}, case `{hc.case}`, the same draws), "
            f"run at the sweep's dt = {fmt(hc.dt)} s, were simulated again as one batch at "
            f"dt / 2{batch_note}. A metric agrees when "
            f"|a − b| <= atol + rtol max(|a|, |b|), rtol = {fmt(hc.rtol)}, atol: {tol} "
            f"(else 0); two missing values agree, a missing and a finite one do not"
            f"{not_compared}. An outcome agrees when it is the same at both steps. "
            f"**{k} of {n} runs agree in every metric and outcome.**")
    return (text + refined_runs_text(n, samples) + "\n\n"
            + halving_tables(hc, metrics, outcomes, labels, sig))


def draw_outcome_scatter(fig, draws, panels, groups, n: int, shade=None) -> None:
    """Each run at its draws, one panel per (x draw, y draw, x label, y
    label) of ``panels``, marked by its group: ``groups`` (label, mask over
    the runs, colour, marker), each counted "k of ``n``" in the legend of
    the first panel (empty groups left out). ``shade``: (group label, a
    value per run, colour-bar label): that group's runs are coloured by the
    value when it is finite for all of them, so that a sweep where every
    run falls in the group still shows where the draws put each run."""
    for ax, (kx, ky, lx, ly) in zip(fig.subplots(1, len(panels), squeeze=False)[0], panels):
        x, y = np.asarray(draws[kx], float), np.asarray(draws[ky], float)
        for label, sel, color, marker in groups:
            if not sel.any():
                continue
            count = f"{label}: {int(sel.sum())} of {n}"
            if shade is not None and label == shade[0] and np.isfinite(shade[1][sel]).all():
                sc = ax.scatter(x[sel], y[sel], s=16, c=shade[1][sel], cmap="plasma",
                                marker=marker, label=count)
                fig.colorbar(sc, ax=ax, label=shade[2])
            else:
                ax.scatter(x[sel], y[sel], s=14, c=color, marker=marker, label=count)
        ax.set_xlabel(lx)
        ax.set_ylabel(ly)
    fig.axes[0].legend(fontsize=7)


def montecarlo_figures(res, histograms, outcomes) -> tuple[Figure, ...]:
    """The report figures of a sweep ``res``: histograms of its summary
    metrics (``histograms(fig, res)``), its outcome rates
    (:func:`draw_rates`) and its runs at their draws (``outcomes(fig, res)``),
    named ``montecarlo-histograms``, ``-rates``, ``-outcomes``."""
    return (
        Figure("montecarlo-histograms", "Monte Carlo: histograms of the summary metrics.",
               lambda fig: histograms(fig, res), (9.0, 3.2)),
        Figure("montecarlo-rates", "Monte Carlo: outcome rates, Wilson 95 % intervals.",
               lambda fig: draw_rates(fig, res), (6.0, 2.8)),
        Figure("montecarlo-outcomes", "Monte Carlo: outcome of each run against its draws.",
               lambda fig: outcomes(fig, res), (9.0, 3.8)))


def draw_histograms(fig, res, units: dict, marks: dict | None = None) -> None:
    """A histogram of each metric of ``res.SUMMARY`` over its finite values;
    ``units``: metric -> unit (x label), ``marks``: metric -> (x, label) of a
    dashed reference line."""
    marks = marks or {}
    axes = fig.subplots(1, len(res.SUMMARY), squeeze=False)[0]   # one metric: one axes
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


@dataclass(frozen=True)
class SweepWords:
    """A study's words for its sweep: all the tables and figures of this
    module need that is not general (a table of labels, units and flags).

    Attributes
    ----------
    outcomes : dict
        Outcome -> its words (:func:`summary_tables`).
    units : dict
        Summary metric -> unit (:func:`draw_histograms`).
    marks : dict
        Metric -> (x, label) of a dashed line on its histogram.
    halving_metrics, halving_outcomes : tuple of str
        What the step-halving check compares (:func:`halving_section`).
    draws : tuple
        (draw, column label) of the runs that disagree in the check.
    batch_note, not_compared : str
        The words of :func:`halving_section`.
    panels : tuple
        (x draw, y draw, x label, y label) of each panel of the outcome
        scatter (:func:`draw_outcome_scatter`).
    groups : tuple
        (label, flags set, flags not set, colour, marker) of each group of
        runs in the scatter: the runs with every flag of the first tuple and
        none of the second (flags of ``res.violations``).
    shade : (group label, metric, colour-bar label) or None
        The group coloured by a metric of its runs (NaN where missing).
    alternates : dict
        Draw -> (draw, column label, axis label) used in its place where the
        sweep has that draw (a draw that replaces another).
    """

    outcomes: dict
    units: dict
    marks: dict = field(default_factory=dict)
    halving_metrics: tuple = ()
    halving_outcomes: tuple = ()
    draws: tuple = ()
    batch_note: str = ""
    not_compared: str = ""
    panels: tuple = ()
    groups: tuple = ()
    shade: tuple | None = None
    alternates: dict = field(default_factory=dict)

    def _draw(self, key: str, label: str, drawn, axis: bool) -> tuple[str, str]:
        """(draw, label) of ``key``, or its alternate where ``drawn`` has it."""
        alt = self.alternates.get(key)
        return (alt[0], alt[2 if axis else 1]) if alt and alt[0] in drawn else (key, label)

    def tables(self, res, sig: int) -> str:
        """:func:`summary_tables` of ``res`` with :attr:`outcomes`."""
        return summary_tables(res, sig, self.outcomes)

    def histograms(self, fig, res) -> None:
        """:func:`draw_histograms` of ``res`` with :attr:`units` and :attr:`marks`."""
        draw_histograms(fig, res, self.units, self.marks)

    def halving(self, hc, samples: int | None = None, sig: int = 3) -> str:
        """:func:`halving_section` of the check ``hc`` of a sweep of
        ``samples`` runs (None: not known)."""
        labels = tuple(self._draw(d, lab, hc.draws, False) for d, lab in self.draws)
        return halving_section(hc, self.halving_metrics, self.halving_outcomes, labels,
                               samples, self.batch_note, self.not_compared, sig)

    def outcome_scatter(self, fig, res) -> None:
        """:func:`draw_outcome_scatter` of ``res`` with :attr:`panels`,
        :attr:`groups` and :attr:`shade`."""
        flag = lambda k: np.asarray(res.violations[k], bool)
        groups = []
        for label, on, off, colour, marker in self.groups:
            sel = np.ones(res.n, bool)
            for k in on:
                sel = sel & flag(k)
            for k in off:
                sel = sel & ~flag(k)
            groups.append((label, sel, colour, marker))
        panels = []
        for kx, ky, lx, ly in self.panels:
            (kx, lx), (ky, ly) = (self._draw(kx, lx, res.samples, True),
                                  self._draw(ky, ly, res.samples, True))
            panels.append((kx, ky, lx, ly))
        shade = None if self.shade is None else (self.shade[0], np.asarray(
            res.metrics.get(self.shade[1], [np.nan] * res.n), float), self.shade[2])
        draw_outcome_scatter(fig, res.samples, tuple(panels), tuple(groups), res.n, shade)

    def section(self, res, *, heading: str, intro: str, draws, summary_note: str,
                notes=(), halving=None, samples: int | None = None, sig: int = 3) -> str:
        """A report section of the sweep ``res``: ``## heading``, ``intro``,
        the ``draws`` table (rows of parameter, range), ``summary_note`` over
        :meth:`tables` (``sig`` digits), :func:`rates_text`, the study's
        ``notes`` (paragraphs), the figures' text (:data:`DRAWS_TEXT`) and,
        when given, the step-halving check ``halving`` (:meth:`halving`) of
        a sweep of ``samples`` runs."""
        parts = [f"## {heading}\n\n{intro}", md_table(["parameter", "range"], draws, "ll"),
                 summary_note, self.tables(res, sig), rates_text(res.n), *notes, DRAWS_TEXT]
        if halving is not None:
            parts.append("### Step-size check of the Monte Carlo runs\n\n"
                         + self.halving(halving, samples, sig))
        return "\n\n".join(parts)

    def figures(self, res) -> tuple[Figure, ...]:
        """:func:`montecarlo_figures` of ``res``."""
        return montecarlo_figures(res, self.histograms, self.outcome_scatter)
