"""Falsification of a level set: a point with V' >= 0 and V as small as possible.

Three stages, all seeded:

1. uniform samples in the ellipsoid {V <= c_search};
2. rays: directions on the unit sphere of the V-metric, each walked outwards
   on a geometric grid of levels; the first level with V' >= 0 per ray;
3. local optimisation (scipy SLSQP): minimise V(x) subject to V'(x) >= 0,
   from the best hits of 1-2.

A hit is kept only when it is *confirmed* by interval arithmetic at the point
(the enclosure of V' at the degenerate box [x, x] has a lower bound >= 0);
an optimiser result on the boundary V' = 0 is pushed outwards along its ray
until it is confirmed. The counterexample's level is the upper bound of V at
the point: every level c >= c_refuted holds a point with V' >= 0, so
"V' < 0 on {0 < V <= c}" is false for V. This refutes the *certificate*
(this V at this level), not convergence from that point.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from .problem import BasinProblem


@dataclass(frozen=True)
class Falsification:
    """Result of :func:`falsify`.

    Attributes
    ----------
    c_refuted : float
        Smallest confirmed counterexample level (inf: none found).
    counterexample : tuple or None
        The point x (V'(x) >= 0, V(x) <= c_refuted).
    vdot_at : float
        Lower bound of V' at the counterexample (>= 0).
    samples : int
        Points evaluated (samples, ray points; optimiser evaluations not counted).
    seed : int
    """

    c_refuted: float
    counterexample: tuple | None
    vdot_at: float
    samples: int
    seed: int


def _unit_ball(rng, n_pts: int, n: int) -> np.ndarray:
    g = rng.standard_normal((n_pts, n))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    return g * rng.random((n_pts, 1)) ** (1.0 / n)


def _confirm(problem: BasinProblem, x: np.ndarray) -> tuple[float, float] | None:
    """(V upper bound, V' lower bound) when V'(x) >= 0 is proven at x, else None."""
    (vd,), _ = problem.vdot_interval(x[None, :], x[None, :])
    if vd.lo[0] >= 0:
        return float(problem.level_of(x).hi[0]), float(vd.lo[0])
    return None


class StagedFalsification:
    """:func:`falsify` in two stages (issue 36, item 4): the samples and rays
    with their raw hits confirmed (cheap: one vectorised evaluation), then,
    only when :meth:`finish` is called, the optimiser (SLSQP from the best
    hits, each result pushed out until confirmed; most of the cost, and the
    only user of the gradient).

    After the first stage :attr:`c_upper` is an upper bound of the final
    ``c_refuted``: the optimiser stage only ever lowers the level it starts
    from (a result replaces it only when lower). A caller whose question the
    bound already settles (a point whose level is at or above it is beyond
    the refuted level whatever the optimiser finds) may skip :meth:`finish`;
    a caller that needs the level calls it and gets exactly what
    :func:`falsify` returns (same samples, same hits, same starts: the second
    stage draws no random numbers).

    Parameters are those of :func:`falsify`.
    """

    def __init__(self, problem: BasinProblem, c_search: float, *, seed: int = 0,
                 n_samples: int = 20_000, n_rays: int = 512, n_levels: int = 160,
                 n_starts: int = 8, c_floor: float | None = None):
        n = len(problem.states)
        rng = np.random.default_rng(np.random.SeedSequence(seed))
        c_floor = 1e-12 * c_search if c_floor is None else c_floor
        Lc = np.linalg.cholesky(problem.P)                 # P = L L'
        to_x = np.linalg.inv(Lc.T)                         # e = to_x u gives e'Pe = |u|^2
        U = _unit_ball(rng, n_samples, n) * np.sqrt(c_search)
        dirs = rng.standard_normal((n_rays, n))
        dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
        levels = np.geomspace(max(c_floor, 1e-9 * c_search), c_search, n_levels)
        R = (dirs[:, None, :] * np.sqrt(levels)[None, :, None]).reshape(-1, n)
        X = problem.x_eq + np.concatenate([U, R]) @ to_x.T
        with np.errstate(all="ignore"):
            vd = problem.vdot_numeric(X)
        V = problem.V(X)
        hit = np.isfinite(vd) & (vd >= 0) & (V > c_floor)
        self._problem, self._seed, self._n_starts, self._c_floor = problem, seed, n_starts, c_floor
        self._X, self._hit, self._done = X, hit, None
        self._best = (np.inf, None, np.nan)
        self._order = None
        if not hit.any():
            self._done = Falsification(np.inf, None, np.nan, len(X), seed)
            return
        order = np.argsort(np.where(hit, V, np.inf))[:max(n_starts * 4, 1)]
        best_c, best_x, best_vd = np.inf, None, np.nan
        for k in order:                                     # the raw hits, confirmed
            if not hit[k]:
                break
            ok = _confirm(problem, X[k])
            if ok and ok[0] < best_c:
                best_c, best_x, best_vd = ok[0], X[k], ok[1]
                break
        self._order, self._best = order, (best_c, best_x, best_vd)

    @property
    def c_upper(self) -> float:
        """Upper bound of the final ``c_refuted`` (inf: none known yet)."""
        return self._done.c_refuted if self._done is not None else float(self._best[0])

    def finish(self) -> Falsification:
        """The optimiser stage; the result of :func:`falsify` (computed once)."""
        if self._done is not None:
            return self._done
        problem, X, hit, c_floor = self._problem, self._X, self._hit, self._c_floor
        best_c, best_x, best_vd = self._best
        cons = {"type": "ineq", "fun": lambda x: float(problem.vdot_numeric(x[None, :])[0]),
                "jac": problem.vdot_grad_numeric}
        for k in self._order[:self._n_starts]:
            if not hit[k]:
                break
            with np.errstate(all="ignore"):
                res = minimize(lambda x: float(problem.V(x[None, :])[0]), X[k],
                               jac=lambda x: 2.0 * problem.P @ (x - problem.x_eq),
                               constraints=[cons], method="SLSQP",
                               options={"maxiter": 200, "ftol": 1e-14})
            x = res.x
            if not np.all(np.isfinite(x)):
                continue
            e = x - problem.x_eq
            for s in (1.0, *(1.0 + 10.0 ** -np.arange(12, 1, -1))):   # push outwards until proven
                ok = _confirm(problem, problem.x_eq + s * e)
                if ok:
                    if c_floor < ok[0] < best_c:
                        best_c, best_x, best_vd = ok[0], problem.x_eq + s * e, ok[1]
                    break
        if best_x is None:
            self._done = Falsification(np.inf, None, np.nan, len(X), self._seed)
        else:
            self._done = Falsification(best_c, tuple(float(v) for v in best_x), best_vd, len(X),
                                       self._seed)
        self._X = self._hit = self._order = None
        return self._done


def falsify(problem: BasinProblem, c_search: float, *, seed: int = 0, n_samples: int = 20_000,
            n_rays: int = 512, n_levels: int = 160, n_starts: int = 8,
            c_floor: float | None = None) -> Falsification:
    """Seeded search for the lowest level of {V <= c_search} with V' >= 0.

    Parameters
    ----------
    problem : BasinProblem
    c_search : float
        Largest level searched.
    seed : int
        Seed of the numpy SeedSequence.
    n_samples, n_rays, n_levels, n_starts : int
        Uniform samples; rays and levels per ray; optimiser starts.
    c_floor : float, optional
        Points below this level are ignored (default 1e-12 c_search: the
        equilibrium itself, where V' = 0).
    """
    return StagedFalsification(problem, c_search, seed=seed, n_samples=n_samples,
                               n_rays=n_rays, n_levels=n_levels, n_starts=n_starts,
                               c_floor=c_floor).finish()
