"""Passenger comfort and wheel torque of an antiskid run (issue 19, item 5).

Acceleration, jerk, their peaks and the stretches above a limit are the
general :mod:`workbench.features.comfort` (its ``[comfort]`` table: a_max,
jerk_max, window, all required here; paper 003 states no comfort limit, so
the limits are the design's choice and carry their source). Everything is
computed from the runs the study records anyway (every case at dt and dt/2,
recorded every ``record_dt``; no extra simulation).

The ``[comfort]`` table (:func:`~workbench.features.comfort.load_comfort`)
and the convergence of the peaks over three steps
(:func:`~workbench.features.comfort.peaks_converged`) are general too.
What stays here is paper 003's: the torque is the controller's commanded
u(t) against the peak adhesion torque T_adh = mu(lambda_opt) m g r of the
nominal model (the most the rail transmits in steady state), and the
``cases[NAME].*`` quantities with their dt, dt/2, dt/4 convergence flag.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ...features.comfort import (COMFORT_RTOL, Comfort, ComfortLimits, comfort_of_speed,
                                 peaks_converged)

__all__ = ["COMFORT_QUANTITIES", "RunComfort", "comfort_of", "comfort_quantities"]


@dataclass(frozen=True)
class RunComfort(Comfort):
    """:class:`~workbench.features.comfort.Comfort` of the train's speed, and
    the commanded torque.

    Attributes
    ----------
    u_max_over_peak : float
        Largest commanded |u| over the peak adhesion torque.
    """

    u_max_over_peak: float


def comfort_of(run, spec: ComfortLimits, u_peak: float, step: float) -> RunComfort:
    """:class:`RunComfort` of a recorded run (``run.t``, ``run.x[0]`` = v,
    ``run.u``) on a uniform grid of ``step`` seconds."""
    c = comfort_of_speed(run.t, run.x[0], spec, step)
    u = np.asarray(run.u[0], float)
    return RunComfort(**{f.name: getattr(c, f.name) for f in fields(c)},
                      u_max_over_peak=float(np.max(np.abs(u))) / u_peak)


#: Per-case comfort measures (attributes of :class:`RunComfort`).
_MEASURES = ("a_max_abs", "jerk_max_abs", "time_above_a", "time_above_jerk", "u_max_over_peak")
#: Quantities per case (prefixed ``cases[NAME].``) when a design has ``[comfort]``.
COMFORT_QUANTITIES = _MEASURES + ("comfort_converged",)


def comfort_quantities(name: str, fine: RunComfort, coarse: RunComfort,
                       quarter: RunComfort | None = None, rtol: float = COMFORT_RTOL) -> dict:
    """The :data:`COMFORT_QUANTITIES` of one case (reported from dt/2).

    ``comfort_converged``: the peaks at dt, dt/2 and dt/4 (``quarter``) pass
    :func:`workbench.features.comfort.peaks_converged`: "yes", else None (not
    determined, INCONCLUSIVE; also without a dt/4 run: a two-level agreement
    is no convergence, issue 33 item 4)."""
    b = f"cases[{name}]"
    conv = None if quarter is None else peaks_converged((coarse, fine, quarter), rtol)
    return {f"{b}.{k}": getattr(fine, k) for k in _MEASURES} | {f"{b}.comfort_converged": conv}
