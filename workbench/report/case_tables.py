"""Tables of a study that runs several named cases of one closed loop.

A *case* is one configuration of a run (a controller variant, a scenario);
its metrics map a metric key to a float, NaN where the run never reached
what the metric measures. ``labels`` map a metric key to (label, unit,
significant digits). The caller supplies every word about its system; these
functions only lay the values out:

* :func:`case_metric_table`: one row per metric, one column per case;
* :func:`case_convergence_table`: each case's metrics at dt, dt/2 and, when
  run, dt/4, with the convergence verdict; :func:`case_convergence_section`:
  that table under a heading that says how the levels are judged;
* :func:`event_cell`: whether and when an event happened, a cell of an
  extra row of :func:`case_metric_table`;
* :func:`case_rows`: one row per case with a placeholder row for a case
  without the item (a phase switch never reached, say).

Used by the ``antiskid-run`` study (paper 003) and the ``switched-run`` kind;
``tests/test_case_tables.py`` renders a toy system with them.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Iterable, Mapping, Sequence

from .markdown import fmt, md_table

#: The cell of a value that does not exist (not reached, not run).
MISSING = "—"

Labels = Mapping[str, tuple[str, str, int]]


def present(x: float | None) -> float | None:
    """``None`` (printed :data:`MISSING` by :func:`fmt`) for a NaN, else ``x``."""
    return None if x is None or math.isnan(x) else x


def fmt_finite(x: float | None, sig: int) -> str:
    """``x`` with ``sig`` digits, :data:`MISSING` for None, NaN or an infinity."""
    return MISSING if x is None or not math.isfinite(x) else fmt(x, sig)


def event_cell(t: float, where: Callable[[], str], sig: int = 4) -> str:
    """Whether and when an event (a divergence, say) happened in a case's
    run: "no" for a NaN time ``t``, else "yes, t = <t> s (<where()>)";
    ``where`` is called only when it happened (its values exist then)."""
    return "no" if math.isnan(t) else f"yes, t = {fmt(t, sig)} s ({where()})"


def case_metric_table(names: Sequence[str], metrics: Sequence[Mapping[str, float]],
                      keys: Iterable[str], labels: Labels,
                      extra_rows: Iterable[Sequence[object]] = ()) -> str:
    """One row per metric key (label, unit, then each case's value), one
    column per case; a NaN value prints :data:`MISSING`.

    Parameters
    ----------
    names : case names, in column order.
    metrics : each case's metrics, in the same order.
    keys : the metric keys shown, in row order.
    labels : key -> (label, unit, significant digits).
    extra_rows : rows appended as given (label, unit, one cell per case).
    """
    rows = []
    for key in keys:
        label, unit, sig = labels[key]
        rows.append([label, unit] + [fmt(present(m[key]), sig) for m in metrics])
    rows += [list(r) for r in extra_rows]
    return md_table(["metric", "unit"] + [f"`{n}`" for n in names], rows,
                    "ll" + "r" * len(names))


@dataclass(frozen=True)
class CaseLevels:
    """A case's metrics at the step dt, at dt/2 and (``quarter``, None when
    not run) at dt/4, and its per-metric verdict ``ok``: converged (three
    levels) or, with two levels only, dt and dt/2 agree."""

    name: str
    coarse: Mapping[str, float]
    fine: Mapping[str, float]
    quarter: Mapping[str, float] | None
    ok: Mapping[str, bool]


def case_convergence_table(cases: Iterable[CaseLevels], labels: Labels,
                           sig: int = 6) -> str:
    """Every case's metrics (the keys of ``labels``, in order) at dt, dt/2,
    dt/4 with the verdict; a metric NaN at every level is left out. With two
    levels the verdict says only whether they agree (no convergence claim)."""
    rows = []
    for c in cases:
        for key, (label, _unit, _sig) in labels.items():
            a, b = c.coarse[key], c.fine[key]
            q4 = math.nan if c.quarter is None else c.quarter[key]
            if math.isnan(a) and math.isnan(b) and math.isnan(q4):
                continue
            if c.quarter is None:
                verdict = "(dt, dt/2 " + ("agree)" if c.ok[key] else "differ)")
            else:
                verdict = "yes" if c.ok[key] else "**no**"
            rows.append([f"`{c.name}`", label, fmt(a, sig), fmt(b, sig),
                         MISSING if c.quarter is None else fmt(q4, sig), verdict])
    return md_table(["case", "metric", "dt", "dt/2", "dt/4", "converged"], rows, "llrrrl")


def case_convergence_section(cases: Iterable[CaseLevels], labels: Labels, dt: float,
                             rtol: float, p_min: float) -> str:
    """A ``## Convergence in the step size`` section: the levels run (dt,
    dt/2 reported, dt/4 where a claim states convergence), the verdict (the
    guarded Richardson estimate of
    :func:`workbench.features.refinement.guarded_check` within ``rtol`` of
    the largest |value| plus the design's atol; ``p_min``: the order it
    assumes where the differences change sign), then
    :func:`case_convergence_table`."""
    return ("## Convergence in the step size\n\nEvery metric computed at dt = "
            f"{fmt(dt)} s and dt/2 = {fmt(dt / 2)} s (reported), and at dt/4 for a "
            "case whose convergence a claim states. Converged: the Richardson error "
            "estimate of the three levels (`workbench.features.refinement.guarded_check`; levels "
            "whose differences change sign are not in the asymptotic range and are "
            f"estimated from the larger difference at order {fmt(p_min)}) is within "
            f"rtol = {fmt(rtol)} of the largest |value| plus the design's atol. "
            "A case without a dt/4 run shows only whether dt and dt/2 agree within that "
            "tolerance, which is no convergence.\n\n"
            + case_convergence_table(cases, labels))


def case_rows(items: Iterable[tuple[str, object]], cells: Callable[[object], Sequence[object]],
              missing: Sequence[object]) -> list[list[object]]:
    """One row per (case name, item): the name in code font, then
    ``cells(item)``, or ``missing`` when the item is None."""
    return [[f"`{name}`"] + list(missing if item is None else cells(item))
            for name, item in items]
