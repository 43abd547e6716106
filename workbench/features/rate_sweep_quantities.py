"""The quantities of a rate sweep (:mod:`workbench.features.rate_sweep`)
and the rate metrics its claims compare (issue 20, made general in issue 35).

A sweep in a report has a quantity prefix, the metrics of a rate, a
reference row (the controller not sampled, say), metrics compared between
the highest grid rate and the reference (gaps) and quantities that are a
rate metric minus the reference's (differences); :class:`Section` holds
them. Test on a system of no paper: ``tests/test_rate_sweep.py``.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Callable, Mapping

if TYPE_CHECKING:
    from .rate_sweep import SweepTable, Variant

__all__ = ["Section", "claimed_rate_metrics", "quantity_value", "quantity_names", "quantities",
           "sweep_quantity_names", "sweep_quantities"]


@dataclass(frozen=True)
class Section:
    """The names of a rate sweep in a report: quantities
    ``<prefix>.<reference>.<m>`` and ``<prefix>.<variant>...``
    (:func:`sweep_quantities`) of the rate metrics ``metrics``, the ``gaps``
    to the reference and the ``differences`` (quantity -> the rate metric
    it is the difference to the reference of); the three-level checks
    cover grid rates up to ``max_rate`` (Hz); ``extra_names`` are the
    section's other quantities (of its replay checks, say), ``extra(res)``
    their values."""

    prefix: str
    metrics: tuple
    max_rate: float
    reference: str
    gaps: tuple = ()
    differences: Mapping[str, str] = field(default_factory=dict)
    extra_names: tuple = ()
    extra: Callable | None = None

    def claimed(self, table, claims) -> tuple:
        """The rate metrics the ``[[claims]]`` tables ``claims`` compare on
        the grid of ``table`` (a :class:`workbench.features.rate_sweep.SweepTable`;
        :func:`claimed_rate_metrics`, a difference counting as its rate metric)."""
        return claimed_rate_metrics(self.prefix, [n for n, _, _ in table.variants()],
                                    table.rates, self.metrics, self.max_rate, claims,
                                    self.differences)

    def quantity_names(self, table) -> set[str]:
        """The quantities of a sweep of ``table`` (:func:`sweep_quantity_names`)."""
        return sweep_quantity_names(self.prefix, table, self.metrics, self.reference, self.gaps,
                                    tuple(self.differences)) | set(self.extra_names)

    def quantities(self, res) -> dict:
        """Their values for ``res`` (a :class:`workbench.features.rate_sweep.SweepResult`)."""
        return {**sweep_quantities(self.prefix, res.variants, self.metrics, self.reference,
                                   res.reference.metrics, self.gaps, self.differences),
                **(self.extra(res) if self.extra else {})}

    def rate_pattern(self) -> re.Pattern:
        """The start of a rate quantity ``<prefix>.<variant>.rate[<f>].``
        (groups: the variant, the rate)."""
        return re.compile(re.escape(self.prefix) + r"\.([a-z_]+)\.rate\[([^\]]+)\]\.")

    def levels(self, res, quantity: str, runs, decl):
        """A rate quantity ``<prefix>.<variant>.rate[<f>].<m>`` of the sweep
        ``res`` at plant_step (reported), plant_step / 2 and plant_step / 4, as
        :class:`workbench.features.refinement.Levels`: each finer level is
        the sweep's own row when it ran one there (the mesh check's at / 2,
        the three-level check's at / 4, which has the scenarios ``m``
        needs), else the rate's row made by the model ``runs``, ``decl`` (a
        :class:`~workbench.features.rate_sweep.Runs` memo, each run made
        once whatever quantity asks, and its
        :class:`~workbench.features.rate_sweep.RateMetrics`); the value at a
        level is the quantity of the sweep with that row in place of the
        grid's (so a difference to the reference stays one)."""
        from .rate_sweep import rate_row
        from .refinement import Levels
        m = self.rate_pattern().match(quantity)
        name, rate = m[1], float(m[2])
        if rate not in res.spec.rates:
            return Levels((), reason=f"rate {rate:g} Hz is not a grid rate")
        v, metric = res.variant(name), quantity.rsplit(".", 1)[1]
        metric = self.differences.get(metric, metric)
        half = next((r for r in v.mesh_rows if r.rate == rate), None)
        quarter = next((r for r in v.quarter_rows if r.rate == rate and metric in r.metrics),
                       None)
        if quarter is not None:   # the scenarios it ran, the grid's metrics for the others
            quarter = replace(quarter, metrics={**v.row(rate).metrics, **quarter.metrics})
        vals = [self.quantities(res).get(quantity)]
        for k, row in ((1, half), (2, quarter)):
            if row is None:
                row = rate_row(runs, decl, rate, v.q, v.tau, res.spec.plant_step / 2 ** k)
            alt = replace(v, rows=tuple(row if x.rate == rate else x for x in v.rows))
            vals.append(self.quantities(replace(res, variants=tuple(
                alt if x.name == name else x for x in res.variants))).get(quantity))
        return Levels(tuple(vals), "plant_step", res.spec.plant_step)


def claimed_rate_metrics(prefix: str, variants, rates: tuple, names: tuple, max_rate: float,
                         claims, alias: Mapping[str, str] | None = None) -> tuple:
    """((variant, rate, metric), ...), sorted: the rate metrics that the
    ``[[claims]]`` tables ``claims`` (raw TOML tables; a malformed one is
    skipped here and reported by the claims' own validation) compare as
    ``<prefix>.<variant>.rate[<f>].<metric>`` (``variants``: their names;
    ``metric`` in ``names``), at a grid rate up to ``max_rate``; ``alias``: quantity -> the rate metric it moves
    with (a difference to a reference, say)."""
    pattern = re.compile(r"^" + re.escape(prefix) + r"\.([a-z_]+)\.rate\[([^\]]+)\]\.([a-z0-9_]+)$")
    known, alias = set(variants), alias or {}
    out = set()
    for c in claims if isinstance(claims, list) else ():
        m = pattern.match(str(c.get("quantity", ""))) if isinstance(c, dict) else None
        if m is None or m[1] not in known:
            continue
        try:
            rate = float(m[2])
        except ValueError:
            continue
        metric = alias.get(m[3], m[3])
        if rate in rates and rate <= max_rate and metric in names:
            out.add((m[1], rate, metric))
    return tuple(sorted(out))


def quantity_value(x):
    """A quantity value: None for NaN."""
    return None if isinstance(x, float) and math.isnan(x) else x


def quantity_names(prefix: str, name: str, rates: tuple, metrics: tuple,
                   reference: str = "", gaps: tuple = (), differences=()) -> set[str]:
    """The quantities of variant ``name`` (:func:`quantities`)."""
    b = f"{prefix}.{name}"
    return ({f"{b}.{k}" for k in ("min_rate", "bracket_low", "bracket_high", "mesh_converged")}
            | {f"{b}.gap_to_{reference}.{m}" for m in gaps}
            | {f"{b}.rate[{f:g}].{m}" for f in rates for m in tuple(metrics) + tuple(differences)})


def quantities(prefix: str, v: Variant, metrics: tuple, reference: str = "",
               ref: dict | None = None, gaps: tuple = (), differences=None) -> dict:
    """The quantities of a variant: ``<prefix>.<name>.min_rate``,
    ``.bracket_low``, ``.bracket_high``, ``.mesh_converged`` ("yes" or None),
    ``.gap_to_<reference>.<m>`` (|top grid rate - ``ref``| of each metric of
    ``gaps``), and per grid rate ``.rate[<f>].<m>`` of ``metrics`` and of
    ``differences`` (name -> metric: the metric minus ``ref``'s); None for
    NaN."""
    b = f"{prefix}.{v.name}"
    q = {f"{b}.min_rate": v.min_rate}
    q[f"{b}.bracket_low"], q[f"{b}.bracket_high"] = v.bracket
    q[f"{b}.mesh_converged"] = "yes" if v.mesh_converged else None
    top = v.rows[-1].metrics
    for m in gaps:
        q[f"{b}.gap_to_{reference}.{m}"] = quantity_value(abs(top[m] - ref[m]))
    for r in v.rows:
        q.update({f"{b}.rate[{r.rate:g}].{m}": quantity_value(r.metrics[m]) for m in metrics})
        for d, m in (differences or {}).items():
            q[f"{b}.rate[{r.rate:g}].{d}"] = quantity_value(r.metrics[m] - ref[m])
    return q


def sweep_quantity_names(prefix: str, table: SweepTable, metrics: tuple, reference: str,
                         gaps: tuple = (), differences=()) -> set[str]:
    """The quantities of a sweep (:func:`sweep_quantities`)."""
    names = {f"{prefix}.{reference}.{m}" for m in metrics}
    for name, _, _ in table.variants():
        names |= quantity_names(prefix, name, table.rates, metrics, reference, gaps,
                                differences)
    return names


def sweep_quantities(prefix: str, variants_: tuple, metrics: tuple, reference: str,
                     ref: dict, gaps: tuple = (), differences=None) -> dict:
    """The quantities of a sweep: ``<prefix>.<reference>.<m>`` of the
    reference's metrics ``ref``, then those of every variant
    (:func:`quantities`)."""
    q = {f"{prefix}.{reference}.{m}": quantity_value(ref[m]) for m in metrics}
    for v in variants_:
        q.update(quantities(prefix, v, metrics, reference, ref, gaps, differences))
    return q
