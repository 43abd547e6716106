"""A certified switching rule for paper 003's eq (75): the cruise gains k2
for which the printed switch state (v_d, lambda_opt) lies in a certified
basin of the cruise law (61).

For each k2 of a grid (k1 kept), :func:`~workbench.papers.p003.antiskid_basin.switch_in_basin`
decides whether the switch state is CERTIFIED (inside {V <= c_certified}
for some P = modal_P(A + B K, [1, w]) of the grid) or not, and simulates
the delay-free trajectory from it; the edge between the largest certified
grid value and the next one is then bisected
(:func:`workbench.features.basin_points.sweep_gain_entry`). Gains given for comparison
(e.g. the rows of 003's Table 3) are judged the same way, with their own k1.

The rule is *sufficient*: a state outside every certified level set may
still converge (the "fate" column says what the delay-free trajectory does).

Only the gain parameterisation (k2 of law (61), k1 kept, Table 3's rows) is
paper 003's; the sweep is :func:`workbench.features.basin_points.sweep_gain_entry`.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (61),
   (75); Table 3.
"""
from __future__ import annotations

from functools import lru_cache

from ...features.basin_points import GainSweep, sweep_gain_entry
from ...memo import shared
from .antiskid_basin import switch_in_basin

#: Result of :func:`safe_k2_range`: a :class:`~workbench.features.basin_points.GainSweep`
#: of k2 (entry 1) with k1 = ``gain[0]`` kept; ``grid_min`` the smallest k2 of the grid.
K2Sweep = GainSweep


@lru_cache(maxsize=8)
def _sweep(values: tuple, v_d: float, k1: float, point: tuple, grid: tuple, compare: tuple,
           bisect: int, seed: int) -> K2Sweep:
    vals = dict(values)
    judge = lambda K: switch_in_basin(vals, v_d, K, point, seed=seed)
    return sweep_gain_entry(judge, point, (k1, 0.0), 1, grid, compare=compare, bisect=bisect)


def safe_k2_range(values: dict, v_d: float, k1: float, point, *, grid, compare=(),
                  bisect: int = 4, seed: int = 0) -> K2Sweep:
    """Cruise gains k2 (k1 kept) for which ``point`` lies in a certified basin.

    Parameters
    ----------
    values : dict
        Nominal plant constants (SI) the controller is built on.
    v_d : float
        Cruise speed (m/s).
    k1 : float
        First gain entry, kept along the sweep.
    point : (v, lambda)
        Switch state (absolute), e.g. (v_d, lambda_opt) for eq (75) as printed.
    grid : sequence of float
        k2 values judged.
    compare : sequence of (label, (k1, k2))
        Gains judged for comparison (e.g. 003 Table 3).
    bisect : int
        Bisection steps on the edge of the certified range.
    seed : int
        Seed of the falsifier.

    Returns
    -------
    K2Sweep
    """
    vals = tuple(sorted((k, float(v)) for k, v in values.items()))
    cmp_ = tuple((str(lab), (float(g[0]), float(g[1]))) for lab, g in compare)
    key = (vals, float(v_d), float(k1), tuple(float(p) for p in point),
           tuple(float(g) for g in grid), cmp_, int(bisect), int(seed))
    # the designs that differ only in the plant's mass share the controller's
    # nominal model, hence this sweep: computed once per run (run folder)
    return shared("antiskid_basin_k2.sweep", key, lambda: _sweep(*key))
