"""Interval certificates: stable for every constant delay in [h_a, h_b].

A CERTIFIED step of a criterion of :mod:`workbench.lmi.analysis` is a *point*
certificate: the system is asymptotically stable at the delay it was solved
for. Feasibility of those LMIs is not monotone in h in general (a system may
be stable on two separate windows), so a bisection over point certificates
does not prove stability on [0, h]. This module proves intervals.

The argument (one LMI, the decision variables shared across the interval).
For every criterion each block is either independent of h or, after
multiplication by a positive weight w(h), a matrix polynomial in h of degree
at most two whose h^2 coefficient is positive semidefinite at every point
that satisfies the h-independent blocks:

* :class:`~workbench.lmi.analysis.JensenLMI`, ``w = h``:
  ``h Phi(h) = phi0 + h^2 F'RF`` and ``F'RF >= 0`` because ``R >= 0`` is a
  block of the criterion;
* :class:`~workbench.lmi.analysis.BesselLegendreLMI` (Wirtinger = N 1),
  ``w = h``: ``h Phi_N(h) = X + h He(G1' Theta H) + h^2 F'RF`` (Theta, S, R
  the variables; ``Theta >= 0``, ``S >= 0``, ``R >= 0`` do not depend on h);
* :class:`~workbench.lmi.analysis.FreeWeightingLMI`, ``w = 1``: the block is
  affine in h;
* :class:`~workbench.lmi.analysis.DelayIndependentLMI`: nothing depends on h.

So ``w(h) B(h)`` is convex in h (in the Loewner order): if one point
satisfies ``B(h_a) < 0`` and ``B(h_b) < 0`` with the same variables, then for
h = lambda h_a + (1 - lambda) h_b,
``w(h) B(h) <= lambda w(h_a) B(h_a) + (1 - lambda) w(h_b) B(h_b) < 0``, and
the criterion holds at every delay of [h_a, h_b] with that one point: the
functional of the criterion (built at each h from the shared variables)
proves stability for every constant delay in the interval. Sub-intervals of
a certified interval are certified by the same point, so the interval
searches below are monotone and a bisection is valid.

From h_a = 0: the lower block is the limit ``X = lim_{h->0} w(h) B(h)``
(for w = h the 1/h part of the block; for w = 1 the block at h = 0). A
strictly negative X proves that A + A_d is Hurwitz — on the delay-free
vector [x; x; x; 0 ...] (x_d = x, the Legendre moments of a constant
function) it reduces to ``He(P (A + A_d)) < 0`` with P (Theta's first block)
positive definite — so [0, h_b] is certified, h = 0 included, and the
interval starts where stability is known without any eigenvalue test.

References
----------
.. [SG15] Seuret A., Gouaisbaut F., "Hierarchy of LMI conditions for the
   stability analysis of time-delay systems", SCL 81 (2015) 1-7 (Theorem 4;
   Example 2 is a system stable only on a delay window).
.. [BV04] Boyd S., Vandenberghe L., *Convex Optimization*, CUP 2004,
   sec. 3.6 (matrix convexity: a nonnegative combination of convex matrix
   functions is convex in the Loewner order).
"""
from __future__ import annotations

import enum
import math
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from .coordinates import recheck_original
from .core import Block, MarginLMI, Outcome, Step
from .delay_input import check_bisection, time_scale


class Form(str, enum.Enum):
    """What a certified number means (closed set)."""

    #: stable at the delay h it was solved for (nothing said about other h)
    POINT = "point"
    #: stable for every constant delay in [h_a, h_b]
    INTERVAL = "interval"


#: How each h-dependent block depends on h: "h" (h B(h) quadratic with a
#: positive semidefinite h^2 coefficient) or "1" (B(h) affine in h).
WEIGHTS = ("h", "1")


class IntervalLMI(MarginLMI):
    """The criterion ``base`` at both ends of [h_a, h_b] with shared variables.

    ``solve_at(h_b)`` decides the interval whose lower end was set by
    :meth:`set_lower` (``h_a = 0``: the limit block X of the module docstring;
    fixed when the object is built). Blocks of the base criterion named in
    its ``h_blocks`` mapping appear twice (suffixes ``@lo`` and ``@hi``), the
    others once. A CERTIFIED step proves stability for every constant delay
    in [h_a, h_b] (module docstring).

    Parameters
    ----------
    base : MarginLMI
        A criterion with an ``h_blocks`` mapping {block name: "h" or "1"}.
    from_zero : bool
        Lower end h_a = 0.
    build : bool
        Build the cvxpy problem now (:class:`~workbench.lmi.core.MarginLMI`).
    """

    def __init__(self, base: MarginLMI, *, from_zero: bool, build: bool = True):
        weights = getattr(base, "h_blocks", None)
        if weights is None or any(w not in WEIGHTS for w in weights.values()):
            raise ValueError(f"criterion {type(base).__name__}: h_blocks = {weights!r}; "
                             "expected a mapping of block names to 'h' or '1'")
        self.base, self.from_zero, self.weights = base, bool(from_zero), dict(weights)
        self.h_a = 0.0
        super().__init__(margin=base.margin, bound=base.bound, build=build)

    def parameters(self):
        return () if self.from_zero else ("h_a", "iota_a")

    def variables(self):
        return self.base.variables()

    def recheck(self, values, h: float) -> dict[str, float]:   # against the caller's loop
        return recheck_original(self, values, h, owner=self.base)

    def set_lower(self, h_a: float) -> None:
        """Lower end h_a > 0 (s) of the interval (not for ``from_zero``)."""
        if self.from_zero or not (math.isfinite(h_a) and h_a > 0):
            raise ValueError(f"h_a = {h_a!r}; expected a positive finite delay for an "
                             "interval LMI not built from zero")
        self.h_a = float(h_a)
        self.set_parameters(h_a=h_a, iota_a=1.0 / h_a)

    def _lower(self, x, p, bmat) -> list[Block]:
        if not self.from_zero:
            return self.base.blocks(x, {"h": p["h_a"], "iota": p["iota_a"]}, bmat)
        at10 = self.base.blocks(x, {"h": 0, "iota": 1}, bmat)
        at00 = self.base.blocks(x, {"h": 0, "iota": 0}, bmat)
        out = []
        for b1, b0 in zip(at10, at00):
            w = self.weights.get(b1.name)
            out.append(b0 if w != "h" else Block(b1.name, b1.matrix - b0.matrix, b1.sense))
        return out

    def blocks(self, x, p, bmat):
        hi = self.base.blocks(x, {"h": p["h"], "iota": p["iota"]}, bmat)
        lo = {b.name: b for b in self._lower(x, p, bmat)}
        out = []
        for b in hi:
            if b.name in self.weights:
                out += [Block(b.name + "@lo", lo[b.name].matrix, b.sense),
                        Block(b.name + "@hi", b.matrix, b.sense)]
            else:
                out.append(b)
        return out


@dataclass(frozen=True)
class Link:
    """One interval LMI solved with shared variables: certified on [lo, hi]."""

    lo: float
    hi: float
    step: Step


@dataclass(frozen=True)
class IntervalCertificate:
    """A certified interval of constant delays (form :attr:`Form.INTERVAL`).

    Attributes
    ----------
    lo, hi : float
        Stable for every constant delay lo <= h <= hi (s); ``hi = inf`` only
        for the delay-independent criterion.
    links : tuple[Link, ...]
        Consecutive sub-intervals covering [lo, hi], each certified by one
        solve with its own shared variables (a union of certified intervals
        is certified).
    """

    lo: float
    hi: float
    links: tuple[Link, ...]

    @property
    def form(self) -> Form:
        return Form.INTERVAL

    @property
    def step(self) -> Step:
        """The certified solve of the last link."""
        return self.links[-1].step

    def contains(self, h: float) -> bool:
        return self.lo <= h <= self.hi


@dataclass(frozen=True)
class IntervalSearch:
    """Result of :func:`certified_interval`.

    Attributes
    ----------
    interval : IntervalCertificate or None
        The interval reported: the one from h = 0 when the criterion
        certified one, else the longest (relative to its upper end) of the
        windows grown from ``starts``; None when nothing was certified.
    intervals : tuple[IntervalCertificate, ...]
        Every disjoint interval found (increasing lo).
    outcome : Outcome
        CERTIFIED when ``interval`` is set; REFUTED when every solve was
        refuted; INCONCLUSIVE otherwise.
    steps : tuple[Step, ...]
        Every solve (interval and point solves), in order.
    """

    interval: IntervalCertificate | None
    intervals: tuple[IntervalCertificate, ...]
    outcome: Outcome
    steps: tuple[Step, ...]

    @property
    def bounds(self) -> tuple[float, float] | None:
        return None if self.interval is None else (self.interval.lo, self.interval.hi)

    @property
    def solves(self) -> int:
        return len(self.steps)

    @property
    def seconds(self) -> float:
        return sum(s.seconds for s in self.steps)


def _grow(decide: Callable[[float], Step], good: float, limit: float, rel_tol: float,
          budget: list[int], steps: list[Step], *, first: float = 4.0,
          coarse: float = 0.0) -> tuple[float, Step | None]:
    """Move a certified end from ``good`` (> 0) towards ``limit`` (either side, > 0).

    Monotone: if ``decide`` certifies at h, it certifies at every value between
    ``good`` and h (sub-intervals). Geometric steps (x4) until a value is not
    certified or ``limit`` is certified, then bisection in log scale until the
    relative gap to the first not-certified value is <= ``rel_tol`` (or to
    ``coarse`` times the log-distance moved: a link of a chain). An
    inconclusive answer in the first phase does not end it: the geometric
    midpoint towards ``good`` is tried first.
    """
    up = limit > good
    best, best_step, bad, retried = good, None, None, False
    h = min(good * first, limit) if up else max(good / first, limit)
    while budget[0] > 0 and bad is None:
        s = _run(decide, h, budget, steps)
        if s.outcome is Outcome.CERTIFIED:
            best, best_step, retried = h, s, False
            if h == limit:
                return best, best_step
            h = min(h * 4, limit) if up else max(h / 4, limit)
        elif s.outcome is Outcome.INCONCLUSIVE and not retried:
            retried, h = True, math.sqrt(best * h)
        else:
            bad = h
    while budget[0] > 0 and bad is not None and abs(math.log(bad / best)) > max(
            math.log1p(rel_tol), coarse * abs(math.log(best / good))):
        h = math.sqrt(best * bad)
        s = _run(decide, h, budget, steps)
        if s.outcome is Outcome.CERTIFIED:
            best, best_step = h, s
        else:
            bad = h
    return best, best_step


def _run(decide, h, budget, steps) -> Step:
    s = decide(h)
    budget[0] -= 1
    steps.append(s)
    return s


def _find(decide: Callable[[float], Step], first: float, floor: float, budget: list[int],
          steps: list[Step]) -> tuple[float, Step] | None:
    """First certified value of first, first/4, ... down to ``floor`` (None: none)."""
    h = first
    while budget[0] > 0:
        s = _run(decide, h, budget, steps)
        if s.outcome is Outcome.CERTIFIED:
            return h, s
        if h <= floor:
            return None
        h = max(h / 4, floor)
    return None


#: Smallest delay an interval search tries, as a fraction of :func:`time_scale`.
FLOOR_FRACTION = 1e-4
#: Default number of grid points of the scan of :func:`certified_interval`.
SCAN_POINTS = 24
#: Lower ends grown down from a start stop at this fraction of the start.
LOWER_FRACTION = 1e-6


def certified_interval(lmi: MarginLMI, *, h_hi: float, starts: Sequence[float] = (),
                       from_zero: bool = True, guess: float | None = None,
                       rel_tol: float = 1e-5, max_solves: int = 120,
                       scan: int = SCAN_POINTS, lower: IntervalLMI | None = None,
                       zero: MarginLMI | None = None) -> IntervalSearch:
    """Largest interval of constant delays the criterion certifies, by shared variables.

    Parameters
    ----------
    lmi : MarginLMI
        A criterion of :mod:`workbench.lmi.analysis` (it carries ``A``, ``Ad``
        and ``h_blocks``).
    h_hi : float
        Search cap (s): no interval end beyond it is tried (an interval ending
        at ``h_hi`` means "at least up to h_hi").
    starts : sequence of float
        Delays (s) at which to try a point certificate and grow a window
        around it (e.g. the midpoints of the exact stability windows), for
        systems unstable at h = 0 or with several windows.
    from_zero : bool
        Search an interval [0, h_b] first (module docstring: it proves A + A_d
        Hurwitz itself).
    guess : float, optional
        First h_b tried from zero (s); default ``min(h_hi, time_scale)``.
    rel_tol : float
        Relative accuracy of each searched end.
    max_solves : int
        Budget of solver calls.
    scan : int
        When neither h = 0 nor any start gave an interval: point solves on a
        geometric grid from 0.01 time scales to ``h_hi``, the first certified
        one a start (0: no scan).
    lower, zero : IntervalLMI, optional
        The interval LMIs of ``lmi`` to solve, [h_a, h_b] and [0, h_b]
        (default: built here), e.g. copies sharing a compiled problem
        (:func:`workbench.benchmark_windows.fork`).

    Returns
    -------
    IntervalSearch
        Every interval certified, and the one reported (from 0 when found).
    """
    _check_search(h_hi, starts, guess, rel_tol, max_solves)
    weights = getattr(lmi, "h_blocks", None)
    if weights is None:
        raise ValueError(f"criterion {type(lmi).__name__}; expected one with h_blocks")
    steps: list[Step] = []
    budget = [int(max_solves)]
    if not weights:                     # nothing depends on h: one solve decides [0, inf)
        s = _run(lmi.solve_at, h_hi, budget, steps)
        iv = (IntervalCertificate(0.0, math.inf, (Link(0.0, math.inf, s),))
              if s.outcome is Outcome.CERTIFIED else None)
        return _result(iv, [iv] if iv else [], steps)
    tau = time_scale(lmi.A, lmi.Ad)
    floor = min(FLOOR_FRACTION * tau, h_hi)
    win = lower or IntervalLMI(lmi, from_zero=False)
    found: list[IntervalCertificate] = []
    if from_zero:
        # a delay-range criterion's point certificate is already one on [0, h]
        zero = lmi if getattr(lmi, "range_from_zero", False) else (
            zero or IntervalLMI(lmi, from_zero=True))
        first = min(h_hi, guess if guess else tau)
        hit = _find(zero.solve_at, first, floor, budget, steps)
        if hit is not None:
            hb, st = _grow(zero.solve_at, hit[0], h_hi, rel_tol, budget, steps)
            links = [Link(0.0, hb, st or hit[1])]
            _chain(win, links, h_hi, rel_tol, budget, steps, up=True)
            found.append(IntervalCertificate(0.0, links[-1].hi, tuple(links)))
    for h0 in _starts(starts, found, scan, tau, h_hi, lmi, budget, steps):
        if budget[0] <= 0 or any(iv.contains(h0) for iv in found) or not 0 < h0 <= h_hi:
            continue
        s = _run(lmi.solve_at, h0, budget, steps)
        if s.outcome is not Outcome.CERTIFIED:
            continue
        links = [Link(h0, h0, s)]
        _chain(win, links, h_hi, rel_tol, budget, steps, up=True)
        below = max([iv.hi for iv in found if iv.hi < h0] + [LOWER_FRACTION * h0])
        _chain(win, links, below, rel_tol, budget, steps, up=False)
        links.sort(key=lambda k: k.lo)
        found.append(IntervalCertificate(links[0].lo, links[-1].hi, tuple(links)))
    found.sort(key=lambda iv: iv.lo)
    zero_iv = next((iv for iv in found if iv.lo == 0), None)
    best = zero_iv or max(found, key=lambda iv: iv.hi - iv.lo, default=None)
    return _result(best, found, steps)


def _starts(starts, found, scan, tau, h_hi, lmi, budget, steps):
    """The given starts in increasing order, then (nothing certified yet) the
    first certified point of a geometric scan."""
    yield from sorted(starts)
    if found or not scan or not math.isfinite(tau):
        return
    lo = min(1e-2 * tau, h_hi)
    for h in np.geomspace(lo, h_hi, int(scan)) if lo < h_hi else [h_hi]:
        if budget[0] <= 0 or found:
            return
        if _run(lmi.solve_at, float(h), budget, steps).outcome is Outcome.CERTIFIED:
            yield float(h)
            return


#: Largest number of links a chain adds on one side.
MAX_LINKS = 32


def _chain(win: IntervalLMI, links: list[Link], limit: float, rel_tol: float,
           budget: list[int], steps: list[Step], *, up: bool) -> None:
    """Extend a certified interval by links with fresh shared variables: upwards
    from the last link's hi to ``limit`` or downwards from the first link's lo;
    stops when a link adds less than ``rel_tol`` (relative), at the limit, or
    after :data:`MAX_LINKS` links."""
    first = 4.0
    for _ in range(MAX_LINKS):
        end = links[-1].hi if up else min(k.lo for k in links)
        if budget[0] <= 0 or (end >= limit if up else end <= limit):
            return

        def decide(h, e=end):
            if up:
                win.set_lower(e)
                return win.solve_at(h)
            win.set_lower(h)
            return win.solve_at(e)
        new, st = _grow(decide, end, limit, rel_tol, budget, steps, first=first, coarse=0.25)
        if st is None:
            return
        links.append(Link(end, new, st) if up else Link(new, end, st))
        grew = new / end if up else end / new
        if grew - 1 <= rel_tol:
            return
        first = max(grew, 1 + 2 * rel_tol)


def _result(best, found, steps) -> IntervalSearch:
    if best is not None:
        outcome = Outcome.CERTIFIED
    elif steps and all(s.outcome is Outcome.REFUTED for s in steps):
        outcome = Outcome.REFUTED
    else:
        outcome = Outcome.INCONCLUSIVE
    return IntervalSearch(best, tuple(found), outcome, tuple(steps))


def _check_search(h_hi, starts, guess, rel_tol, max_solves) -> None:
    if isinstance(h_hi, bool) or not (isinstance(h_hi, (int, float, np.floating))
                                      and math.isfinite(h_hi) and h_hi > 0):
        raise ValueError(f"h_hi = {h_hi!r}; expected a positive finite delay (s)")
    for h in starts:
        if isinstance(h, bool) or not (isinstance(h, (int, float, np.floating))
                                       and math.isfinite(h) and h > 0):
            raise ValueError(f"starts contains {h!r}; expected positive finite delays (s)")
    check_bisection(rel_tol, guess, max_solves)
