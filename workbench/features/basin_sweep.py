"""Sweeps of a basin verdict: over candidate Lyapunov matrices (the best
verdict for one state) and over a scalar gain (the edge of the certified
range, bisected).

General: the verdict is a callback (a gain or a candidate -> a row or an
:class:`~workbench.outcome.Outcome`); nothing here knows the loop.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..outcome import Outcome

#: Order of verdicts: a CERTIFIED candidate beats an INCONCLUSIVE one, which beats REFUTED.
RANK = {Outcome.CERTIFIED: 2, Outcome.INCONCLUSIVE: 1, Outcome.REFUTED: 0}


def best_verdict(candidates, judge):
    """(best outcome, its candidate) of ``judge(candidate)`` over ``candidates``,
    in order, stopping at the first CERTIFIED; (REFUTED, None) when none is
    better (an exception of ``judge`` propagates)."""
    best = (Outcome.REFUTED, None)
    for c in candidates:
        out = judge(c)
        if RANK[out] > RANK[best[0]]:
            best = (out, c)
        if out is Outcome.CERTIFIED:
            break
    return best


@dataclass(frozen=True)
class GainEdge:
    """Result of :func:`gain_edge`.

    Attributes
    ----------
    rows : tuple
        Grid and bisection rows, sorted by gain.
    edge : (float, float) or None
        (largest certified gain, smallest gain above it found not certified);
        None when no adjacent certified / not certified pair lies on the grid.
    certified_below_edge : bool
        Every row up to the edge's lower end is certified.
    """

    rows: tuple
    edge: tuple | None
    certified_below_edge: bool


def gain_edge(judge, grid, *, ok, gain, bisect: int = 4) -> GainEdge:
    """Judge each gain of ``grid`` (ascending) and bisect the first edge where
    a certified gain is followed by one that is not.

    Parameters
    ----------
    judge : callable
        (gain, source) -> row; ``source`` is "grid" or "edge" (a bisection point).
    grid : sequence of float
    ok : callable
        row -> bool: the row is certified.
    gain : callable
        row -> float: its gain.
    bisect : int
        Bisection steps on the edge.
    """
    rows = [judge(g, "grid") for g in sorted(grid)]
    edge = None
    oks = [ok(r) for r in rows]
    for i in range(len(rows) - 1):
        if oks[i] and not oks[i + 1]:
            lo, hi = gain(rows[i]), gain(rows[i + 1])
            for _ in range(bisect):
                mid = 0.5 * (lo + hi)
                r = judge(mid, "edge")
                rows.append(r)
                lo, hi = (mid, hi) if ok(r) else (lo, mid)
            edge = (lo, hi)
            break
    rows.sort(key=gain)
    below = edge is not None and all(ok(r) for r in rows if gain(r) <= edge[0])
    return GainEdge(tuple(rows), edge, below)
