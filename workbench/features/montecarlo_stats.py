"""Statistics of a Monte Carlo sweep's runs: per-metric summaries over the
finite values and the rates of outcomes with their Wilson 95 % intervals.

A sweep is any batch of independent runs; what a run computes is the
caller's (a kernel, a simulation, a model callback). Its result is
:class:`RunsResult`: the drawn samples, per-run metrics (floats, NaN where a
run did not determine one) and per-run outcome flags ("violations"), plus
the wall time and worker count. A study declares which metrics it summarises
and which outcomes it rates (class attributes of a subclass), and reads them
back as flat ``"<metric>.<statistic>"``, ``"fraction.<flag>"`` and
``"wilson.<outcome>.lo|hi"`` quantities (:meth:`RunsResult.statistics`),
declared once for its claims (:func:`runs_quantities`).

The outcome ``OK`` is a run with none of the flags.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .montecarlo import wilson_interval

__all__ = ["OK", "STATISTICS", "RunsResult", "finite_span", "runs_quantities", "summary_row"]

#: Statistics of each summarised metric (over its finite values).
STATISTICS = ("n_finite", "min", "median", "p95", "max")
#: The outcome of a run with no flag set.
OK = "ok"


def summary_row(name: str, values) -> list:
    """[name, n finite, min, median, 95th percentile, max] of ``values``
    over its finite entries (None for each statistic when there is none;
    numpy's linear-interpolation percentile)."""
    x = np.asarray(values, float)
    ok = x[np.isfinite(x)]
    if ok.size == 0:
        return [name, 0, None, None, None, None]
    return [name, int(ok.size), float(ok.min()), float(np.median(ok)),
            float(np.percentile(ok, 95)), float(ok.max())]


def finite_span(values) -> tuple:
    """(min, max) of the non-NaN entries of ``values``; (None, None) when
    every entry is NaN (or there is none)."""
    v = np.asarray(values, float)
    ok = ~np.isnan(v)
    return (float(np.min(v[ok])), float(np.max(v[ok]))) if ok.any() else (None, None)


@dataclass(frozen=True)
class RunsResult:
    """The runs of one Monte Carlo sweep.

    Attributes
    ----------
    samples : dict
        Drawn factor -> list of floats (one per run).
    metrics : dict
        Metric -> list of floats (NaN: not determined by the run).
    violations : dict
        Flag -> list of bool (one per run).
    seconds : float
        Wall time of the sweep (NaN: read back from files).
    workers : int

    Class attributes (a study's subclass sets them)
    -----------------------------------------------
    SUMMARY : tuple of str
        The metrics :meth:`summary_rows` summarises.
    OUTCOMES : tuple of str
        The outcomes :meth:`outcome_rates` rates: flags of ``violations``
        and :data:`OK` (no flag set).
    """

    samples: dict
    metrics: dict
    violations: dict
    seconds: float
    workers: int

    SUMMARY: ClassVar[tuple] = ()
    OUTCOMES: ClassVar[tuple] = ()

    @property
    def n(self) -> int:
        """The number of runs."""
        return len(next(iter(self.metrics.values())))

    def summary_rows(self) -> list[list]:
        """:func:`summary_row` of each metric of ``SUMMARY``."""
        return [summary_row(k, self.metrics[k]) for k in self.SUMMARY]

    def outcome_rates(self) -> list[tuple]:
        """(outcome, k, n, k / n, lo, hi) per ``OUTCOMES``: the runs with the
        outcome and the Wilson 95 % score interval of its rate."""
        flags = {k: np.asarray(v, bool) for k, v in self.violations.items()}
        flags[OK] = ~np.logical_or.reduce(list(flags.values()))
        return [(o, *wilson_interval(int(flags[o].sum()), self.n)) for o in self.OUTCOMES]

    def statistics(self) -> dict:
        """``{"<metric>.<statistic>": value}`` from :meth:`summary_rows`,
        ``{"fraction.<flag>": value}`` (fraction of all runs) and
        ``{"wilson.<outcome>.lo" | ".hi": bound}`` (:meth:`outcome_rates`).

        Computed once per result (the result is frozen; :func:`runs_quantities`
        reads one key per declared quantity); a copy is returned."""
        memo = self.__dict__.get("_statistics")
        if memo is None:
            memo = {f"{r[0]}.{s}": x for r in self.summary_rows()
                    for s, x in zip(STATISTICS, r[1:])}
            memo.update({f"fraction.{k}": sum(v) / self.n for k, v in self.violations.items()})
            for o, _, _, _, lo, hi in self.outcome_rates():
                memo[f"wilson.{o}.lo"], memo[f"wilson.{o}.hi"] = lo, hi
            object.__setattr__(self, "_statistics", memo)
        return dict(memo)


def runs_quantities(prefix: str, summary, flags, outcomes) -> tuple:
    """A sweep's quantities, declared once
    (:class:`~workbench.features.quantities.Declared`, reading a
    :class:`RunsResult`; a study puts them in a
    :class:`~workbench.features.quantities.Part` of its result):
    ``<prefix>.samples`` (the runs), ``<prefix>.<metric>.<statistic>`` of each
    ``summary`` metric, ``<prefix>.fraction.<flag>`` of each of ``flags`` and
    ``<prefix>.wilson.<outcome>.lo`` / ``.hi`` of each of ``outcomes``
    (:meth:`RunsResult.statistics`; None: no finite value)."""
    from .quantities import Declared
    keys = ([f"{m}.{s}" for m in summary for s in STATISTICS] + [f"fraction.{k}" for k in flags]
            + [f"wilson.{o}.{b}" for o in outcomes for b in ("lo", "hi")])
    return (Declared(f"{prefix}.samples", "1", lambda res: res.n),
            Declared(prefix + ".{key}", "?", lambda res, key: res.statistics()[key],
                     over=lambda spec: [{"key": k} for k in keys]))
