"""The named module ``deceleration_loop`` of the ``stop-accuracy`` kind: paper
004's command generator, which closes a loop on the deceleration measured
from the axle speed sensors (issue 35, item 2).

The controller's law gives the *target* deceleration ``a_req`` (m/s^2; in
paper 004 the ATO's a_req = v_p^2 / (2 d_p)). The module, every control
period and per run:

1. reads the axle speeds of the measured speed v (the true speed times a
   fault's ``speed_ratio``; each axle in a state: ``o`` healthy, ``s`` sliding,
   reads ``slide_ratio`` x v, ``f`` failed, reads 0, ``h`` reads
   ``high_ratio`` x v, ``z`` stuck at its reading when braking started) and
   takes the train speed as their maximum (004 section 2.7);
2. differentiates it (backward difference over the control period) and
   low-passes it (first order, ``tau_filter``): the measured deceleration a_f;
3. corrects the command: with e = a_req - a_f, incremental fuzzy control
   (:class:`workbench.controllers.fuzzy.FuzzyIncrement`, scales ``e_scale``,
   ``de_scale``, ``du_scale``) while |e| > ``e_switch``, a PID (``kp``,
   ``ki``, ``kd``; :class:`workbench.controllers.pid.MaskedBatchPID`)
   restarted around the correction at each switch while |e| <= ``e_switch``
   (004 section 2.5); the correction is limited to +-c_max;
4. sends a_req + correction; where every axle is detected bad (sliding or
   failed) the loop is off and the law's a_req goes out alone (the fallback
   to the ATO open loop of 004 section 2.7). A stuck or high-reading axle is
   not detected.

Why a module and not an expression: the filter, the fuzzy correction (an
integral of increments), the PID's integrator and the speed when braking
started are internal state; an expression of the present cannot hold them.

A design writes ``deceleration_loop = { e_switch = "constant", ..., axles = 4 }``
in a ``[[controllers]]`` table: every key of :data:`LOOP_UNITS` names a constant
of ``[constants]`` in that unit; faults set the axles' states
(``[[faults]] axles = "fffo"``).

References
----------
Paper 004 (Wang, Wang, Wang 2019), sections 2.5 and 2.7.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AXLE_STATES", "DETECTED", "DecelerationLoop", "LOOP_UNITS", "LoopGains",
           "axle_speeds", "read_axles", "read_loop"]

#: ``deceleration_loop`` key -> unit of the constant it names (ki: the PID's
#: u = kp e + ki int(e dt) + kd de/dt, u and e in m/s^2).
LOOP_UNITS = {"e_switch": "m/s^2", "tau_filter": "s", "e_scale": "m/s^2", "de_scale": "m/s^3",
              "du_scale": "m/s^2", "kp": "1", "ki": "1/s", "kd": "s", "slide_ratio": "1",
              "high_ratio": "1"}
#: Axle-sensor states: healthy, sliding (reads low), failed (reads 0), reads high,
#: stuck at its reading when braking started.
AXLE_STATES = "osfhz"
#: States the command generator detects (the loop is off where every axle is in one).
DETECTED = "sf"


@dataclass(frozen=True)
class LoopGains:
    """A controller's ``deceleration_loop``: constants' names (:data:`LOOP_UNITS`)
    and the number of axle sensors."""

    names: dict
    axles: int = 4

    def values(self, constants) -> dict:
        return {k: constants[v].value for k, v in self.names.items()}

    def text(self) -> str:
        """One line for the report."""
        return ("deceleration loop (module `deceleration_loop`: the law is the target "
                f"deceleration; measured from the max of {self.axles} axle speeds; fuzzy "
                "increments above e_switch, PID below; constants " + ", ".join(
                    k if k == v else f"{k} = {v}" for k, v in self.names.items()) + ")")


def read_loop(t, constants) -> LoopGains:
    """A controller's ``deceleration_loop = {...}``: every key of
    :data:`LOOP_UNITS` names a constant of that unit, ``axles`` is a count."""
    from .modules import named_constants
    lt = t.table("deceleration_loop")
    axles = lt.number("axles", default=None, integer=True, lo=1, hi=16, what="axle count")
    axles = 4 if axles is None else int(axles)
    names = named_constants(lt, constants, LOOP_UNITS)
    lt.finish()
    v = LoopGains(names, axles).values(constants)
    checks = (("e_switch", v["e_switch"] > 0, "above 0"),
              ("tau_filter", v["tau_filter"] >= 0, "at least 0"),
              *((k, v[k] > 0, "above 0") for k in ("e_scale", "de_scale", "du_scale")),
              *((k, v[k] >= 0, "at least 0") for k in ("kp", "ki", "kd")),
              ("slide_ratio", 0 < v["slide_ratio"] <= 1, "in (0, 1]"),
              ("high_ratio", 1 <= v["high_ratio"] <= 2, "in [1, 2]"))
    for k, ok, what in checks:
        if not ok:
            raise t.fail(f"deceleration_loop.{k}", names[k], f"a constant {what} (it is "
                         f"{v[k]:g})")
    return LoopGains(names, axles)


def read_axles(t, controllers) -> str | None:
    """A fault's ``axles = "fffo"``: one state of :data:`AXLE_STATES` per axle of
    every controller's ``deceleration_loop``."""
    if not t.has("axles"):
        return None
    text = t.string("axles")
    counts = {c.loop.axles for c in controllers if c.loop is not None}
    if not counts:
        raise t.fail("axles", text, "no axle states (no controller has a deceleration_loop)")
    if len(counts) > 1 or len(text) not in counts or set(text) - set(AXLE_STATES):
        raise t.fail("axles", text, f"{min(counts)} axle states of {AXLE_STATES!r} ("
                     "o healthy, s sliding, f failed, h reads high, z stuck)")
    return text


def axle_speeds(states: np.ndarray, v: np.ndarray, v_first: np.ndarray, slide: float,
                high: float) -> np.ndarray:
    """Speeds (m/s) the axle sensors read, shape (n, axles), from the train
    speed ``v`` and the speed ``v_first`` when braking started (n,)."""
    return _read(_masks(states), v, v_first, slide, high)


def _masks(states: np.ndarray) -> list:
    return [states == "o", states == "s", states == "h", states == "z"]


def _read(masks, v, v_first, slide, high):
    col = v[:, None]
    return np.select(masks, [col, col * (1 - slide), col * high,
                             np.broadcast_to(v_first[:, None], masks[0].shape)], 0.0)


class DecelerationLoop:
    """The module's state over the runs of one controller.

    Parameters
    ----------
    gains : dict
        The constants' values (:meth:`LoopGains.values`).
    states : ndarray of str, shape (n, axles)
        Each run's axle states (fixed over the run).
    dt_ctrl, c_max : float
        Control period (s) and full service (m/s^2, the correction's limit).
    """

    def __init__(self, gains: dict, states: np.ndarray, dt_ctrl: float, c_max: float):
        from ...controllers.fuzzy import FuzzyIncrement
        from ...controllers.pid import MaskedBatchPID
        n = len(states)
        self.g, self.dt, self.c_max = gains, dt_ctrl, c_max
        self.fuzzy = FuzzyIncrement(gains["e_scale"], gains["de_scale"], gains["du_scale"])
        self.masks = _masks(states)
        self.closed = ~np.all(np.isin(states, list(DETECTED)), axis=1)
        self.pid = MaskedBatchPID({k: gains[k] for k in ("kp", "ki", "kd")}, dt_ctrl,
                                  self.closed)
        self.c, self.a_f, self.e_prev = np.zeros(n), np.zeros(n), np.zeros(n)
        self.anchor, self.in_pid = np.zeros(n), np.zeros(n, bool)
        self.v_prev = self.v_first = None

    def command(self, a_req: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The command (m/s^2) for the target ``a_req`` at the speed ``v`` the
        axles see (m/s), one control period after the last call."""
        g, dt = self.g, self.dt
        if self.v_first is None:
            self.v_first = v.copy()
        v_m = _read(self.masks, v, self.v_first, g["slide_ratio"], g["high_ratio"]).max(axis=1)
        if self.v_prev is None:
            self.v_prev = v_m.copy()
        raw = (self.v_prev - v_m) / dt
        self.v_prev = v_m
        k = dt / (g["tau_filter"] + dt)
        self.a_f = self.a_f + k * (raw - self.a_f)
        e = a_req - self.a_f
        de = (e - self.e_prev) / dt
        self.e_prev = e
        # command = a_req (feed-forward) + correction; the correction is integrated by the
        # fuzzy increments, or set by the PID around its value at the switch
        corr = self.c
        small = np.abs(e) <= g["e_switch"]
        enter = small & ~self.in_pid
        self.anchor = np.where(enter, corr, self.anchor)
        self.pid.reset(enter)
        fz = corr + self.fuzzy.increment(e, de)
        pid_out = self.pid.step(small, e, self.anchor)
        corr = np.clip(np.where(small, pid_out, fz), -self.c_max, self.c_max)
        self.in_pid = small
        self.c = np.where(self.closed, corr, 0.0)
        return np.where(self.closed, a_req + corr, a_req)
