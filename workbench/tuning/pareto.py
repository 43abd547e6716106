"""Pareto fronts of minimised objectives and a stated rule to pick one point.

Used by the multi-objective tuning of paper 002's controllers
(:mod:`workbench.kinds.tracking.run`): every candidate is a row of
objective values, all minimised; a row with a non-finite entry (a run that
did not stop) is never on a front and never chosen.
"""
from __future__ import annotations

import numpy as np

#: Relative tie band of a dominance comparison: two objective values within
#: ``TIE_REL * max(|a|, |b|)`` of each other are equal. A reproducible run's
#: objectives move less than 1e-7 relative under a last-bit change of its inputs
#: (:mod:`workbench.features.reproducible`), so an exact ``<`` between near-equal
#: values (two relay runs stopping at the same point, a punctuality of 0 against
#: 1e-16) would decide dominance on the last bits; 1e-6 is ten times that.
TIE_REL = 1e-6


def _no_worse_better(A: np.ndarray, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(no worse in every objective, better in one) of rows ``A`` against ``B``
    (broadcast), each comparison with the tie band :data:`TIE_REL`."""
    tol = TIE_REL * np.maximum(np.abs(A), np.abs(B))
    return np.all(A <= B + tol, axis=-1), np.any(A < B - tol, axis=-1)


def dominates(a: np.ndarray, b: np.ndarray) -> bool:
    """True when ``a`` is no worse than ``b`` in every objective and better in
    one, values within the relative band :data:`TIE_REL` counting as equal."""
    no_worse, better = _no_worse_better(np.asarray(a, float), np.asarray(b, float))
    return bool(no_worse and better)


def pareto_mask(points) -> np.ndarray:
    """Boolean mask of the non-dominated rows of ``points`` (shape (N, M),
    minimised). Rows with a non-finite entry are excluded; equal rows (within
    :data:`TIE_REL`) are all kept (none dominates the other)."""
    P = np.asarray(points, float)
    ok = np.all(np.isfinite(P), axis=1)
    mask = ok.copy()
    idx = np.flatnonzero(ok)
    for i in idx:
        others = P[idx]
        no_worse, better = _no_worse_better(others, P[i])
        mask[i] = not (no_worse & better).any()
    return mask


def weighted_cost(points, scales, weights) -> np.ndarray:
    """sum_j w_j x_j / s_j per row (inf where a row has a non-finite entry).

    The minimiser of a positively weighted sum is always on the Pareto
    front, so choosing by it picks a front point."""
    P = np.asarray(points, float)
    cost = (P / np.asarray(scales, float)) @ np.asarray(weights, float)
    return np.where(np.all(np.isfinite(P), axis=1), cost, np.inf)


def choose(points, scales, weights, admissible=None) -> int:
    """Index of the row with the smallest :func:`weighted_cost` (the first of
    equal ones) among the ``admissible`` rows (a boolean mask; all rows when
    None or when no row is admissible); raises ValueError when no row is finite."""
    cost = weighted_cost(points, scales, weights)
    if admissible is not None and np.any(np.asarray(admissible) & np.isfinite(cost)):
        cost = np.where(admissible, cost, np.inf)
    if not np.isfinite(cost).any():
        raise ValueError("no candidate with finite objectives")
    return int(np.argmin(cost))


def grid_edges(params, chosen: int, keys) -> tuple[str, ...]:
    """Names of the parameters whose value at row ``chosen`` of the full
    factorial grid ``params`` (shape (N, P)) is the smallest or the largest
    value of that parameter's grid (parameters with a single value are not
    searched and never count).

    A tuning search whose optimum lies on the edge of its grid has not shown
    that the optimum is inside it (issue 33, item 4): the grid must be
    extended in those parameters, or the design point is INCONCLUSIVE.
    """
    P = np.asarray(params, float)
    out = []
    for j, k in enumerate(keys):
        vals = np.unique(P[:, j])
        if vals.size > 1 and P[chosen, j] in (vals[0], vals[-1]):
            out.append(k)
    return tuple(out)


def dominated_share(front_a, front_b) -> float:
    """Share of the rows of ``front_b`` that some row of ``front_a`` dominates
    (0 when ``front_b`` is empty)."""
    A, B = np.asarray(front_a, float), np.asarray(front_b, float)
    if len(B) == 0:
        return 0.0
    hit = [any(dominates(a, b) for a in A) for b in B]
    return float(np.mean(hit))
