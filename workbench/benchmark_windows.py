"""Exact stability windows against LMI certificates, for the delay benchmark
(the only place where :mod:`workbench.lmi` and :mod:`workbench.margins` meet).

A certified point must lie in an exact stable window; a certified interval
must lie inside one (issue 13). The spectral abscissa on a grid is the
independent picture of the figure.
"""
from __future__ import annotations

import copy
import math
import os
from dataclasses import replace

import numpy as np

from .lmi.analysis import BesselLegendreLMI, WirtingerLMI, make_criterion
from .lmi.core import Outcome
from .lmi.interval import IntervalCertificate, IntervalLMI, IntervalSearch, Link, certified_interval
from .margins import SpectrumNotConverged, spectral_abscissa, stability_windows
from .printed_grid import axis_end, directed

#: Relative slack of the window tests for the exact windows' rounding.
WINDOW_RTOL = 1e-9
#: Grid points of the spectral-abscissa curve.
CURVE_POINTS = 161


def printed_ratio(r) -> float | None:
    """hi / h* of a row's interval from 0, from hi rounded down to 4 digits
    (:func:`directed`) and truncated to 4 decimals: the digits a second CPU
    reproduces (the chained solves' last digits differ between CPUs)."""
    if r.interval_ratio is None or r.interval is None:
        return None
    hi = r.interval[1]
    if math.isinf(hi):
        return r.interval_ratio
    h_star = hi / r.interval_ratio
    return math.floor(directed(hi, up=False) / h_star * 1e4) / 1e4


def show_window(a: float, b: float, fmt) -> str:
    """A window as text: closed at 0, open at a crossing delay."""
    return ("[0" if a == 0 else f"({fmt(a)}") + f", {fmt(b)})"


def exact_windows(A, Ad, h_max: float) -> tuple[tuple[float, float], ...]:
    """Exact stability windows intersected with [0, h_max] (s); a window that
    never closes keeps ``hi = inf`` (stable for every larger delay)."""
    out = []
    for a, b in stability_windows(A, Ad, h_max):
        if a <= h_max:
            out.append((a, b if math.isinf(b) else min(b, h_max)))
    return tuple(out)


def in_window(h: float, windows, rtol: float = WINDOW_RTOL) -> bool:
    """The delay h (s) lies in an exact stable window (open at crossing delays,
    closed at 0; ``rtol`` relative slack)."""
    return any((a == 0 and h == 0) or (a * (1 - rtol) < h < b * (1 + rtol))
               for a, b in windows)


def interval_inside(lo: float, hi: float, windows, rtol: float = WINDOW_RTOL) -> bool:
    """[lo, hi] lies inside one exact stable window (see :func:`in_window`)."""
    return any((lo >= a if a == 0 else lo > a * (1 - rtol))
               and (hi == b == math.inf or hi < b * (1 + rtol)) for a, b in windows)


#: Significant digits of the printed interval ends (the grid they are decided on).
PRINTED_DIGITS = 4


#: Significant digits of a printed point bound (the report's h column).
POINT_DIGITS = 5


def settle_point(lmi, h: float, h_refuted: float, sig: int = POINT_DIGITS) -> float:
    """A bisection's certified delay ``h`` decided on the grid of printed
    values (see :func:`settle_interval`): the grid value above ``h`` when the
    criterion certifies the system *at* that value (a solve there), else the
    grid value below when it certifies there, else ``h`` itself (printed
    rounded down). ``lmi`` None (no criterion to solve): ``h``."""
    if lmi is None or not (0 < h < math.inf):
        return h
    up, down = directed(h, up=True, sig=sig), directed(h, up=False, sig=sig)
    for g in ((up,) if up < h_refuted else ()) + (down,):
        if g == h:
            return h
        if 0 < g and lmi.solve_at(g).outcome is Outcome.CERTIFIED:
            return g
    return h


def settle_interval(lmi, c: IntervalCertificate, h_max: float,
                    sig: int = PRINTED_DIGITS, win: IntervalLMI | None = None
                    ) -> IntervalCertificate:
    """The interval ``c`` with its ends decided on the grid of printed values.

    A search ends within its tolerance of the criterion's boundary, and where
    that boundary lies near a printed digit's rounding point the end is
    printed one way on one CPU and the other way on another. So the printed
    digits are certified themselves: a finite lower end ``lo`` becomes the
    grid value below it when one more link [that value, lo] is certified
    (else the grid value above it, inside the certified interval), and an
    upper end ``hi`` the grid value above it when the link [hi, that value]
    is certified (else the grid value below it). Each end is then a printed
    value, decided by a solve *at* that value: a last-bit difference can
    change it only where the criterion's own boundary lies within solver
    noise of the grid value, not wherever the search happened to stop.
    ``win``: the interval LMI [h_a, h_b] of ``lmi`` to solve (default: built
    here).
    """
    win = win or IntervalLMI(lmi, from_zero=False)
    links, lo, hi = list(c.links), c.lo, c.hi
    if 0 < lo:
        down, up = directed(lo, up=False, sig=sig), directed(lo, up=True, sig=sig)
        s = None
        if 0 < down < lo:
            win.set_lower(down)
            s = win.solve_at(lo)
        if s is not None and s.outcome is Outcome.CERTIFIED:
            links.insert(0, Link(down, lo, s))
            lo = down
        else:
            lo = up
    if math.isfinite(hi) and hi > 0:
        down, up = directed(hi, up=False, sig=sig), directed(hi, up=True, sig=sig)
        s = None
        if hi < up <= h_max:
            win.set_lower(hi)
            s = win.solve_at(up)
        if s is not None and s.outcome is Outcome.CERTIFIED:
            links.append(Link(hi, up, s))
            hi = up
        else:
            hi = down
    if not lo <= hi:                 # narrower than one grid step: keep the search's ends
        return c
    return IntervalCertificate(lo, hi, tuple(links))


def interval_fields(lmi, bound, windows, h_star: float, h_max: float, rel_tol: float,
                    guess=None, compiled: "Compiled | None" = None) -> dict:
    """Interval search of one criterion and its comparison with the exact windows:
    ``interval``, ``intervals``, ``interval_solves``, ``interval_ratio``, ``point_sound``,
    ``interval_sound`` (keyword fields of a benchmark row). ``lmi`` None: the
    point comparison only. ``compiled``: the example's :class:`Compiled`
    (default: interval LMIs built here)."""
    h = bound.h_certified
    point = None if not h > 0 else (
        windows == ((0.0, math.inf),) if math.isinf(h) else in_window(h, windows))
    out = dict(point_sound=point)
    if lmi is None:
        return out
    starts = [middle(a, b, h_max) for a, b in windows if a > 0]
    comp = compiled or Compiled(lmi.A, lmi.Ad, lmi.margin)
    zero = None if getattr(lmi, "range_from_zero", False) or not getattr(lmi, "h_blocks", 1) \
        else comp.interval(lmi, from_zero=True)
    search = certified_interval(lmi, h_hi=h_max, starts=starts, rel_tol=rel_tol,
                                guess=guess or (h if 0 < h < h_max else None),
                                max_solves=260, zero=zero,
                                lower=comp.interval(lmi, from_zero=False))
    if search.interval is not None:
        settled = tuple(settle_interval(lmi, c, h_max, win=comp.interval(lmi, from_zero=False))
                        for c in search.intervals)
        pick = search.intervals.index(search.interval)
        search = IntervalSearch(settled[pick], settled, search.outcome, search.steps)
    iv = search.bounds
    out.update(interval=iv, interval_solves=search.solves,
               intervals=tuple((c.lo, c.hi) for c in search.intervals))
    if iv is not None:
        out["interval_sound"] = all(interval_inside(c.lo, c.hi, windows)
                                    for c in search.intervals)
        if iv[0] == 0:
            out["interval_ratio"] = (iv[1] / h_star if 0 < h_star < math.inf else
                                     (1.0 if math.isinf(iv[1]) and math.isinf(h_star)
                                      else None))
    return out


def _fresh(problem):
    """The cvxpy problem ``problem`` with its compilation (``_cache``: the
    parametrised program) shared and no solver: a shallow copy whose Clarabel
    solver cache starts empty. (cvxpy hands a re-solved problem's previous
    Clarabel solver back for a data update, so the last bits of a solve depend
    on what that problem object solved before.)"""
    if problem is None:
        return None
    twin = object.__new__(type(problem))
    twin.__dict__.update(problem.__dict__)
    twin._solver_cache, twin._status, twin._value, twin._solution = {}, None, None, None
    return twin


def fork(lmi):
    """A copy of the criterion ``lmi`` that shares its compiled problems (no
    new cvxpy compilation) and has a solver state of its own: it solves bit
    for bit as a newly built criterion would, and ``lmi`` as if never forked
    (``tests/test_benchmark_compiled.py``). Variables and parameters are
    shared: each solve sets the delay, other parameters (an interval's lower
    end) must be set before each solve, as every caller here does."""
    twin = copy.copy(lmi)
    twin._problem, twin._canonical = _fresh(lmi._problem), _fresh(lmi._canonical)
    if hasattr(twin, "_twin_lmi"):     # a retry's twin criterion: built again when needed
        twin._twin_lmi = None
    return twin


class Compiled:
    """The criteria of one example and their interval LMIs, each compiled once.

    The first request of a criterion (method, N) or of an interval LMI of a
    criterion returns a new one; every later request a fork
    (:func:`fork`): the same compiled problem
    with a solver state of its own, so every solve is bit for bit that of a
    newly built criterion (the cvxpy compilation is the larger part of the
    suite's time: issue 36, item 4). ``A``, ``Ad``: the example's matrices.
    ``WORKBENCH_BENCHMARK_UNSHARED=1`` selects the old path (a new criterion,
    hence a new compilation, for every request, and every Bessel-Legendre
    order's interval searched, see :func:`implies_next`;
    ``benchmarks/delay_benchmarks_times.py``).
    """

    def __init__(self, A, Ad, margin: float):
        self.A, self.Ad, self.margin = A, Ad, margin
        self._criteria: dict = {}
        self._intervals: dict = {}
        self.unshared = os.environ.get("WORKBENCH_BENCHMARK_UNSHARED") == "1"

    #: Criteria that are one LMI (the same blocks, hence the same compiled
    #: problem) under another name: Wirtinger is Bessel-Legendre of order 1.
    SAME = {("wirtinger", None): ("bessel-legendre", 1)}
    #: The class a fork is given for a name of :data:`SAME`.
    CLASS = {"wirtinger": WirtingerLMI, "bessel-legendre": BesselLegendreLMI}

    def criterion(self, method: str, N: int | None = None):
        """The criterion of ``method`` (order ``N``), new or a fork."""
        key = self.SAME.get((method, N), (method, N))
        if key not in self._criteria or self.unshared:
            self._criteria[key] = make_criterion(method, self.A, self.Ad, N=N,
                                                 margin=self.margin)
            return self._criteria[key]
        twin = fork(self._criteria[key])
        if twin.method != method:        # the same LMI under the other name (SAME)
            twin.__class__ = self.CLASS[method]
        return twin

    def interval(self, base, *, from_zero: bool) -> IntervalLMI:
        """The interval LMI of ``base`` (a criterion or a fork of one), new or a fork."""
        key = (id(base._problem._cache), from_zero)
        if key not in self._intervals or self.unshared:
            self._intervals[key] = (base, IntervalLMI(base, from_zero=from_zero))
            return self._intervals[key][1]
        return fork(self._intervals[key][1])


def middle(a: float, b: float, h_max: float) -> float:
    """Geometric middle (s) of the window (a, b) cut at h_max."""
    b = min(b, h_max)
    return math.sqrt(a * b) if b > a else a


def abscissa_curve(A, Ad, windows, h_star: float, h_max: float, intervals
                   ) -> tuple[tuple[float, float], ...]:
    """(h, spectral abscissa) on a uniform grid over [0, H] with H the plot
    horizon: 1.3 times the largest finite window end, certified end or h*,
    rounded up to 2 significant digits (:func:`~workbench.printed_grid.axis_end`:
    the same grid on every CPU) and capped at h_max; NaN where the
    collocation did not converge."""
    ends = [x for w in windows for x in w] + [h_star]
    ends += [x for iv in intervals if iv is not None for x in iv]
    finite = [x for x in ends if math.isfinite(x) and x > 0]
    if finite:
        H = min(h_max, axis_end(1.3 * max(finite)))
    else:
        R = float(np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2))
        H = min(h_max, axis_end(20.0 / R) if R > 0 else h_max)
    out = []
    for h in np.linspace(0.0, H, CURVE_POINTS):
        try:
            alpha = spectral_abscissa(A, Ad, float(h))
        except SpectrumNotConverged:
            alpha = math.nan
        out.append((float(h), float(alpha)))
    return tuple(out)


def implies_next(prev, windows, h_max: float, sig: int = PRINTED_DIGITS) -> bool:
    """Order N's interval certificate ``prev`` (a benchmark row, settled on
    the printed grid) already gives order N + 1's row: the exact stability set
    in [0, h_max] is one window (a, b) and ``prev`` certifies it as far as the
    grid goes — lo = a = 0 or the grid value below lo is at most a, and hi
    reaches h_max or the grid value above hi is at least b (each with the
    windows' relative slack :data:`WINDOW_RTOL`).

    Why the row is then the same as a search would give: order N + 1's
    settled ends are grid values (or, narrower than one grid step, not a
    superset of ``prev``), and a certified interval lies inside an exact
    window (the criterion's functional proves stability there; claim
    ``suite-sound``), so its interval cannot strictly contain ``prev``; an
    interval that does not contain ``prev`` is replaced by ``prev`` in any case
    (:func:`monotone`). One window holds one certified interval, so the
    ``intervals`` agree too. (Point bounds are searched as before.)
    """
    if prev is None or prev.interval is None or len(windows) != 1 or len(prev.intervals) != 1:
        return False
    (a, b), (lo, hi) = windows[0], prev.interval
    lo_max = lo == a == 0 or (a > 0 and 0 < lo and
                              directed(lo * (1 - 1e-9), up=False, sig=sig) <= a * (1 - WINDOW_RTOL))
    hi_max = hi >= h_max or (math.isfinite(b) and
                             directed(hi * (1 + 1e-9), up=True, sig=sig) >= b * (1 + WINDOW_RTOL))
    return bool(lo_max and hi_max and interval_inside(lo, hi, windows))


def monotone(prev, row):
    """Order N's row with at least order N - 1's interval: a certificate of
    order N - 1 on an interval is one of order N there (SG15 Theorem 4), so
    the hierarchy's intervals never shrink with N (by construction)."""
    if prev is None or prev.interval is None or (
            row.interval is not None and row.interval[0] <= prev.interval[0]
            and row.interval[1] >= prev.interval[1]):
        return row
    return replace(row, interval=prev.interval, intervals=prev.intervals,
                   interval_sound=prev.interval_sound, interval_ratio=prev.interval_ratio)
