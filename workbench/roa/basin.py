"""Region-of-attraction estimate of a nonlinear closed loop: the bracket
[c_certified, c_refuted] of the largest level {V <= c} on which V' < 0.

:func:`estimate_basin` runs the falsifier (:mod:`workbench.roa.falsify`) to
find the lowest level with a confirmed counterexample, then the verifier
(:mod:`workbench.roa.certify`: Taylor ball at x*, interval box cover of the
annulus) below it. Levels are judged by :meth:`BasinEstimate.verdict`:

* CERTIFIED -- c <= c_certified: V' < 0 on {c_inner < V <= c} is proven, so
  {V <= c} is positively invariant and every trajectory starting in it
  enters {V <= c_inner} (c_inner = 0: converges to x*);
* REFUTED -- c >= c_refuted: a point of {V <= c} with V' >= 0 is known;
* INCONCLUSIVE -- c in (c_certified, c_refuted).

The loop is the *delay-free* closed loop given to
:class:`~workbench.roa.problem.BasinProblem` (under exact prediction, as in
paper 003's Theorems 2-3).

References
----------
.. [Khalil] H. K. Khalil, *Nonlinear Systems*, 3rd ed., 2002, section 8.2.
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026,
   Theorems 2-3 (delay-free loop under exact prediction).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..outcome import Outcome
from .certify import ball_argument, verify_annulus
from .falsify import Falsification, falsify
from .problem import BasinProblem, quadratic_enclosure


@dataclass(frozen=True)
class LevelVerdict:
    """Verdict on one level c of V.

    Attributes
    ----------
    outcome : Outcome
    level : float
        The level judged (for a point: an upper bound of V at the point when
        CERTIFIED, a lower bound when REFUTED).
    bracket : (float, float)
        (c_certified, c_refuted) of the estimate.
    """

    outcome: Outcome
    level: float
    bracket: tuple[float, float]


@dataclass(frozen=True)
class BasinEstimate:
    """Everything a region-of-attraction estimate established (no rendering).

    Attributes
    ----------
    names : tuple of str
        State coordinates.
    x_eq : tuple of float
        Equilibrium x*.
    P : tuple of tuple of float
        Matrix of V = (x - x*)' P (x - x*).
    P_source : str
        How P was chosen ("lyapunov", "certificate", "given", "optimised").
    c_search : float
        Largest level examined.
    c_certified : float
        V' < 0 proven on {c_inner < V <= c_certified} (0: nothing proven).
    c_refuted : float
        Lowest level with a confirmed point V' >= 0 (inf: none found up to c_search).
    counterexample : tuple or None
        That point.
    c_ball, c_inner, mu : float
        Ball argument (:func:`~workbench.roa.certify.ball_argument`).
    boxes, unresolved : int
        Boxes evaluated and left unresolved by the annulus cover.
    budget_hit : bool
    min_width : float
        Smallest box width of the cover, relative to the box's distance from x*.
    samples : int
        Points the falsifier evaluated.
    seed : int
    """

    names: tuple
    x_eq: tuple
    P: tuple
    P_source: str
    c_search: float
    c_certified: float
    c_refuted: float
    counterexample: tuple | None
    c_ball: float
    c_inner: float
    mu: float
    boxes: int
    unresolved: int
    budget_hit: bool
    min_width: float
    samples: int
    seed: int

    @property
    def bracket(self) -> tuple[float, float]:
        return (self.c_certified, self.c_refuted)

    def verdict(self, c: float) -> LevelVerdict:
        """CERTIFIED / REFUTED / INCONCLUSIVE for the level c."""
        if c <= self.c_certified:
            out = Outcome.CERTIFIED
        elif c >= self.c_refuted:
            out = Outcome.REFUTED
        else:
            out = Outcome.INCONCLUSIVE
        return LevelVerdict(out, float(c), self.bracket)

    def level_bounds(self, x) -> tuple[float, float]:
        """Rigorous (lower, upper) bounds of V at the point x."""
        x = np.asarray(x, float)[None, :]
        iv = quadratic_enclosure(np.array(self.P), np.array(self.x_eq), x, x)
        return float(iv.lo[0]), float(iv.hi[0])

    def point_verdict(self, x) -> LevelVerdict:
        """Is the point x inside the certified level set? CERTIFIED when an
        upper bound of V(x) is <= c_certified; REFUTED when a lower bound of
        V(x) is >= c_refuted (V cannot certify x: its level holds a point
        with V' >= 0; whether x converges is a separate question);
        INCONCLUSIVE otherwise."""
        lo, hi = self.level_bounds(x)
        if hi <= self.c_certified:
            return LevelVerdict(Outcome.CERTIFIED, hi, self.bracket)
        if lo >= self.c_refuted:
            return LevelVerdict(Outcome.REFUTED, lo, self.bracket)
        return LevelVerdict(Outcome.INCONCLUSIVE, hi, self.bracket)


def estimate_basin(problem: BasinProblem, c_search: float, *, seed: int = 0,
                   n_samples: int = 20_000, n_rays: int = 512,
                   min_width: float = 2.0**-12, max_boxes: int = 400_000,
                   falsified: Falsification | None = None) -> BasinEstimate:
    """Bracket the largest level {V <= c} with V' < 0 (module docstring).

    Parameters
    ----------
    problem : BasinProblem
        Delay-free closed loop, equilibrium and P.
    c_search : float
        Largest level examined (choose it so that {V <= c_search} stays in
        the model's domain; outside it the enclosures are infinite and the
        level simply cannot be certified).
    seed : int
        Seed of the falsification search.
    n_samples, n_rays : int
        Falsifier sample sizes.
    min_width, max_boxes
        Box cover resolution and budget (:func:`~workbench.roa.certify.verify_annulus`).
    falsified : Falsification, optional
        The result of ``falsify(problem, c_search, seed=seed, n_samples=n_samples,
        n_rays=n_rays)`` when the caller already has it (:func:`falsified_top`):
        the same object this function would compute, so the estimate is the same.

    Returns
    -------
    BasinEstimate
    """
    if not c_search > 0:
        raise ValueError(f"c_search = {c_search!r}; expected a positive level")
    fal = falsified if falsified is not None else falsify(
        problem, c_search, seed=seed, n_samples=n_samples, n_rays=n_rays)
    c_top = min(c_search, fal.c_refuted)
    ball = ball_argument(problem, c_top)
    if ball.c_ball > 0:
        ann = verify_annulus(problem, ball.c_ball, c_top, min_width=min_width,
                             max_boxes=max_boxes)
        c_cert, boxes, unres, budget = ann.c_certified, ann.boxes, ann.unresolved, ann.budget_hit
    else:
        c_cert, boxes, unres, budget = 0.0, 0, 0, False
    if c_cert <= ball.c_inner:
        c_cert = 0.0
    return BasinEstimate(
        names=problem.names, x_eq=tuple(float(v) for v in problem.x_eq),
        P=tuple(tuple(float(v) for v in row) for row in problem.P), P_source=problem.P_source,
        c_search=float(c_search), c_certified=float(c_cert), c_refuted=float(fal.c_refuted),
        counterexample=fal.counterexample, c_ball=ball.c_ball, c_inner=ball.c_inner,
        mu=ball.mu, boxes=boxes, unresolved=unres, budget_hit=budget, min_width=min_width,
        samples=fal.samples, seed=seed)


def falsified_top(problem: BasinProblem, c_search: float, *, seed: int = 0,
                  n_samples: int = 20_000, n_rays: int = 512) -> tuple[Falsification, float]:
    """The falsifier's stage of :func:`estimate_basin` alone: (its result, c_top).

    ``c_top = min(c_search, c_refuted)`` bounds the certified level from
    above: :func:`estimate_basin` certifies the ball level c_ball <= c_top
    (:func:`~workbench.roa.certify.ball_argument` starts at c_top and only
    shrinks) and then at most c_top (:func:`~workbench.roa.certify.verify_annulus`
    never returns more than its ``c_top``), or 0. So before any box is
    covered, ``c_certified <= c_top <= c_refuted`` is known, and a question
    this bound settles (a point with a lower bound of V >= c_refuted and an
    upper bound > c_top is REFUTED whatever the cover finds; a path whose V
    stays above c_top never enters the certified set) needs no cover. Pass
    the result to ``estimate_basin(..., falsified=...)`` to finish the
    estimate with the same numbers as a single call.
    """
    if not c_search > 0:
        raise ValueError(f"c_search = {c_search!r}; expected a positive level")
    fal = falsify(problem, c_search, seed=seed, n_samples=n_samples, n_rays=n_rays)
    return fal, min(c_search, fal.c_refuted)
