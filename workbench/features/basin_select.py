"""The choice of a quadratic Lyapunov function among candidates, and a basin
estimate computed only as far as a question needs it.

General: a candidate is anything ``make(candidate) -> (BasinProblem, level
searched)`` turns into a problem (e.g. the weights of
:func:`workbench.roa.modal_P`); the points judged are states of that problem.

* :func:`best_estimate` -- the candidate whose estimate certifies the most
  points, then with the widest margin of the worst one; candidates that cannot
  win are dropped after the falsifier's stage (their box cover never runs);
* :class:`DeferredEstimate` -- one estimate in three stages, answering a
  point's verdict and whether a path enters the certified set from the
  falsifier alone when it settles them.
"""
from __future__ import annotations

import math
import os

import numpy as np

from ..errors import ModelError
from ..outcome import Outcome
from ..roa import BasinEstimate, BasinProblem, estimate_basin
from ..roa.falsify import StagedFalsification
from ..roa.problem import quadratic_enclosure


#: Set (to anything) to run every certificate of :class:`DeferredEstimate` and
#: :func:`best_estimate` as before issue 36 (benchmarks/check_times.py compares
#: the two paths).
EAGER_ENV = "WORKBENCH_BASIN_EAGER"


class DeferredEstimate:
    """``estimate_basin(prob, c, seed=seed)`` in three stages (issue 36, item 4):
    the falsifier's samples and rays now, its optimiser only when a question
    needs the refuted level itself, the certificate (Taylor ball and box
    cover) only when asked for. After the first stage ``c_refuted <= c_upper``
    is known (:class:`~workbench.roa.falsify.StagedFalsification`), after
    the second ``c_certified <= c_top`` (:func:`workbench.roa.basin.falsified_top`)."""

    def __init__(self, prob, c: float, seed: int = 0):
        self.prob, self._c = prob, c
        self._seed = seed
        self._stage = StagedFalsification(self.prob, self._c, seed=seed)
        self._est = None
        if os.environ.get(EAGER_ENV) or not self.prob.M_eig_bounds()[0] > 0:
            # the cover's one ModelError (bounding_box_z): raised here, where
            # estimate_basin raises it, so the caller's handling is unchanged
            self.est

    @property
    def fal(self):
        """The falsifier's result: exactly ``falsified_top(prob, c, seed)[0]``."""
        return self._stage.finish()

    @property
    def c_top(self) -> float:
        """``min(c_search, c_refuted)``: an upper bound of c_certified."""
        return min(self._c, self.fal.c_refuted)

    @property
    def _top_upper(self) -> float:
        """An upper bound of :attr:`c_top` known before the optimiser runs."""
        return min(self._c, self._stage.c_upper)

    @property
    def est(self) -> BasinEstimate:
        """The full estimate: exactly ``estimate_basin(prob, c, seed=seed)`` (same
        problem, level, seed and falsifier result)."""
        if self._est is None:
            self._est = estimate_basin(self.prob, self._c, seed=self._seed, falsified=self.fal)
        return self._est

    def outcome(self, x) -> Outcome:
        """``est.point_verdict(x).outcome``, without the cover when the
        falsifier settles it: with lo <= V(x) <= hi, lo >= c_refuted and
        hi > c_top >= c_certified, point_verdict's first test (hi <=
        c_certified) fails and its second (lo >= c_refuted) holds: REFUTED.
        The falsifier's first stage settles it already when lo >= c_upper
        and hi > min(c_search, c_upper) (c_refuted <= c_upper)."""
        iv = quadratic_enclosure(self.prob.P, self.prob.x_eq, np.asarray(x, float)[None, :],
                                 np.asarray(x, float)[None, :])
        lo, hi = float(iv.lo[0]), float(iv.hi[0])
        if lo >= self._stage.c_upper and hi > self._top_upper:
            return Outcome.REFUTED
        if lo >= self.fal.c_refuted and hi > self.c_top:
            return Outcome.REFUTED
        return self.est.point_verdict(x).outcome

    def enters(self, path) -> bool:
        """``est.c_certified > 0 and any(V(path) <= est.c_certified)``, without
        the cover when V > c_top >= c_certified along the whole path, and
        without the falsifier's optimiser when V > min(c_search, c_upper) >=
        c_top (a NaN state is not above either: the cover then decides)."""
        V = self.prob.V(path)
        if np.all(V > self._top_upper) or np.all(V > self.c_top):
            return False
        est = self.est
        return bool(est.c_certified > 0 and np.any(V <= est.c_certified))


def score(est: BasinEstimate, points) -> tuple:
    """Sort key of a P: certified points first, then the margin of the worst
    of them (c_certified / level)."""
    if not points:
        return (0, est.c_certified)
    lv = [est.level_bounds(x)[1] for x in points]
    ok = sum(l <= est.c_certified for l in lv)
    return (ok, min(est.c_certified / l if l > 0 else math.inf for l in lv))


def score_bound(prob: BasinProblem, c_top: float, points) -> tuple:
    """An upper bound of ``score(estimate_basin(prob, c, falsified=fal), points)``
    from the falsifier's stage alone (``(fal, c_top) = falsified_top(prob, c)``),
    the coarse pass of :func:`best_estimate` (issue 36, item 4).

    The estimate certifies c_certified <= c_top (:func:`~workbench.roa.basin.falsified_top`),
    and its level bounds of a point depend on P and x* only, so the count
    of certified points and the worst margin c_certified / level of
    :func:`score` are each at most their value at c_certified = c_top:
    the score is lexicographically <= this bound. A P whose bound does not
    exceed the best score so far cannot replace it (the sweep keeps the
    first of equal scores), and its box cover is skipped: the chosen P, its
    estimate and so every printed number are those of the full sweep.
    """
    P, x_eq = np.array(prob.P, float), np.array(prob.x_eq, float)
    lv = []
    for x in points:
        x = np.asarray(x, float)[None, :]
        lv.append(float(quadratic_enclosure(P, x_eq, x, x).hi[0]))
    if not points:
        return (0, c_top)
    ok = sum(l <= c_top for l in lv)
    return (ok, min(c_top / l if l > 0 else math.inf for l in lv))


def best_estimate(candidates, make, points, *, seed: int = 0):
    """(candidate, problem, estimate) of the best candidate (:func:`score`; the
    first of equal scores), or None when every candidate raises ModelError
    (e.g. no Hurwitz linearisation).

    Parameters
    ----------
    candidates : sequence
    make : callable
        candidate -> (BasinProblem, level searched).
    points : sequence of state
        States judged (the problem's coordinates).
    seed : int
        Falsifier seed.
    """
    best = None
    for q in candidates:
        try:
            prob, c = make(q)
            stage = StagedFalsification(prob, c, seed=seed)
            coarse = best is not None and not os.environ.get(EAGER_ENV)
            # coarse pass: this P cannot be chosen (score_bound, which grows
            # with the level: c_top <= min(c, c_upper) before the optimiser)
            if coarse and score_bound(prob, min(c, stage.c_upper), points) <= best[0]:
                continue
            fal = stage.finish()
            if coarse and score_bound(prob, min(c, fal.c_refuted), points) <= best[0]:
                continue
            est = estimate_basin(prob, c, seed=seed, falsified=fal)
        except ModelError:
            continue
        key = score(est, points)
        if best is None or key > best[0]:
            best = (key, q, prob, est)
    return None if best is None else best[1:]
