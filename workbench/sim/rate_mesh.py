"""A refined mesh set by a rate bound: the level of each step of
:func:`workbench.sim.delay.simulate_closed_loop` on a refined mesh.

A plant whose fastest rate is S / x at a state magnitude x (a stiff mode
that speeds up as x falls, e.g. a creep ratio at low speed) is stepped at
dt / 2**k, k the smallest level (at most ``k_max``) with
(dt_ref / 2**k) S / x <= ``courant``. The level is measured against the
design's step ``dt_ref``, not the run's: a run at dt_ref / 2 then takes
exactly half of every step of the run at dt_ref, so step halving still
compares a mesh with its refinement.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["RateMesh"]


@dataclass(frozen=True)
class RateMesh:
    """Step halving by a rate bound (module docstring).

    Parameters
    ----------
    dt_ref : float
        The design's step (s): level 0.
    courant : float
        Largest step x rate accepted.
    k_max : int
        Finest level (steps of dt / 2**k_max).
    x_floor : float
        The state magnitude is taken as at least this (the rate S / x stays
        finite at x = 0).
    """

    dt_ref: float
    courant: float
    k_max: int
    x_floor: float = 1e-3

    def level(self, x: float, S: float) -> int:
        """The level k of a step from the state magnitude ``x``, the fastest
        rate being ``S / x`` (1/s)."""
        rate = self.dt_ref * S / (self.courant * max(x, self.x_floor))
        return 0 if rate <= 1.0 else min(self.k_max, math.ceil(math.log2(rate)))

    def of_state(self, S: float):
        """``level(x)`` of a state ``x`` whose first entry is the magnitude,
        the fastest rate being ``S / x[0]`` (the ``level`` of
        :func:`workbench.sim.delay.simulate_closed_loop`)."""
        return lambda x: self.level(x[0], S)
