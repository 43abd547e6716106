"""Delay-LMI benchmark: every analysis criterion on literature examples with
known exact margins (``workbench benchmark delay``).

Examples are data files (``designs/benchmarks/*.toml``, one ``[example]``
table each: name, title, source, A, Ad); the settings come from a design of
kind ``delay-benchmark`` (``designs/delay-benchmarks.toml``), so the CLI
table, the report and the claims are one computation. Published numbers
appear only as claims of that design.

For each example: the exact margin by two independent methods
(:func:`~workbench.margins.delay_margin_eig`,
:func:`~workbench.margins.delay_margin_sweep`) and the exact stability
windows up to the search cap, then for each method two certificates, kept
apart (issue 13): the **point** bound of the shared bisection (stable at
that delay; its ratio to the exact margin) and the **interval** certificate
(stable for every constant delay in [lo, hi], :mod:`workbench.lmi.interval`),
each compared with the exact windows (:mod:`workbench.benchmark_windows`);
solver calls and seconds, and optionally the rational re-check of the point
certificate (:mod:`workbench.lmi.exact_check`).
"""
from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .benchmark_windows import (Compiled, abscissa_curve, directed, exact_windows,
                                implies_next, interval_fields, middle, monotone, settle_point,
                                show_window)
from .errors import DesignError
from .lmi.analysis import METHODS, certified_delay
from .lmi.core import DEFAULT_MARGIN
from .lmi.hierarchy import bessel_legendre_auto
from .margins import (AGREEMENT_RTOL, Agreement, DelayMargin, compare_margins, delay_margin_eig,
                      delay_margin_sweep)
from .reader import Reader, display_path
from .toml_input import load_toml

AUTO = "bessel-legendre-auto"


@dataclass(frozen=True)
class Example:
    """A literature example x' = A x + A_d x(t - h) (matrices as nested tuples)."""

    name: str
    title: str
    source: str
    A: tuple
    Ad: tuple
    path: str


@dataclass(frozen=True)
class BenchmarkSettings:
    """What to run (from the ``[benchmark]`` table of a delay-benchmark design).

    Attributes
    ----------
    examples : str
        Folder of example files, relative to the design file.
    methods : tuple[str, ...]
        Subset of :data:`~workbench.lmi.analysis.METHODS`.
    orders : int
        Bessel-Legendre orders 0..orders are tabulated.
    N_max : int
        Cap of the automatic order search.
    gap_tol : float
        Automatic mode stops when 1 - h_N / h* < gap_tol.
    margin, rel_tol, h_max : float
        LMI definiteness margin, bracket width, delay search cap (s).
    exact_check : bool
        Re-check every certificate in rational arithmetic.
    """

    examples: str = "benchmarks"
    methods: tuple[str, ...] = METHODS
    orders: int = 5
    N_max: int = 8
    gap_tol: float = 1e-4
    margin: float = DEFAULT_MARGIN
    rel_tol: float = 1e-5
    h_max: float = 100.0
    exact_check: bool = False


@dataclass(frozen=True)
class MethodRow:
    """One method on one example: a point and an interval certificate.

    ``h_certified`` is the largest delay at which the criterion certified
    stability — a **point** certificate, "stable at h" (s; ``inf`` for a
    certified delay-independent test; ``h_max`` means "at least h_max"),
    ``ratio`` = h_certified / h* (None when h* is infinite, except 1.0 when
    both are), ``exact_check`` the rational re-check outcome of the point
    certificate (None when not run or nothing was certified), ``outcome`` the
    bracket's outcome (``certified`` / ``refuted`` / ``inconclusive``) and
    ``at_cap`` whether ``h_certified`` is only the search cap. ``interval``
    is the **interval** certificate [lo, hi] — stable for every constant
    delay in it (:func:`~workbench.lmi.interval.certified_interval`; from 0
    when found, else the longest window) — or None, ``intervals`` every
    disjoint certified interval (one per window reached); ``interval_ratio`` its
    end over h* when it starts at 0. ``point_sound`` / ``interval_sound``:
    the point lies in an exact stable window / the interval lies inside one
    (None when nothing was certified). ``interval_solves`` is 0 for a
    Bessel-Legendre order whose interval is order N - 1's, implied without a
    search (:func:`~workbench.benchmark_windows.implies_next`).
    """

    method: str
    N: int | None
    h_certified: float
    h_refuted: float
    ratio: float | None
    solves: int
    seconds: float
    exact_check: str | None
    outcome: str = "inconclusive"
    at_cap: bool = False
    interval: tuple[float, float] | None = None
    intervals: tuple[tuple[float, float], ...] = ()
    interval_solves: int = 0
    point_sound: bool | None = None
    interval_sound: bool | None = None
    interval_ratio: float | None = None

    def to_json(self, *, with_check: bool = False) -> dict:
        d = {"method": self.method, "N": self.N, "h_certified": _j(self.h_certified),
             "h_refuted": _j(self.h_refuted), "outcome": self.outcome, "at_cap": self.at_cap,
             "ratio": _j(self.ratio), "solves": self.solves, "seconds": round(self.seconds, 4),
             "certified_interval": None if self.interval is None else
             [_j(self.interval[0]), _j(self.interval[1])],
             "certified_intervals": [[_j(a), _j(b)] for a, b in self.intervals],
             "interval_ratio": _j(self.interval_ratio), "interval_solves": self.interval_solves}
        if with_check:
            d["exact_check"] = self.exact_check
        return d


#: Below this relative difference two exact margins differ by rounding only.
AGREEMENT_FLOOR = 1e-12


def agreement_bound(rel_diff: float) -> float:
    """The power of ten a relative difference stays below, floored at
    :data:`AGREEMENT_FLOOR` (``inf`` stays ``inf``): the digits of an
    agreement that hold on every CPU (rounding differs between kernels)."""
    if not math.isfinite(rel_diff):
        return math.inf
    return max(AGREEMENT_FLOOR, 10.0 ** math.ceil(math.log10(rel_diff))) if rel_diff > 0 \
        else AGREEMENT_FLOOR


@dataclass(frozen=True)
class ExampleResult:
    """One example: exact margins, exact stability windows within [0, h_max]
    (``hi = inf``: stable for every larger delay), the spectral abscissa on a
    grid (h, alpha) for the figure, and one row per method."""

    example: Example
    exact: DelayMargin
    exact_sweep: DelayMargin
    rows: tuple[MethodRow, ...]
    windows: tuple[tuple[float, float], ...] = ()
    abscissa: tuple[tuple[float, float], ...] = ()

    @property
    def sound(self) -> bool:
        """No certified point outside, and no certified interval across, the
        exact stability windows."""
        return all(r.point_sound is not False and r.interval_sound is not False
                   for r in self.rows)

    @property
    def agreement(self) -> float:
        """Relative difference |a - b| / max(|a|, |b|) of the two exact methods
        (0 when equal, inf when only one is infinite; no absolute floor)."""
        return compare_margins(self.exact, self.exact_sweep, AGREEMENT_RTOL)[1]

    @property
    def exact_agree(self) -> bool:
        """The two exact methods agree (same reason, relative difference <=
        :data:`~workbench.margins.AGREEMENT_RTOL`)."""
        return compare_margins(self.exact, self.exact_sweep,
                               AGREEMENT_RTOL)[0] is Agreement.AGREE

    def row(self, method: str, N: int | None = None) -> MethodRow | None:
        return next((r for r in self.rows if r.method == method and
                     (N is None or r.N == N)), None)

    def bl_monotone(self, slack: float) -> bool:
        """Bessel-Legendre bounds non-decreasing in N (relative slack for the
        bisection's bracket width)."""
        hs = [r.h_certified for r in sorted((r for r in self.rows if
                                             r.method == "bessel-legendre"), key=lambda r: r.N)]
        return all(b >= a * (1 - slack) for a, b in zip(hs, hs[1:]))


@dataclass(frozen=True)
class BenchmarkResult:
    settings: BenchmarkSettings
    examples: tuple[ExampleResult, ...]

    def to_json(self, *, with_check: bool = False) -> dict:
        """``{"h_max", "exact_methods_agree", "examples": [{"name", "exact_margin",
        "exact_margin_sweep", "exact_agreement", "exact_methods_agree", "methods":
        [{"method", "N", "h_certified", "h_refuted", "outcome", "at_cap", "ratio",
        "solves", "seconds", "certified_interval", "interval_ratio",
        "interval_solves"}], "stable_windows", "sound"}], "sound"}`` (issues 4, 13
        and 21): ``stable_windows`` the exact windows [lo, hi] within [0, h_max]
        (hi ``"inf"``: stable for every larger delay), ``certified_interval``
        [lo, hi] every constant delay certified, or null), plus ``exact_check`` per
        method when ``with_check``; infinite values are the string ``"inf"``
        (JSON has no infinity), undefined ratios ``null``."""
        return {"h_max": _j(self.settings.h_max), "exact_methods_agree": self.exact_agree,
                "sound": self.sound,
                "examples": [{"name": e.example.name, "exact_margin": _j(e.exact.h),
                              "exact_margin_sweep": _j(e.exact_sweep.h),
                              "exact_agreement": _j(e.agreement),
                              "exact_methods_agree": e.exact_agree,
                              "stable_windows": [[_j(a), _j(b)] for a, b in e.windows],
                              "sound": e.sound,
                              "methods": [r.to_json(with_check=with_check) for r in e.rows]}
                             for e in self.examples]}

    @property
    def sound(self) -> bool:
        """Every certified point and interval lies in an exact stable window."""
        return all(e.sound for e in self.examples)

    @property
    def exact_agree(self) -> bool:
        """Both exact methods agree on every example."""
        return all(e.exact_agree for e in self.examples)

    def max_ratio(self) -> float:
        """Largest end of a certified interval [0, hi] over the exact margin h*
        (finite h* only; soundness: < 1). Point certificates are not margins
        and do not count here (they may lie in a later window)."""
        rs = [r.interval_ratio for e in self.examples for r in e.rows
              if r.interval_ratio is not None and math.isfinite(e.exact.h)]
        return max(rs) if rs else 0.0


def _j(x):
    if x is None:
        return None
    return "inf" if math.isinf(x) else float(x)


# -- loading -------------------------------------------------------------------------
#: Largest order of a benchmark example.
MAX_ORDER = 40


def _matrix(r: Reader, name: str) -> tuple:
    val = r.raw(name)
    if (not isinstance(val, list) or not val or not all(isinstance(row, list) for row in val)
            or any(len(row) != len(val) for row in val)):
        raise r.fail(name, val, "a square matrix as a list of rows, e.g. [[-1.0, 0.0], "
                     "[0.0, -2.0]]")
    if len(val) > MAX_ORDER:     # the LMIs' memory grows as n^4 (500 states: 466 GiB)
        raise r.fail(name, f"<a {len(val)} x {len(val)} matrix>",
                     f"at most {MAX_ORDER} states (the delay LMIs grow as n^4 in memory)")
    for i, row in enumerate(val):
        for j, x in enumerate(row):
            if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                raise r.fail(f"{name}[{i}][{j}]", x, "a finite number")
    return tuple(tuple(float(x) for x in row) for row in val)


def load_example(path: str | Path) -> Example:
    """Read one example file (an ``[example]`` table); DesignError on any problem."""
    shown = display_path(path)
    data = load_toml(path, shown)
    root = Reader(shown, data)
    ex = root.table("example")
    name = ex.string("name")
    if name != Path(path).stem:
        raise ex.fail("name", name, f'the file name without .toml, "{Path(path).stem}"')
    title, source = ex.string("title"), ex.string("source")
    A, Ad = _matrix(ex, "A"), _matrix(ex, "Ad")
    if len(A) != len(Ad):
        raise ex.fail("Ad", [list(r) for r in Ad], f"a {len(A)} x {len(A)} matrix like A")
    ex.finish()
    root.finish()
    return Example(name, title, source, A, Ad, shown)


def load_examples(folder: Path) -> tuple[Example, ...]:
    files = sorted(folder.glob("*.toml"))
    if not files:
        raise DesignError(display_path(folder), "<folder>", "<empty>", "example files (*.toml)")
    return tuple(load_example(p) for p in files)


def load_settings(r: Reader) -> BenchmarkSettings:
    """The ``[benchmark]`` table (every key optional, defaults of the dataclass)."""
    d = BenchmarkSettings()
    methods = r.raw("methods", list(d.methods))
    if (not isinstance(methods, list) or not methods
            or any(m not in METHODS for m in methods) or len(set(methods)) != len(methods)):
        raise r.fail("methods", methods, "distinct names among " + ", ".join(METHODS))
    s = BenchmarkSettings(
        examples=r.string("examples", default=d.examples), methods=tuple(methods),
        orders=int(r.number("orders", default=d.orders, integer=True, lo=0, hi=10)),
        N_max=int(r.number("N_max", default=d.N_max, integer=True, lo=0, hi=12)),
        gap_tol=r.number("gap_tol", default=d.gap_tol, positive=True, hi=0.5),
        margin=r.number("margin", default=d.margin, positive=True, hi=1e-2),
        rel_tol=r.number("rel_tol", default=d.rel_tol, positive=True, hi=0.1),
        h_max=r.number("h_max", default=d.h_max, lo=1e-3, hi=1e4, what="number (s)"),
        exact_check=r.boolean("exact_check", default=d.exact_check))
    r.finish()
    return s


# -- running -------------------------------------------------------------------------
def _row(s: BenchmarkSettings, method: str, N: int | None, b, h_star: float, solves: int,
         seconds: float, check: str | None, lmi, windows, guess=None,
         point_lmi=None, compiled=None) -> MethodRow:
    h = settle_point(point_lmi or lmi, b.h_certified, b.bracket.h_refuted)
    return MethodRow(method, N, h, b.bracket.h_refuted, _ratio(h, h_star), solves, seconds,
                     check, b.bracket.outcome.value, bool(s.h_max <= h < math.inf),
                     **interval_fields(lmi, b, windows, h_star, s.h_max, s.rel_tol, guess,
                                       compiled))


def _ratio(h: float, exact: float) -> float | None:
    if math.isinf(exact):
        return 1.0 if math.isinf(h) else None
    return h / exact if exact > 0 else None


def _check(lmi, bound, enabled: bool) -> str | None:
    if not enabled or bound.bracket.certificate is None:
        return None
    from .lmi.exact_check import exact_check
    step = bound.bracket.certificate
    return exact_check(lmi, step.certificate, step.h).outcome.value


def run_example(ex: Example, s: BenchmarkSettings) -> ExampleResult:
    """Exact margins and windows, then every method of ``s`` on one example: its
    point bound (:func:`~workbench.lmi.analysis.certified_delay`) and its
    interval (:func:`~workbench.lmi.interval.certified_interval`, grown from
    0 and from the middle of every exact window). Each criterion and interval
    LMI is compiled once (:class:`~workbench.benchmark_windows.Compiled`)."""
    A, Ad = np.array(ex.A), np.array(ex.Ad)
    exact, sweep = delay_margin_eig(A, Ad), delay_margin_sweep(A, Ad)
    h_star = exact.h
    windows = exact_windows(A, Ad, s.h_max)
    comp = Compiled(A, Ad, s.margin)
    rows: list[MethodRow] = []
    kw = dict(rel_tol=s.rel_tol, h_hi=s.h_max)
    # unstable at h = 0: the point search starts inside the first window
    guess = middle(*windows[0], s.h_max) if windows and windows[0][0] > 0 else None
    for m in s.methods:
        if m == "bessel-legendre":
            continue
        lmi = comp.criterion(m)
        b = certified_delay(lmi, guess=guess, **kw)
        rows.append(_row(s, m, None, b, h_star, b.solves, b.seconds,
                         _check(lmi, b, s.exact_check), lmi, windows, compiled=comp))
    if "bessel-legendre" in s.methods:
        auto = bessel_legendre_auto(A, Ad, h_star, gap_tol=s.gap_tol, N_max=s.N_max,
                                    N_through=s.orders, margin=s.margin, guess=guess,
                                    make=lambda N: comp.criterion("bessel-legendre", N), **kw)
        by_N = {}
        for b in auto.bounds:
            if b.N <= s.orders:
                lmi = comp.criterion("bessel-legendre", b.N)
                by = comp.criterion("bessel-legendre", b.certified_by
                                    ) if b.certified_by is not None else lmi
                prev = by_N.get(b.N - 1)
                implied = not comp.unshared and implies_next(prev, windows, s.h_max)
                row = _row(s, b.method, b.N, b, h_star, b.solves, b.seconds,
                           _check(by, b, s.exact_check), None if implied else lmi, windows,
                           point_lmi=by, compiled=comp)
                if implied:      # order N - 1's interval, maximal on the grid: not searched
                    row = replace(row, interval=prev.interval, intervals=prev.intervals,
                                  interval_sound=prev.interval_sound,
                                  interval_ratio=prev.interval_ratio)
                rows.append(monotone(prev, row))
                by_N[b.N] = rows[-1]
        best = auto.best
        used = [b for b in auto.bounds if b.N <= best.N]
        lmi = comp.criterion("bessel-legendre", best.N)
        row = _row(s, AUTO, best.N, best, h_star, sum(b.solves for b in used),
                   sum(b.seconds for b in used), _check(lmi, best, s.exact_check),
                   lmi if best.N not in by_N else None, windows, compiled=comp)
        if best.N in by_N:          # the same order's interval, not searched twice
            t = by_N[best.N]
            row = replace(row, h_certified=t.h_certified, ratio=t.ratio,
                          interval=t.interval, intervals=t.intervals,
                          interval_solves=t.interval_solves,
                          interval_sound=t.interval_sound, interval_ratio=t.interval_ratio)
        rows.append(row)
    curve = abscissa_curve(A, Ad, windows, h_star, s.h_max,
                           [r.interval for r in rows] + [(r.h_certified,) * 2 for r in rows])
    return ExampleResult(ex, exact, sweep, tuple(rows), windows, curve)


def run_benchmark(examples: tuple[Example, ...], s: BenchmarkSettings, *,
                  progress: bool = False) -> BenchmarkResult:
    """Every example under every method; ``progress``: a bar over the examples
    on stderr (terminal only, :mod:`workbench.sim.progress`)."""
    from .sim.progress import progress as progress_bar
    return BenchmarkResult(s, tuple(run_example(e, s) for e in progress_bar(
        examples, desc="benchmark", unit="example", enabled=progress and len(examples) > 1)))


# -- CLI -------------------------------------------------------------------------------
def benchmark_delay(design, *, as_json: bool = False, exact_check: bool = False,
                    out=print) -> int:
    """``workbench benchmark delay [DESIGN] [--json] [--exact-check]``.

    Runs the suite of a delay-benchmark design and prints method x example:
    the point certificate (stable at h), its ratio to the exact margin, the
    interval certificate (stable for every constant delay in [lo, hi]),
    solves, seconds, and per example the exact stable windows. Exit 0 when
    every run finished, the two exact methods agree on every example
    (relative difference <= :data:`~workbench.margins.AGREEMENT_RTOL`), every
    certified point lies in an exact stable window and every certified
    interval inside one, no interval [0, hi] reaches h* (and, with
    ``--exact-check``, every certificate passes the rational re-check); 1
    otherwise. ``design`` is a loaded ``delay-benchmark`` design (the CLI
    loads and checks its kind).
    """
    from .report.markdown import fmt, md_table

    spec = design.spec
    if exact_check:
        spec = replace(spec, settings=replace(spec.settings, exact_check=True))
    t0 = time.perf_counter()
    res = run_benchmark(spec.examples, spec.settings, progress=not as_json)
    wall = time.perf_counter() - t0
    checks = [r.exact_check for e in res.examples for r in e.rows if r.exact_check]
    ok = (res.max_ratio() < 1 and res.sound and all(c == "certified" for c in checks)
          and res.exact_agree)
    if as_json:
        out(json.dumps(res.to_json(with_check=exact_check), indent=2))
        return 0 if ok else 1
    for e in res.examples:
        agree = ("" if e.exact_agree else
                 f" — EXACT METHODS DISAGREE (rel. diff {fmt(e.agreement, 2)})")
        wins = " U ".join(show_window(a, b, lambda x: fmt(x, 7)) for a, b in e.windows) or "none"
        out(f"\n{e.example.name}: h* = {fmt(e.exact.h, 7)} s (eig), {fmt(e.exact_sweep.h, 7)} "
            f"s (phase sweep){agree} — {e.example.title}\nexact stable windows in "
            f"[0, {fmt(spec.settings.h_max)}] s: {wins}" + ("" if e.sound else
                                                           " — A CERTIFICATE LIES OUTSIDE"))
        table = [[r.method, "" if r.N is None else r.N,
                  fmt(r.h_certified, 6) + (" (>= cap)" if r.at_cap else ""), fmt(r.ratio, 6),
                  "—" if r.interval is None else
                  f"[{fmt(directed(r.interval[0], up=True, sig=5), 5)}, "
                  f"{fmt(directed(r.interval[1], up=False, sig=5), 5)}]",
                  f"{r.solves}+{r.interval_solves}", f"{r.seconds:.2f}"]
                 + ([r.exact_check or "—"] if exact_check else []) for r in e.rows]
        out(md_table(["method", "N", "stable at h (point, s)", "ratio", "stable on [lo, hi] "
                      "(interval, s)", "solves", "s"]
                     + (["exact check"] if exact_check else []), table,
                     "lrrrrrr" + ("l" if exact_check else "")))
    out(f"\n{len(res.examples)} examples in {wall:.1f} s; point: stable at that delay; "
        f"interval: stable for every constant delay in it; largest interval end / h* "
        f"{fmt(res.max_ratio(), 6)}" + ("" if ok else " — NOT OK"))
    return 0 if ok else 1
