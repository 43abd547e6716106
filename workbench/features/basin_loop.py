"""A closed loop whose gain enters as symbols, and its basin problem for a
candidate modal Lyapunov matrix: what a gain sweep of a basin verdict
(:mod:`workbench.features.basin_points`) builds per gain and candidate.

General: the loop is any sympy vector field in its states and gain symbols;
its Jacobian and Hessians are derived once (symbolically, with the gain
free) and the gain substituted per value, so that a sweep over gains does not
differentiate again. :class:`GainLoop` bundles such a loop with its
linearisation, domain, candidate Lyapunov matrices and escape, and answers the
basin questions per gain (the verdicts of given states, the trajectories).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property, lru_cache

import numpy as np
import sympy as sp

from ..plants.lambdify_cache import lambdify
from ..roa import BasinProblem, estimate_basin, modal_P
from ..roa.check import search_level
from .basin_points import (GainSweep, PointVerdict, check_points, point_in_basin, sampled_starts,
                           sweep_gain_entry)
from .basin_trajectory import Trajectory, trajectory


def derivatives(f, states) -> tuple:
    """(Jacobian, Hessians) of the vector field ``f`` in ``states`` (sympy lists)."""
    J = [[sp.diff(fi, s) for s in states] for fi in f]
    H = [[[sp.diff(Jki, s) for s in states] for Jki in row] for row in J]
    return J, H


def at_gain(f, derivs, symbols, K) -> tuple:
    """(f, (J, H)) with the gain symbols replaced by the values ``K`` (floats)."""
    rep = {k: sp.Float(float(v)) for k, v in zip(symbols, K)}
    put = lambda e: e.xreplace(rep)
    J, H = derivs
    return ([put(e) for e in f], ([[put(e) for e in row] for row in J],
                                  [[[put(e) for e in r] for r in Hk] for Hk in H]))


def modal_problem(f, states, x_eq, A_cl, weights, *, derivs=None, names=None, points=(),
                  domain=None, c_search=None, P_source: str = "optimised") -> tuple:
    """(BasinProblem with P = :func:`~workbench.roa.modal_P` (A_cl, weights), level
    searched: :func:`~workbench.roa.check.search_level` of ``points`` in ``domain``)."""
    P = modal_P(A_cl, weights)
    prob = BasinProblem(f, states, x_eq, P, P_source=P_source, names=names, derivatives=derivs)
    return prob, search_level(prob, points, domain, c_search)


@dataclass(frozen=True)
class GainBasin:
    """Result of :meth:`GainLoop.basin` (no rendering).

    Attributes
    ----------
    K : tuple of float
        The gain.
    w : object
        The candidate chosen (e.g. the weight of a fast mode in a modal P).
    check : workbench.roa.check.BasinCheck
        Its estimate and the verdict of each judged state.
    trajectories : tuple of Trajectory
        From the judged states, then from the sampled starts.
    """

    K: tuple
    w: object
    check: object
    trajectories: tuple

    @property
    def judged(self) -> list:
        """(label, outcome, fate) of each judged state
        (:func:`~workbench.features.basin_switch.switch_quantities`)."""
        return [(p.label, p.verdict.outcome, tr.fate)
                for p, tr in zip(self.check.points, self.trajectories)]


@dataclass(frozen=True, eq=False)
class GainLoop:
    """A closed loop x' = f(x; K) whose gain K enters ``f`` as ``symbols``, in
    coordinates with its equilibrium at ``x_eq`` for every gain, and its basin
    per gain: the modal problems over the ``candidates`` (each mapped by
    ``weights`` to the weights of :func:`~workbench.roa.modal_P` (A + B K, .)),
    the verdicts of given states, the trajectories and their fates.

    Attributes
    ----------
    f : list of sympy expressions
        In ``states`` and the gain ``symbols``.
    states, symbols : tuple of sympy Symbol
    A, B : ndarray
        Linearisation at x_eq (A + B K: the closed loop's).
    x_eq : tuple
    names : tuple of str
        Display names of the states.
    domain : (lo, hi)
        Box the model holds on (caps the level searched).
    candidates : tuple
        Candidates of P, best first on ties (e.g. weights of a fast mode).
    weights : callable
        candidate -> weights of :func:`~workbench.roa.modal_P`.
    events : tuple of callable
        Terminal ``solve_ivp`` events of the escape (e.g. :func:`~.basin_trajectory.limit_event`).
    escape : str
        Fate word of an escaped trajectory.
    max_step : float
        Largest integration step (s).
    loop : str
        Description of the loop (:class:`~workbench.roa.check.BasinCheck`).
    """

    f: list
    states: tuple
    symbols: tuple
    A: np.ndarray
    B: np.ndarray
    x_eq: tuple
    names: tuple
    domain: tuple
    candidates: tuple
    weights: Callable
    events: tuple = ()
    escape: str = "diverges"
    max_step: float = math.inf
    loop: str = ""

    @cached_property
    def derivs(self) -> tuple:
        """(Jacobian, Hessians) with the gain symbolic (derived once)."""
        return derivatives(self.f, self.states)

    @lru_cache(maxsize=16)
    def at(self, K: tuple) -> tuple:
        """(f, derivatives, A + B K) at the gain ``K`` (a tuple of floats)."""
        f, derivs = at_gain(self.f, self.derivs, self.symbols, K)
        return f, derivs, self.A + self.B @ np.array([K], float)

    def problem(self, K, w, points, c_search=None) -> tuple:
        """(problem, level searched) of candidate ``w`` at ``K`` (:func:`modal_problem`)."""
        f, derivs, A_cl = self.at(tuple(K))
        return modal_problem(f, self.states, self.x_eq, A_cl, self.weights(w), derivs=derivs,
                             names=self.names, points=points, domain=self.domain,
                             c_search=c_search)

    def estimate(self, K, w, points, *, seed: int = 0, c_search=None) -> tuple:
        """(problem, its :func:`~workbench.roa.estimate_basin`) of candidate ``w`` at ``K``."""
        prob, c = self.problem(K, w, points, c_search)
        return prob, estimate_basin(prob, c, seed=seed)

    def numeric(self, K):
        """The numeric vector field ``fn(*x)`` at ``K``."""
        return lambdify(self.states, self.at(tuple(K))[0], "math")

    def check(self, K, points, *, seed: int = 0):
        """(candidate, problem, BasinCheck) of the best candidate for the labelled
        ``points`` (:func:`~.basin_points.check_points`), or None (no Hurwitz loop)."""
        return check_points(self.candidates, lambda w, xs: self.problem(K, w, xs), points,
                            loop=self.loop, seed=seed)

    def judge(self, K, x, T: float, *, seed: int = 0) -> PointVerdict:
        """Best verdict over the candidates for the state ``x`` and the fate of the
        trajectory from it over [0, T] (:func:`~.basin_points.point_in_basin`)."""
        return point_in_basin(self.candidates, lambda w, xs: self.problem(K, w, xs), x,
                              self.numeric(K), T, events=self.events, escape=self.escape,
                              max_step=self.max_step, seed=seed)

    def sweep(self, K, x, index: int, grid, T: float, *, point=None, compare=(), bisect: int = 4,
              seed: int = 0, share: tuple | None = None) -> GainSweep:
        """Entry ``index`` of the gain ``K`` over ``grid``, the state ``x`` judged by
        :meth:`judge` over [0, T] at each gain, the edge of the certified range
        bisected, and the labelled gains ``compare`` judged the same way
        (:func:`~.basin_points.sweep_gain_entry`; ``point``: the state as the
        result records it, default ``x``, e.g. in the design's own coordinates).

        ``share`` = (name, key identifying this loop): the sweep is computed once
        per run (:func:`workbench.memo.computed_once`: in this process, and in
        the run folder for the run's other processes), keyed by ``key`` and
        every argument above."""
        point = tuple(float(p) for p in (x if point is None else point))
        compare = tuple((str(lab), tuple(float(g) for g in G)) for lab, G in compare)

        def compute():
            return sweep_gain_entry(lambda G: self.judge(G, x, T, seed=seed), point, K, index,
                                    grid, compare=compare, bisect=bisect)
        if share is None:
            return compute()
        from ..memo import computed_once
        key = (share[1], tuple(float(k) for k in K), tuple(float(v) for v in x), int(index),
               tuple(float(g) for g in grid), float(T), point, compare, int(bisect), int(seed))
        return computed_once(share[0], key, compute)

    def trajectory(self, fn, x0, T: float, inside, *, path_dt=None) -> Trajectory:
        """One trajectory of x' = fn(*x) from x0 and its fate, escaping by the
        loop's events (:func:`~.basin_trajectory.trajectory`)."""
        return trajectory(fn, x0, T, inside, events=self.events, escape=self.escape,
                          max_step=self.max_step, path_dt=path_dt)

    def basin(self, K, points, *, n_traj: int, T: float, scale, pad, default, seed: int = 0,
              path_dt=None) -> GainBasin | None:
        """The :class:`GainBasin` of the best candidate for the labelled
        ``points`` (:meth:`check`; None: no Hurwitz loop), with the
        trajectories from the points and from ``n_traj`` seeded starts around them
        (:func:`~.basin_points.sampled_starts` with ``scale``, ``pad``, ``default``)
        over [0, T], "converges" once in the certified level set."""
        best = self.check(K, points, seed=seed)
        if best is None:
            return None
        w, prob, check = best
        starts = sampled_starts([x for _, x in points], n_traj, seed=seed, scale=scale, pad=pad,
                                default=default)
        fn, c = self.numeric(K), check.estimate.c_certified
        inside = lambda p: prob.V(p) <= c
        return GainBasin(tuple(float(k) for k in K), w, check, tuple(
            self.trajectory(fn, x0, T, inside, path_dt=path_dt) for x0 in starts))
