"""What a Monte Carlo run draws, from (seed, run index) only (issue 35: one
sampling of a sweep's runs).

* named parameters, uniform on declared ranges or from a declared
  :class:`~workbench.features.montecarlo.Distribution` (its inverse CDF):
  row i of one seeded draw of uniforms
  (:func:`workbench.sim.batch.uniform_draws`), so the first n runs of a
  larger sweep with the same seed draw the same values and a chunk of runs
  draws its own rows (:func:`draw_runs`);
* per-run values of counter-based streams (:mod:`workbench.sim.counter_rng`):
  a value of run i is a pure function of (seed, stream, i), so adding such
  a draw leaves the rows above unchanged (:func:`draw_runs` with
  ``streams``), and the keys of per-run streams a kernel reads as the run
  goes (measurement noise per measured signal, piecewise-constant
  disturbance segments; :func:`stream_keys`);
* how many steps of a refined run one value of a noise sampled on the
  sweep's step grid is held (:func:`hold_steps`), so a run at dt / 2 sees
  the same noise as at dt.

How the draws enter a plant, a controller or a kernel is the study's.
"""
from __future__ import annotations

import numpy as np

__all__ = ["draw_runs", "hold_steps", "stream_keys"]


def draw_runs(n: int, seed: int, ranges: dict, start: int = 0,
              streams: dict | None = None) -> dict:
    """Draws of runs ``start <= i < n``: name -> array.

    Parameters
    ----------
    n, seed, start : int
    ranges : dict
        name -> (lo, hi), uniform, or a
        :class:`~workbench.features.montecarlo.Distribution` (its ``ppf``
        of the uniform): row i of one seeded draw of uniforms on [0, 1)
        (:func:`~workbench.sim.batch.uniform_draws`; lo + (hi - lo) u, as
        there).
    streams : dict, optional
        name -> (stream, (lo, hi)): uniform, the first number of the run's
        key in that counter-based stream
        (:func:`~workbench.sim.counter_rng.run_key`), drawn after and
        independent of ``ranges``.
    """
    from ..sim.batch import uniform_draws
    from ..sim.counter_rng import run_key, uniform
    u = uniform_draws(n, seed, dict.fromkeys(ranges, (0.0, 1.0)), start)
    out = {k: r.ppf(u[k]) if hasattr(r, "ppf") else r[0] + (r[1] - r[0]) * u[k]
           for k, r in ranges.items()}
    runs = np.arange(start, n)
    for name, (stream, (lo, hi)) in (streams or {}).items():
        out[name] = lo + (hi - lo) * uniform(run_key(seed, stream, runs), 0)
    return out


def stream_keys(seed: int, streams: dict, runs) -> dict:
    """name -> tuple of the ``uint64`` keys (as ints) of runs ``runs`` in
    each counter-based stream of ``streams`` (name -> stream number)."""
    from ..sim.counter_rng import run_key
    runs = np.asarray(runs, np.int64)
    return {c: tuple(run_key(seed, k, runs).tolist()) for c, k in streams.items()}


def hold_steps(grid: float, dt: float) -> int:
    """Steps of size ``dt`` each value of a noise sampled every ``grid``
    seconds is held (ValueError unless ``dt`` divides ``grid``)."""
    every = round(grid / dt)
    if not abs(every * dt - grid) <= 1e-12 * grid:
        raise ValueError(f"dt = {dt!r}: the noise needs a step that divides {grid!r}")
    return every
