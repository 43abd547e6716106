"""Least-squares fitting of a model's parameters to logged step-command runs.

General machinery behind a parameter-recovery study: generate SYNTHETIC logs
from the true parameters (piecewise-constant command, seeded Gaussian output
noise, quantisation), fit chosen parameters by minimising the pooled RMSE over
all logs, compare the fits with the truth. The model enters only as a
vectorised ``simulate`` callback::

    simulate(values, log) -> ndarray, shape (n, len(log.t))

the model output at the log's sample times for each row of ``values`` (shape
(n, len(names)), the fitted parameters in ``names`` order). Two optimisers:

* :func:`fruit_fly` -- an improved fruit-fly optimiser (Pan 2012): flies coded
  directly in the normalised parameter box, a search radius shrinking
  quadratically with the iteration, elitist swarm moves;
* scipy's ``differential_evolution`` (vectorised) as the reference.

Used by paper 000's brake fit (:mod:`workbench.fit`); tested on a first-order
lag with dead time in ``tests/test_param_fit.py``.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.optimize import differential_evolution


@dataclass(frozen=True)
class Log:
    """A (synthetic) log sampled every ``dt_log`` seconds.

    Attributes
    ----------
    t : ndarray
        Sample times (s).
    command : ndarray
        Command held over each interval.
    output : ndarray
        Logged model output.
    y0 : float
        Initial output.
    dt_log : float
        Sample interval (s).
    """

    t: np.ndarray
    command: np.ndarray
    output: np.ndarray
    y0: float
    dt_log: float


def command_profile(steps: tuple, t: np.ndarray) -> np.ndarray:
    """Piecewise-constant command: ``steps`` = ((t_start, level), ...)."""
    c = np.zeros_like(t)
    for t0, level in steps:
        c = np.where(t >= t0, level, c)
    return c


def synthetic_log(simulate: Callable, truth: np.ndarray, steps: tuple, *, y0: float,
                  duration: float, dt_log: float, noise_sd: float, quantum: float, seed: int,
                  floor: float | None = None) -> Log:
    """A SYNTHETIC log: ``simulate`` at the true parameters ``truth`` plus noise.

    Output noise is Gaussian (sd ``noise_sd``), clipped below at ``floor`` (if
    given), then quantised to ``quantum``.
    """
    t = np.arange(0.0, duration + 1e-9, dt_log)
    log = Log(t, command_profile(steps, t), np.zeros_like(t), y0, dt_log)
    clean = simulate(np.array([truth]), log)[0]
    noisy = clean + np.random.default_rng(seed).normal(0.0, noise_sd, clean.shape)
    if floor is not None:
        noisy = np.maximum(noisy, floor)
    return Log(t, log.command, np.round(noisy / quantum) * quantum, y0, dt_log)


def rmse(model: np.ndarray, logged: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """Root-mean-square error times ``scale`` (last axis = samples)."""
    return scale * np.sqrt(np.mean((model - logged) ** 2, axis=-1))


def pooled_rmse(simulate: Callable, values: np.ndarray, logs: list[Log],
                scale: float = 1.0) -> np.ndarray:
    """RMSE times ``scale`` over all samples of all ``logs``, per row of ``values``."""
    sq = [rmse(simulate(values, lg), lg.output, scale) ** 2 * len(lg.t) for lg in logs]
    return np.sqrt(np.sum(sq, axis=0) / sum(len(lg.t) for lg in logs))


@dataclass(frozen=True)
class FitResult:
    """Best parameters, objective and cost of one optimiser run."""

    method: str
    values: tuple
    rmse: float
    evaluations: int
    seconds: float
    history: tuple   # best objective per iteration


def fruit_fly(f, dim: int, *, flies: int, iterations: int, seed: int,
              r0: float = 0.5, r_min: float = 0.01) -> tuple[np.ndarray, float, int, tuple]:
    """Improved fruit-fly optimisation of ``f`` (rows -> values) in the unit box.

    Returns the best point, its objective, the number of evaluations and the
    best-so-far history.
    """
    rng = np.random.default_rng(seed)
    swarm = rng.uniform(0, 1, (flies, dim))
    vals = f(swarm)
    best = swarm[int(np.argmin(vals))].copy()
    fbest = float(np.min(vals))
    hist, evals = [fbest], flies
    for it in range(iterations):
        radius = r_min + (r0 - r_min) * (1 - it / iterations) ** 2
        flies_x = np.clip(best + radius * rng.uniform(-1, 1, (flies, dim)), 0, 1)
        vals = f(flies_x)
        evals += flies
        k = int(np.argmin(vals))
        if vals[k] < fbest:
            best, fbest = flies_x[k].copy(), float(vals[k])
        hist.append(fbest)
    return best, fbest, evals, tuple(hist)


def fit(simulate: Callable, logs: list[Log], bounds: np.ndarray, *, method: str, seed: int,
        flies: int = 24, iterations: int = 40, scale: float = 1.0) -> FitResult:
    """Fit the parameters in the box ``bounds`` (rows [lo, hi]) by pooled RMSE.

    ``method`` is ``"foa"`` (:func:`fruit_fly`) or ``"de"`` (differential
    evolution, population about ``flies``); the RMSE is reported times ``scale``.
    """
    lo, hi = bounds[:, 0], bounds[:, 1]
    dim = len(bounds)

    def f(u: np.ndarray) -> np.ndarray:
        return pooled_rmse(simulate, lo + np.clip(np.atleast_2d(u), 0, 1) * (hi - lo), logs,
                           scale)

    t0 = time.perf_counter()
    if method == "foa":
        u, fb, ev, hist = fruit_fly(f, dim, flies=flies, iterations=iterations, seed=seed)
    elif method == "de":
        hist_l = []
        mult = max(1, flies // dim)      # scipy's popsize is a multiple of dim
        r = differential_evolution(lambda U: f(U.T), [(0, 1)] * dim, vectorized=True,
                                   updating="deferred", seed=seed, maxiter=iterations,
                                   popsize=mult, polish=False, tol=0,
                                   callback=lambda intermediate_result: hist_l.append(
                                       float(intermediate_result.fun)))
        # nfev counts vectorised calls; count model runs instead
        u, fb, ev, hist = r.x, float(r.fun), (r.nit + 1) * mult * dim, tuple(hist_l)
    else:
        raise ValueError(f"method = {method!r}; expected 'foa' or 'de'")
    return FitResult(method, tuple(float(x) for x in lo + u * (hi - lo)), fb, ev,
                     time.perf_counter() - t0, hist)
