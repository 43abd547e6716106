"""Sampled PID with output limits and conditional-integration anti-windup.

Shared by every study that compares against PID (papers 000, 002, 004).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class PID:
    """Discrete PID u = kp e + ki sum(e) dt + kd (e - e_prev)/dt.

    Parameters
    ----------
    kp, ki, kd : float
        Gains (units of output per unit error, per unit error-second, per
        unit error/second).
    dt : float
        Sampling period (s), > 0.
    u_min, u_max : float
        Output limits; the integrator is frozen while the output saturates in
        the direction of the error (conditional integration).
    derivative_on_measurement : bool
        Differentiate -y instead of e (no derivative kick on set-point
        steps); then :meth:`step` needs ``measurement``.
    """

    kp: float
    ki: float = 0.0
    kd: float = 0.0
    dt: float = 0.1
    u_min: float = float("-inf")
    u_max: float = float("inf")
    derivative_on_measurement: bool = False
    _integral: float = field(default=0.0, init=False, repr=False)
    _prev: float | None = field(default=None, init=False, repr=False)

    def __post_init__(self):
        if not self.dt > 0:
            raise ValueError(f"dt = {self.dt!r}; expected a positive sampling period (s)")
        if not self.u_min < self.u_max:
            raise ValueError(f"u_min = {self.u_min!r}, u_max = {self.u_max!r}; expected u_min < u_max")

    def reset(self) -> None:
        self._integral, self._prev = 0.0, None

    def step(self, error: float, measurement: float | None = None) -> float:
        """One sample: the saturated output for this error."""
        d_src = -measurement if self.derivative_on_measurement else error
        if self.derivative_on_measurement and measurement is None:
            raise ValueError("measurement is required with derivative_on_measurement")
        deriv = 0.0 if self._prev is None else (d_src - self._prev) / self.dt
        self._prev = d_src
        u_free = self.kp * error + self.ki * (self._integral + error * self.dt) + self.kd * deriv
        u = min(max(u_free, self.u_min), self.u_max)
        saturating = (u_free > self.u_max and error > 0) or (u_free < self.u_min and error < 0)
        if not saturating:
            self._integral += error * self.dt
        return u


class BatchPID:
    """:class:`PID` (error form, no derivative on measurement) for a batch of
    independent loops, one gain set each: the same arithmetic, elementwise.

    Parameters
    ----------
    kp, ki, kd : array_like
        Gains, one per loop (broadcast to ``n``).
    n : int
        Batch size.
    dt, u_min, u_max : float
        As for :class:`PID`.
    """

    def __init__(self, kp, ki, kd, n: int, *, dt: float, u_min: float = float("-inf"),
                 u_max: float = float("inf")):
        if not dt > 0:
            raise ValueError(f"dt = {dt!r}; expected a positive sampling period (s)")
        if not u_min < u_max:
            raise ValueError(f"u_min = {u_min!r}, u_max = {u_max!r}; expected u_min < u_max")
        shape = (n,)
        self.kp, self.ki, self.kd = (np.broadcast_to(np.asarray(x, float), shape)
                                     for x in (kp, ki, kd))
        self.dt, self.u_min, self.u_max = dt, u_min, u_max
        self.integral = np.zeros(shape)
        self.prev: np.ndarray | None = None

    def step(self, error) -> np.ndarray:
        """One sample: the saturated outputs for these errors."""
        error = np.asarray(error, float)
        deriv = np.zeros_like(error) if self.prev is None else (error - self.prev) / self.dt
        self.prev = error
        u_free = self.kp * error + self.ki * (self.integral + error * self.dt) + self.kd * deriv
        u = np.minimum(np.maximum(u_free, self.u_min), self.u_max)
        saturating = ((u_free > self.u_max) & (error > 0)) | ((u_free < self.u_min) & (error < 0))
        self.integral = np.where(saturating, self.integral, self.integral + error * self.dt)
        return u


class MaskedBatchPID:
    """:class:`PID` (no output limits) for a batch of loops that are restarted
    and stepped only where masks say so: the arithmetic of ``PID.step``,
    elementwise (paper 004's deceleration PID, which runs only while the error
    is small and restarts at each switch from the fuzzy controller, section 2.5).

    Parameters
    ----------
    gains : dict
        ``kp``, ``ki``, ``kd`` (validated by :class:`PID`).
    dt : float
        Sampling period (s).
    active : ndarray of bool
        Loops that run at all (the others are never stepped).
    """

    def __init__(self, gains: dict, dt: float, active: np.ndarray):
        ref = PID(**gains, dt=dt)     # validates; its limits are infinite (never saturates)
        self.kp, self.ki, self.kd, self.dt = ref.kp, ref.ki, ref.kd, dt
        self.active = active
        n = len(active)
        self.integral, self.prev, self.has_prev = np.zeros(n), np.zeros(n), np.zeros(n, bool)

    def reset(self, where: np.ndarray) -> None:
        """Restart the loops ``where`` (as :meth:`PID.reset`)."""
        m = where & self.active
        self.integral = np.where(m, 0.0, self.integral)
        self.has_prev &= ~m

    def step(self, where: np.ndarray, e: np.ndarray, base: np.ndarray) -> np.ndarray:
        """``base`` plus the PID output where ``where`` (active loops only), else ``base``."""
        m = where & self.active
        deriv = np.where(self.has_prev, (e - self.prev) / self.dt, 0.0)
        u = self.kp * e + self.ki * (self.integral + e * self.dt) + self.kd * deriv
        self.prev = np.where(m, e, self.prev)
        self.has_prev |= m
        self.integral = np.where(m, self.integral + e * self.dt, self.integral)
        return np.where(m, base + u, base)
