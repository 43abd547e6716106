"""Given states (e.g. where a switched controller hands over to a law) judged
against the certified basin of that law's closed loop, and the sweep of one
gain entry over which a state stays certified.

General: the loop is a factory ``make(candidate, points) -> (BasinProblem,
level searched)`` over candidate Lyapunov matrices (e.g. the weights of
:func:`workbench.roa.modal_P`), its numeric vector field ``fn(*x)`` and the
terminal events of its escape; nothing here knows the plant or the law.

* :func:`check_points` -- the best candidate for a set of labelled states
  (:func:`~workbench.features.basin_select.best_estimate`) and each state's
  verdict (:class:`~workbench.roa.check.BasinCheck`);
* :func:`point_in_basin` -- the best verdict over the candidates for one
  state (:func:`~workbench.features.basin_sweep.best_verdict`, staged
  estimates) and the fate of the trajectory from it;
* :func:`sampled_starts` -- the states and seeded starts around them, for a figure;
* :func:`sweep_gain_entry` -- :func:`point_in_basin` along one entry of a gain
  (:func:`~workbench.features.basin_sweep.gain_edge`), plus labelled gains
  compared;
* :func:`gain_sweep_quantities` -- its claimable edge and compared count;
* :func:`read_gain_sweep`, :func:`load_gain_sweep` -- the ``[basin]`` table's
  keys of that sweep.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..outcome import Outcome
from .basin_select import DeferredEstimate, best_estimate
from .basin_sweep import best_verdict, gain_edge
from .basin_trajectory import escaped, integrate


@dataclass(frozen=True)
class PointVerdict:
    """Best verdict over the candidates for one state and gain.

    Attributes
    ----------
    outcome : Outcome
        CERTIFIED if some candidate's P certifies the state; REFUTED if each P
        that exists refutes its level, or the linearisation is not Hurwitz
        (no basin: every candidate raised ModelError).
    w : object or None
        The deciding candidate (None: no Hurwitz linearisation).
    hurwitz : bool
    fate : str
        The trajectory from the state: "converges" (enters a certified level
        set of a candidate, from which it converges), the escape word (a
        terminal event fired or the step failed), "undecided" within the horizon.
    """

    outcome: Outcome
    w: object
    hurwitz: bool
    fate: str


def check_points(candidates, make, points, *, loop: str, seed: int = 0):
    """(candidate, problem, :class:`~workbench.roa.check.BasinCheck`) of the best
    candidate for the labelled states ``points`` = ((label, x), ...) (the
    problem's coordinates), or None when every candidate raises ModelError.
    ``make(candidate, xs)`` -> (BasinProblem, level searched)."""
    from ..roa.check import BasinCheck, PointCheck
    xs = [x for _, x in points]
    best = best_estimate(candidates, lambda q: make(q, xs), xs, seed=seed)
    if best is None:
        return None
    q, prob, est = best
    checks = tuple(PointCheck(lab, x, est.point_verdict(x)) for lab, x in points)
    return q, prob, BasinCheck(est, checks, loop)


def point_in_basin(candidates, make, x, fn, T: float, *, events=(), escape: str = "diverges",
                   max_step: float = math.inf, seed: int = 0) -> PointVerdict:
    """Is the state ``x`` inside a certified basin for some candidate? The best
    verdict over ``candidates`` in order (each a staged
    :class:`~workbench.features.basin_select.DeferredEstimate` of ``make(candidate,
    [x])``), and the fate of the trajectory of x' = fn(*x) from ``x`` over [0, T]
    (Radau, stopped by the terminal ``events``)."""
    sets = []

    def judge(q):
        sets.append(DeferredEstimate(*make(q, [x]), seed))
        return sets[-1].outcome(x)
    try:
        best = best_verdict(candidates, judge)
    except ModelError:
        return PointVerdict(Outcome.REFUTED, None, False,
                            _fate(fn, x, [], T, events, escape, max_step))
    return PointVerdict(best[0], best[1], True, _fate(fn, x, sets, T, events, escape, max_step))


def _fate(fn, x0, sets, T, events, escape, max_step) -> str:
    """Fate of the trajectory from x0 (:class:`PointVerdict`); ``sets``: the
    staged estimates of the candidates judged."""
    sol = integrate(fn, x0, T, events=events, max_step=max_step, dense=True)
    if any(stage.enters(sol.y.T) for stage in sets):
        return "converges"
    return escape if escaped(sol) else "undecided"


def sampled_starts(xs, n: int, *, seed: int, scale, pad, default) -> list:
    """The states ``xs``, then ``n`` seeded starts uniform in the box of
    half-width max_k |x_k[i]| scale[i] + pad[i] in each coordinate i (``default``
    half-widths when there is no state)."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, 1]))
    half = (np.array([max(abs(x[i]) for x in xs) * scale[i] + pad[i] for i in range(len(scale))])
            if xs else np.array(default))
    return [tuple(x) for x in xs] + [tuple(rng.uniform(-1, 1, len(half)) * half)
                                     for _ in range(n)]


@dataclass(frozen=True)
class GainRow:
    """One gain judged at the state: the gain, its :class:`PointVerdict`, and its
    source: "grid", "edge" (bisection) or a comparison label."""

    gain: tuple
    verdict: PointVerdict
    source: str


@dataclass(frozen=True)
class GainSweep:
    """Result of :func:`sweep_gain_entry` (no rendering).

    Attributes
    ----------
    point : tuple
        State judged.
    gain : tuple
        The gain swept (its ``index`` entry replaced along the sweep).
    index : int
    rows : tuple of GainRow
        Grid and bisection rows, by the swept entry.
    compared : tuple of GainRow
        The gains compared.
    edge : (float, float) or None
        (largest certified value, smallest value above it found not certified);
        None when no grid value, or every grid value, is certified.
    grid_min : float
        Smallest grid value (the certified range is reported from there).
    certified_below_edge : bool
        Every grid value from grid_min to the edge's lower end is certified.
    """

    point: tuple
    gain: tuple
    index: int
    rows: tuple
    compared: tuple
    edge: tuple | None
    grid_min: float
    certified_below_edge: bool


def sweep_gain_entry(judge, point, gain, index: int, grid, *, compare=(),
                     bisect: int = 4) -> GainSweep:
    """Entry ``index`` of ``gain`` over ``grid`` (ascending), the edge of the
    certified range bisected, and the ``compare`` gains ((label, gain), ...).

    Parameters
    ----------
    judge : callable
        gain tuple -> :class:`PointVerdict` of ``point`` (e.g. :func:`point_in_basin`).
    point : tuple
    gain : sequence of float
    index : int
    grid : sequence of float
    compare : sequence of (label, gain)
    bisect : int
        Bisection steps on the edge.
    """
    gain = tuple(float(g) for g in gain)
    at = lambda g: gain[:index] + (float(g),) + gain[index + 1:]
    row = lambda K, src: GainRow(K, judge(K), src)
    sw = gain_edge(lambda g, src: row(at(g), src), grid,
                   ok=lambda r: r.verdict.outcome is Outcome.CERTIFIED,
                   gain=lambda r: r.gain[index], bisect=bisect)
    compared = tuple(row(tuple(float(v) for v in K), str(lab)) for lab, K in compare)
    return GainSweep(tuple(point), gain, index, sw.rows, compared, sw.edge, min(grid),
                     sw.certified_below_edge)


def gain_sweep_quantity_names(entry: str) -> set:
    """Names of :func:`gain_sweep_quantities` (``entry``: the swept entry's name)."""
    return {f"basin.{entry}_safe_max", f"basin.{entry}_unsafe_min", "basin.compared_certified"}


def gain_sweep_quantities(sweep: GainSweep, entry: str) -> dict:
    """Claimable values of a :class:`GainSweep`: the edge of the certified
    range (``basin.{entry}_safe_max``, ``basin.{entry}_unsafe_min``; None
    without an edge) and how many compared gains are CERTIFIED."""
    lo, hi = (None, None) if sweep.edge is None else sweep.edge
    return {f"basin.{entry}_safe_max": lo, f"basin.{entry}_unsafe_min": hi,
            "basin.compared_certified": sum(r.verdict.outcome is Outcome.CERTIFIED
                                            for r in sweep.compared)}


@dataclass(frozen=True)
class GainSweepSettings:
    """The ``[basin]`` keys of a gain sweep (:func:`read_gain_sweep`) and the
    table's falsifier seed."""

    grid: tuple
    compare: tuple            # ((label, gain), ...)
    compare_source: str
    bisect: int
    seed: int = 0


def load_gain_sweep(root, grid_key: str, width: int, *, what: str = "gains"
                    ) -> GainSweepSettings | None:
    """A design's ``[basin]`` table (``root``: a :class:`workbench.reader.Reader`)
    holding a gain sweep: ``enabled`` and ``seed``
    (:func:`~workbench.features.basin.basin_table`), then the keys of
    :func:`read_gain_sweep`; None when the table is absent or disabled."""
    from .basin import basin_table
    table = basin_table(root)
    if table is None:
        return None
    b, enabled, seed = table
    sweep = read_gain_sweep(b, grid_key, width, what=what, seed=seed)
    b.finish()
    return sweep if enabled else None


def read_gain_sweep(b, grid_key: str, width: int, *, what: str = "gains",
                    seed: int = 0) -> GainSweepSettings:
    """Read the sweep's keys from a ``[basin]`` table reader ``b``: ``grid_key``
    (at least two values, sorted), ``compare_gains`` (rows of ``width`` finite
    numbers), ``compare_labels`` (one non-empty string per row, default "row i"),
    ``compare_source`` and ``bisect`` (0-12, default 4). The caller calls ``finish``."""
    grid = b.numbers(grid_key, min_len=2, what=what)
    gains = b.raw("compare_gains", default=[])
    if not isinstance(gains, list):
        raise b.fail("compare_gains", gains, f"a list of gains ({width} numbers each)")
    rows = []
    for i, g in enumerate(gains):
        ok = (isinstance(g, list) and len(g) == width and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
            for x in g))
        if not ok:
            raise b.fail(f"compare_gains[{i}]", g, f"a gain of {width} finite numbers")
        rows.append(tuple(float(x) for x in g))
    labels = b.raw("compare_labels", default=[f"row {i + 1}" for i in range(len(rows))])
    if (not isinstance(labels, list) or len(labels) != len(rows)
            or not all(isinstance(x, str) and x.strip() for x in labels)):
        raise b.fail("compare_labels", labels, f"{len(rows)} non-empty strings, one per gain")
    source = b.string("compare_source", default="—")
    bisect = b.number("bisect", integer=True, default=4, lo=0, hi=12, what="integer")
    return GainSweepSettings(tuple(sorted(grid)), tuple(zip(labels, rows)), source, bisect, seed)
