"""Stops on the nominal plant that track the ``[reference]`` target curve,
recorded whole, with the oscillation count of their speed error while
tracking (:func:`~.loop_damping.sign_changes`): one stop per named
controller, in one batch (:func:`~.run.simulate_cases`), every controller
meeting the same plant.

A report draws the traces (speed error, final approach) and tabulates the
stop errors and the sign changes beside the damping of each loop
(:mod:`.loop_damping`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .loop_damping import sign_changes
from .run import controller_index, simulate_cases

__all__ = ["TrackedStop", "tracked_stops"]


@dataclass(frozen=True)
class TrackedStop:
    """One stop on the nominal plant (no uncertainty).

    Attributes
    ----------
    error : float
        Stop error (m, + = overshoot).
    t, dx, v, v_d : ndarray
        Time from the braking start (s), position - stopping point (m),
        speed and target speed (m/s).
    sign_changes : int
        Sign changes of the speed error v - v_d while tracking (the first
        ``track_share`` of the planned braking time), errors below the
        dead band ignored: the oscillation count.
    """

    error: float
    t: np.ndarray
    dx: np.ndarray
    v: np.ndarray
    v_d: np.ndarray
    sign_changes: int


def tracked_stops(spec, laws, names, speed: float, D: float, *, track_share: float,
                  deadband: float) -> dict:
    """{controller: TrackedStop} of each controller of ``names`` (the design's
    names) braking at ``speed`` (km/h) to the stopping point ``D`` (m) along
    ``spec.reference``, on the nominal plant; ``laws`` of
    :func:`~.run.compile_laws`; sign changes counted over the first
    ``track_share`` of the planned braking, errors below ``deadband`` (m/s)
    ignored."""
    tr, Ds = simulate_cases(spec, laws, spec.dt,
                            [(speed, controller_index(spec, c), None, D) for c in names])
    _, vd, t_plan = spec.reference.braking(D, tr.t)
    track = tr.t < track_share * t_plan
    return {c: TrackedStop(float(tr.x_stop[j] - Ds[j]), tr.t, tr.x[:, j] - Ds[j], tr.v[:, j], vd,
                           sign_changes((tr.v[:, j] - vd)[track], deadband))
            for j, c in enumerate(names)}
