"""A controller sampled at a grid of rates f_c: which rates meet the
requirements, the smallest one, and whether the plant's mesh is fine enough
(issue 20, made general in issue 35).

The model is a callback ``run(rate, scenario, q, tau, step) -> outputs``:
one scenario of the sampled loop at f_c = ``rate`` (Hz), its commands rounded
to multiples of ``q``, its measurements ``tau`` s old, the plant integrated
on a mesh of sub-steps of at most ``step``, returning a dict of outputs. The
metric declarations (:class:`RateMetrics`) say which scenarios a rate runs,
how the metrics of a rate follow from their outputs, which scenarios each
metric needs and the tolerances of the mesh check. The metrics of a rate
always include ``ok``, "yes" when the rate meets every requirement.

Every run goes through a :class:`Runs` memo keyed on (rate, scenario, q, tau,
step), so a run that the table, the bisection, the mesh check, the three
levels or a caller share is made once (issue 36).

For one variant (q, tau) (:func:`sweep_variant`):

* the grid: every rate, every scenario, at ``step``;
* the lowest passing rate: the lowest grid rate from which every higher
  grid rate passes; between it and the grid rate below, ``bisect`` steps on
  log f_c (geometric midpoints rounded to whole Hz, assuming one crossing)
  give a bracket;
* the mesh check (a two-level screen): every grid rate up to
  ``mesh_max_rate`` again at ``step`` / 2, each metric of ``mesh_atol``
  within its tolerance and the verdict the same;
* the three-level check (issue 33 item 4): every claimed
  ``(variant, rate, metric)`` at ``step`` (the grid's run), ``step`` / 2 (the
  screen's run) and ``step`` / 4 (only the scenarios the metric needs), with
  a Richardson estimate of its error (:func:`three_level_check`).

The quantities of a sweep and the rate metrics its claims compare:
:mod:`workbench.features.rate_sweep_quantities`. Test on a system of no
paper: ``tests/test_rate_sweep.py`` (a first-order loop with a sampled
proportional law).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable, Mapping

from .refinement import guarded_check
from ..jsonable import json_method
from ..sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED

__all__ = ["RateMetrics", "Runs", "RateRow", "Variant", "ThreeLevel", "three_level_check",
           "rate_row", "partial_row", "sweep_variant", "variants", "read_rates", "read_inputs",
           "SweepTable", "read_table", "load_table", "sweep", "Trace", "trace_records",
           "SweepResult"]


def variants(q: float, tau: float) -> tuple:
    """((name, q, tau), ...): ``zoh`` (exact, current samples, unquantised),
    and ``zoh_q_tau`` (commands quantised to ``q``, measurements ``tau``
    old) when either is not 0."""
    return (("zoh", 0.0, 0.0),) + ((("zoh_q_tau", q, tau),) if q or tau else ())


def read_rates(t, key: str = "rates_hz") -> tuple:
    """The grid of rates (Hz) of a design table ``t`` (a
    :class:`workbench.reader.Reader`): positive, increasing, within [1, 1e5]."""
    rates = t.numbers(key, positive=True, what="rates (Hz)")
    if any(not b > a for a, b in zip(rates, rates[1:])) or not 1.0 <= rates[0] or \
            not rates[-1] <= 1e5:
        raise t.fail(key, list(rates), "rates in Hz, increasing, within [1, 100000]")
    return rates


def read_inputs(t, unit: str) -> tuple:
    """(quantisation, measurement_delay) of a design table ``t``: optional
    quantities, the command's step in ``unit`` (positive) and the
    measurements' age in s (within [0, 0.5]); None when absent. Their values
    give the variants (:func:`variants`)."""
    return (t.quantity("quantisation", unit, positive=True, default=None),
            t.quantity("measurement_delay", "s", nonneg=True, hi=0.5, default=None))


@dataclass(frozen=True)
class SweepTable:
    """The general keys of a design's rate-sweep table (:func:`read_table`):
    the grid ``rates`` (Hz), the largest plant sub-step ``plant_step`` (s),
    the ``bisect`` steps, the optional ``quantisation`` and
    ``measurement_delay`` (:class:`workbench.reader.Quantity`) and
    ``three_level``, the ((variant, rate, metric), ...) the design's claims
    compare (:func:`workbench.features.rate_sweep_quantities.claimed_rate_metrics`).
    A system's own table subclasses it."""

    rates: tuple
    plant_step: float
    bisect: int
    quantisation: object = None
    measurement_delay: object = None
    three_level: tuple = ()

    def variants(self) -> tuple:
        """The variants of the table's inputs (:func:`variants`)."""
        q = 0.0 if self.quantisation is None else self.quantisation.value
        tau = 0.0 if self.measurement_delay is None else self.measurement_delay.value
        return variants(q, tau)


def read_table(t, unit: str, *, plant_step_hi: float) -> dict:
    """The :class:`SweepTable` keys of a design table ``t`` as keyword
    arguments (``three_level`` not included): ``rates_hz``, ``plant_step``
    (s, positive, at most ``plant_step_hi``), ``bisect`` (default 4, at most
    12), the inputs (:func:`read_inputs`, the command in ``unit``)."""
    rates = read_rates(t)
    step = t.number("plant_step", positive=True, hi=plant_step_hi, what="number (s)")
    return dict(rates=rates, plant_step=step, bisect=t.number(
        "bisect", integer=True, default=4, lo=0, hi=12, what="integer"),
        **dict(zip(("quantisation", "measurement_delay"), read_inputs(t, unit))))


def load_table(root, key: str, cls: type, unit: str, plant_step_hi: float, section,
               own: Callable = dict) -> SweepTable | None:
    """Table ``key`` of a design (its :class:`workbench.reader.Reader`
    ``root``) as a ``cls`` (a :class:`SweepTable`), None when absent: the
    system's own keys first (``own(t)`` -> keyword arguments), then the
    general ones (:func:`read_table`), ``three_level`` the rate metrics the
    design's claims compare (``section``: a
    :class:`workbench.features.rate_sweep_quantities.Section`)."""
    if not root.has(key):
        return None
    t = root.table(key)
    out = cls(**own(t), **read_table(t, unit, plant_step_hi=plant_step_hi))
    t.finish()
    return dataclasses.replace(out, three_level=section.claimed(out, root.data.get("claims", [])))


def trace_records(table: SweepTable, rates: tuple, record: Callable, reference: tuple) -> list:
    """[(variant, rate, record), ...]: ``record(rate, q, tau, step, False)``
    of every variant of ``table`` at each of ``rates`` on its grid (``step``:
    its ``plant_step``), then ``record(rate, 0, 0, step, True)`` of
    ``reference`` = (name, rate, step) (the records a figure's
    :class:`Trace` are cut from)."""
    out = [(name, f, record(f, q, tau, table.plant_step, False))
           for name, q, tau in table.variants() for f in rates if f in table.rates]
    name, rate, step = reference
    return out + [(name, rate, record(rate, 0.0, 0.0, step, True))]


@dataclass(frozen=True)
class Trace:
    """A time trace of a run for a figure: the variant's name (or a
    reference's), the rate, the times and the values ``y`` (arrays)."""

    variant: str
    rate: float
    t: object
    y: object


@dataclass(frozen=True)
class RateMetrics:
    """The metric declarations of a rate sweep.

    ``names``: the metrics of a rate (quantities ``<prefix>.<variant>.rate[<f>].<name>``);
    ``scenarios``: the scenarios a rate runs; ``combine``: {scenario: outputs
    or None (not run)} -> the metrics of a rate (``names``, ``ok`` and any
    others the rendering needs); ``needs``: scenario -> the metrics computed
    from it alone (a metric in none: from every scenario); ``mesh_atol``: metric -> largest
    difference between ``step`` and ``step`` / 2 (the mesh check);
    ``mesh_max_rate``: the mesh and three-level checks cover grid rates up
    to this (Hz); ``outputs``: the names of a run's outputs, given: a
    scenario not run reaches ``combine`` as NaN outputs instead of None."""

    names: tuple
    scenarios: tuple
    combine: Callable[[dict], dict]
    needs: Mapping[str, tuple] = field(default_factory=dict)
    mesh_atol: Mapping[str, float] = field(default_factory=dict)
    mesh_max_rate: float = math.inf
    outputs: tuple = ()

    def scenarios_of(self, metric: str) -> tuple:
        """The scenarios ``metric`` is computed from."""
        return tuple(s for s, ms in self.needs.items() if metric in ms) or tuple(self.scenarios)

    def metrics(self, got: dict) -> dict:
        """``combine`` of {scenario: outputs or None (not run)}."""
        nan = dict.fromkeys(self.outputs, math.nan) if self.outputs else None
        return self.combine({s: nan if o is None else o for s, o in got.items()})


class Runs:
    """``run(rate, scenario, q, tau, step)`` made once per distinct call.

    Parameters
    ----------
    run : callable
        The model (module docstring); its outputs are shared between the
        callers, which must not change them.
    """

    def __init__(self, run: Callable):
        self._run, self._done = run, {}

    def __call__(self, rate: float, scenario, q: float, tau: float, step: float):
        key = (rate, scenario, q, tau, step)
        if key not in self._done:
            self._done[key] = self._run(rate, scenario, q, tau, step)
        return self._done[key]

    @property
    def made(self) -> int:
        """Runs made (distinct calls)."""
        return len(self._done)


@dataclass(frozen=True)
class RateRow:
    """The metrics of one rate (``probe``: a bisection rate, not on the grid)."""

    rate: float
    metrics: dict
    probe: bool = False

    @property
    def ok(self) -> bool:
        return self.metrics["ok"] == "yes"


@dataclass(frozen=True)
class ThreeLevel:
    """A claimed rate metric at plant_step, plant_step / 2, plant_step / 4.

    ``values``: (q1, q2, q4); ``tolerance``: the bound of the Richardson
    estimate (the mesh check's tolerance of the metric, 0 for a metric
    without one; None for an outcome, which converges when the three levels
    agree); ``outcome``: a :mod:`workbench.sim.convergence` outcome;
    ``estimate``: the Richardson estimate of the error of q4 (None for an
    outcome); ``note``: why an estimate was guarded (empty otherwise)."""

    variant: str
    rate: float
    metric: str
    values: tuple
    tolerance: float | None
    outcome: str
    estimate: float | None = None
    note: str = ""

    @property
    def converged(self) -> bool:
        return self.outcome == CONVERGED

    def reason(self) -> str:
        """``not converged: ...`` (empty when converged)."""
        if self.converged:
            return ""
        shown = " / ".join(str(x) if isinstance(x, str) else f"{x:.6g}" for x in self.values)
        est = "" if self.estimate is None else (f", estimate {self.estimate:.2g} > tolerance "
                                                f"{self.tolerance:.2g}")
        return (f"not converged: {self.variant} {self.rate:g} Hz {self.metric} is {shown} at "
                f"plant_step, /2, /4{est}" + (f" ({self.note})" if self.note else ""))


def three_level_check(variant: str, rate: float, metric: str, values: tuple,
                      tolerance: float = 0.0) -> ThreeLevel:
    """The three-level check of one rate metric (``values`` at plant_step,
    /2, /4): an outcome converges when the three agree; a number when every
    level is NaN (not reached), or by
    :func:`workbench.features.refinement.guarded_check` within ``tolerance`` (the
    mesh check's; 0, rounding only, for a metric without one); NaN at some
    levels only is INCONCLUSIVE."""
    if any(isinstance(x, str) for x in values):
        same = len(set(values)) == 1
        return ThreeLevel(variant, rate, metric, values, None,
                          CONVERGED if same else NOT_CONVERGED)
    nans = sum(math.isnan(x) for x in values)
    if nans:
        return ThreeLevel(variant, rate, metric, values, tolerance,
                          CONVERGED if nans == 3 else INCONCLUSIVE, None,
                          "" if nans == 3 else "reached at some levels only")
    r = guarded_check(*values, tolerance=tolerance)
    return ThreeLevel(variant, rate, metric, values, tolerance, r.outcome, r.estimate, r.note)


@dataclass(frozen=True)
class Variant:
    """One sampled controller (q, tau) over the grid.

    ``min_rate``: lowest grid rate from which every higher grid rate passes
    (None: the highest fails); ``bracket``: (highest failing, lowest passing)
    rate known after bisection (None on a side with no rate); ``mesh``:
    (rate, agree, {metric: |difference|}) of the mesh check; ``mesh_rows``:
    its RateRows at step / 2; ``three_level``: the :class:`ThreeLevel` check
    of every claimed rate metric of the variant; ``quarter_rows``: its
    RateRows at step / 4 (the metrics of the scenarios run only)."""

    name: str
    q: float
    tau: float
    rows: tuple
    probes: tuple
    min_rate: float | None
    bracket: tuple
    mesh: tuple
    mesh_rows: tuple = field(default=(), compare=False)
    three_level: tuple = ()
    quarter_rows: tuple = field(default=(), compare=False)

    def row(self, rate: float) -> RateRow:
        return next(r for r in self.rows if r.rate == rate)

    @property
    def mesh_converged(self) -> bool:
        """The two-level screen agrees at every rate and every claimed rate
        metric converged over three levels."""
        return all(a for _, a, _ in self.mesh) and all(t.converged for t in self.three_level)

    def json(self) -> dict:
        """The variant as JSON-able values (the mesh check's rows not included)."""
        rows = lambda rr: [{"rate_hz": r.rate, **r.metrics} for r in rr]    # noqa: E731
        return {"q": self.q, "tau": self.tau, "rows": rows(self.rows),
                "probes": rows(self.probes), "min_rate": self.min_rate,
                "bracket": self.bracket,
                "three_level": [{"rate_hz": t.rate, "metric": t.metric, "values": t.values,
                                 "outcome": t.outcome, "estimate": t.estimate,
                                 "tolerance": t.tolerance} for t in self.three_level]}


def rate_row(runs: Runs, decl: RateMetrics, rate: float, q: float, tau: float, step: float,
             probe: bool = False) -> RateRow:
    """Every scenario of ``decl`` at one rate."""
    return RateRow(rate, decl.metrics({s: runs(rate, s, q, tau, step)
                                       for s in decl.scenarios}), probe)


def partial_row(runs: Runs, decl: RateMetrics, rate: float, scenarios: tuple, q: float,
                tau: float, step: float) -> RateRow:
    """The metrics of ``scenarios`` at one rate: those computed from them
    alone, from the runs :func:`rate_row` makes (the same calls, the same
    numbers)."""
    got = {s: runs(rate, s, q, tau, step) if s in scenarios else None for s in decl.scenarios}
    m = decl.metrics(got)
    return RateRow(rate, {k: v for k, v in m.items()
                          if set(decl.scenarios_of(k)) <= set(scenarios)})


def _bisect(runs, decl, q, tau, step, lo: float, hi: float, steps: int) -> tuple:
    """Rates probed between a failing ``lo`` and a passing ``hi`` (Hz),
    geometric midpoints rounded to whole Hz; returns (probes, lo, hi)."""
    probes = []
    for _ in range(steps):
        mid = float(round(math.sqrt(lo * hi)))
        if not lo < mid < hi:
            break
        row = rate_row(runs, decl, mid, q, tau, step, probe=True)
        probes.append(row)
        lo, hi = (lo, mid) if row.ok else (mid, hi)
    return tuple(probes), lo, hi


def _mesh_check(runs, decl, q, tau, step, rows) -> tuple:
    """Grid rates up to ``mesh_max_rate`` again at step / 2: ((rate, agree,
    {metric: |difference|}), ...) and the RateRows at step / 2."""
    out, fines = [], []
    for row in rows:
        if row.rate > decl.mesh_max_rate:
            continue
        fine = rate_row(runs, decl, row.rate, q, tau, step / 2)
        fines.append(fine)
        diffs, agree = {}, fine.metrics["ok"] == row.metrics["ok"]
        for k, tol in decl.mesh_atol.items():
            a, b = row.metrics[k], fine.metrics[k]
            same_nan = math.isnan(a) and math.isnan(b)
            d = 0.0 if same_nan else abs(a - b)
            diffs[k] = d
            agree = agree and (same_nan or d <= tol)
        out.append((row.rate, agree, diffs))
    return tuple(out), tuple(fines)


def _three_level(runs, decl, name, q, tau, step, claimed, rows, fines) -> tuple:
    """The claimed rate metrics of variant ``name`` at step (``rows``),
    step / 2 (``fines``) and step / 4 (run here, the scenarios they need);
    returns (ThreeLevel rows, RateRows at step / 4)."""
    need: dict = {}
    for v, rate, metric in claimed:
        if v == name:
            need.setdefault(rate, set()).update(decl.scenarios_of(metric))
    quarter = tuple(partial_row(runs, decl, rate, tuple(sorted(sc)), q, tau, step / 4)
                    for rate, sc in sorted(need.items()))
    by = lambda rr, f: next(r for r in rr if r.rate == f)     # noqa: E731
    checks = tuple(three_level_check(name, rate, metric, tuple(
        by(rr, rate).metrics[metric] for rr in (rows, fines, quarter)),
        decl.mesh_atol.get(metric, 0.0)) for v, rate, metric in claimed if v == name)
    return checks, quarter


def sweep_variant(runs: Runs, decl: RateMetrics, rates: tuple, step: float, name: str,
                  q: float, tau: float, *, bisect: int = 4, claimed: tuple = ()) -> Variant:
    """The grid ``rates`` (Hz, increasing), the lowest passing rate, its
    bisection bracket (``bisect`` steps), the mesh check and the three-level
    check of the ``claimed`` ((variant, rate, metric), ...) rate metrics of
    variant ``name`` (module docstring)."""
    rows = tuple(rate_row(runs, decl, f, q, tau, step) for f in rates)
    min_rate = None
    for r in reversed(rows):
        if not r.ok:
            break
        min_rate = r.rate
    probes, bracket = (), (None, min_rate)
    if min_rate is not None and min_rate > rates[0]:
        below = rates[rates.index(min_rate) - 1]
        probes, lo, hi = _bisect(runs, decl, q, tau, step, below, min_rate, bisect)
        bracket = (lo, hi)
    elif min_rate is None:
        bracket = (rates[-1], None)
    mesh, fines = _mesh_check(runs, decl, q, tau, step, rows)
    checks, quarter = _three_level(runs, decl, name, q, tau, step, claimed, rows, fines)
    return Variant(name, q, tau, rows, probes, min_rate, bracket, mesh, fines, checks, quarter)


def sweep(runs: Runs, decl: RateMetrics, table: SweepTable) -> tuple:
    """Every variant of ``table`` over its grid (:func:`sweep_variant`)."""
    return tuple(sweep_variant(runs, decl, table.rates, table.plant_step, name, q, tau,
                               bisect=table.bisect, claimed=table.three_level)
                 for name, q, tau in table.variants())


@dataclass(frozen=True)
class SweepResult:
    """A sweep as a section shows it: its table ``spec``
    (:class:`SweepTable`), the ``reference`` row (the controller not
    sampled, say) at step ``reference_step``, the ``variants``
    (:func:`sweep`), the windows replayed against Radau (``checks``,
    :class:`workbench.features.mesh_replay.WindowCheck`) and the figure's
    ``traces`` (:class:`Trace`). A system's own result subclasses it."""

    spec: SweepTable
    reference: RateRow
    reference_step: float
    variants: tuple
    checks: tuple = ()
    traces: tuple = ()

    def variant(self, name: str) -> Variant:
        return next(v for v in self.variants if v.name == name)

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"reference": "reference.metrics",
                   "variants": lambda r: {v.name: v.json() for v in r.variants},
                   "checks": "checks"}
    to_json = json_method
