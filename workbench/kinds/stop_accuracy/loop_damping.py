"""Damping of the linearised loops of a ``stop-accuracy`` design's controllers
(:mod:`workbench.tuning.pid`: the exact roots of the delay equation), read
from the design's ``[plant]`` (the electric stage's T1, T2, P1), its control
period and the controller's named modules:

* module ``pid``: the speed loop (:func:`~workbench.tuning.pid.speed_loop`),
  dead time T1 plus half a control period (sample and hold), or behind the
  module ``predictor`` (nominal model exact) the half period only;
* module ``deceleration_loop``: the deceleration loop
  (:func:`~workbench.tuning.pid.deceleration_loop`), dead time T1 plus one
  control period (sample and hold, and the backward difference of the
  measured speed), through the loop's measurement filter.

Its time-domain check is :func:`sign_changes` of a recorded error (a ringing
loop changes sign often).
"""
from __future__ import annotations

import numpy as np

from ...tuning.pid import Damping, damping, deceleration_loop, speed_loop
from .run import controller_index

__all__ = ["loop_damping", "loop_values", "pid_damping", "pid_dead_time", "pid_gains",
           "sign_changes"]


def _controller(spec, name: str):
    return spec.controllers[controller_index(spec, name)]


def pid_gains(spec, name: str) -> dict:
    """kp, ki, kd of the module ``pid`` of the controller ``name``."""
    return {k: spec.constants[g].value for k, g in zip(("kp", "ki", "kd"),
                                                       _controller(spec, name).pid[1:])}


def pid_dead_time(spec, name: str) -> float:
    """Dead time (s) of the linearised speed loop of the controller ``name``."""
    hold = spec.dt_ctrl / 2
    return hold if _controller(spec, name).predictor else spec.params["T1"].value + hold


def pid_damping(spec, name: str) -> Damping:
    """:class:`~workbench.tuning.pid.Damping` of the speed loop of the controller ``name``."""
    p = spec.params
    return damping(*speed_loop(**pid_gains(spec, name), P1=p["P1"].value, T2=p["T2"].value),
                   pid_dead_time(spec, name))


def loop_values(spec, name: str) -> dict:
    """The values of the module ``deceleration_loop`` of the controller ``name``
    (gains, filter, sensor ratios)."""
    return _controller(spec, name).loop.values(spec.constants)


def loop_damping(spec, name: str) -> Damping:
    """:class:`~workbench.tuning.pid.Damping` of the deceleration loop of the
    controller ``name``."""
    p, loop = {k: q.value for k, q in spec.params.items()}, loop_values(spec, name)
    return damping(*deceleration_loop(loop["kp"], loop["ki"], P1=p["P1"], T2=p["T2"],
                                      tau=loop["tau_filter"]), p["T1"] + spec.dt_ctrl)


def sign_changes(err, deadband: float) -> int:
    """Sign changes of a recorded error ``err``, samples with |error| below
    ``deadband`` ignored: the oscillation count."""
    s = np.sign(np.where(np.abs(err) < deadband, 0.0, err))
    s = s[s != 0]
    return int(np.sum(s[1:] != s[:-1]))
