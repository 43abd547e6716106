"""ATO target speed profiles between two stations.

A jerk-limited *accelerate - cruise - brake* profile (an S-curve at both
ends) whose cruise speed is chosen so that the run takes exactly the planned
time: paper 002 tracks such a curve between Macun and Nanhu (1657.8 m,
114.9 s planned, 80 km/h limit). The paper does not say how its curve was
generated; this construction is ours and is documented in the report.

Closed forms used (one phase, speed 0 -> v with acceleration limit a and
jerk limit j; by point symmetry of the S-curve about its midpoint the phase
covers the distance v T / 2):

* v >= a^2 / j: T = v / a + a / j (jerk, constant a, jerk);
* v <  a^2 / j: T = 2 sqrt(v / j) (peak acceleration sqrt(v j) < a).

The run time with cruise speed v over distance S is
T(v) = (T_acc(v) + T_brk(v)) / 2 + S / v, valid while the two phases fit in S.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ModelError


@dataclass(frozen=True)
class ProfileSpec:
    """What an inter-station target profile is built from.

    Attributes
    ----------
    distance : float
        Station-to-station distance S (m).
    v_limit : float
        Line speed limit (m/s).
    accel : float
        Acceleration limit (m/s^2).
    brake : float
        Service braking used by the profile (m/s^2, positive).
    jerk : float
        Jerk limit (m/s^3).
    run_time : float
        Planned run time T_o (s).
    """

    distance: float
    v_limit: float
    accel: float
    brake: float
    jerk: float
    run_time: float


def phase_time(v: float, a: float, j: float) -> float:
    """Duration (s) of a jerk-limited speed change 0 -> v (m/s) with limits a, j."""
    if v >= a * a / j:
        return v / a + a / j
    return 2.0 * math.sqrt(v / j)


def run_time(spec: ProfileSpec, v: float) -> float:
    """Run time (s) of the profile with cruise speed ``v`` (m/s)."""
    return 0.5 * (phase_time(v, spec.accel, spec.jerk) + phase_time(v, spec.brake, spec.jerk)) \
        + spec.distance / v


def _fits(spec: ProfileSpec, v: float) -> bool:
    ta, tb = phase_time(v, spec.accel, spec.jerk), phase_time(v, spec.brake, spec.jerk)
    return v * (ta + tb) / 2.0 <= spec.distance


def cruise_speed(spec: ProfileSpec) -> float:
    """The cruise speed (m/s) that makes the run take ``spec.run_time``.

    Solved by bisection on the slow branch of T(v) (T decreases with v
    while both phases fit in the distance).

    Raises
    ------
    ModelError
        When the planned time is shorter than the fastest feasible run.
    """
    hi = spec.v_limit
    if not _fits(spec, hi):  # largest speed whose phases fit: bisection on _fits
        lo_f, hi_f = 0.0, hi
        for _ in range(200):
            mid = 0.5 * (lo_f + hi_f)
            lo_f, hi_f = (mid, hi_f) if _fits(spec, mid) else (lo_f, mid)
        hi = lo_f
    if run_time(spec, hi) > spec.run_time:
        raise ModelError(f"planned run time {spec.run_time} s is shorter than the fastest "
                         f"feasible run ({run_time(spec, hi):.4g} s at {hi:.4g} m/s)")
    lo = 1e-3
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if run_time(spec, mid) > spec.run_time else (lo, mid)
    return 0.5 * (lo + hi)


def _jerk_series(v: float, a: float, j: float) -> tuple[float, float, float]:
    """(jerk time, constant-acceleration time, peak acceleration) of one phase."""
    if v >= a * a / j:
        return a / j, v / a - a / j, a
    ap = math.sqrt(v * j)
    return ap / j, 0.0, ap


@dataclass(frozen=True)
class Profile:
    """A target profile sampled in time.

    Attributes
    ----------
    spec : ProfileSpec
    v_cruise : float
        Cruise speed (m/s).
    t, s, v, a : numpy.ndarray
        Time (s), position (m), speed (m/s), acceleration (m/s^2) samples.
    """

    spec: ProfileSpec
    v_cruise: float
    t: np.ndarray
    s: np.ndarray
    v: np.ndarray
    a: np.ndarray

    def speed_at(self, t) -> np.ndarray:
        """Target speed (m/s) at times ``t`` (s); 0 after the end."""
        return np.interp(t, self.t, self.v, right=0.0)

    def speed_at_distance(self, s) -> np.ndarray:
        """Target speed (m/s) as a function of position ``s`` (m)."""
        return np.interp(s, self.s, self.v, right=0.0)


def build_profile(spec: ProfileSpec, dt: float = 0.01) -> Profile:
    """Sample the jerk-limited profile of ``spec`` every ``dt`` seconds.

    The acceleration is piecewise linear (jerk piecewise constant) and is
    integrated exactly (trapezoid on a, Simpson-exact cubic on s), so the
    final position equals ``spec.distance`` to rounding (the knots of the
    acceleration are added to the time grid).
    """
    v = cruise_speed(spec)
    tj_a, tc_a, ap_a = _jerk_series(v, spec.accel, spec.jerk)
    tj_b, tc_b, ap_b = _jerk_series(v, spec.brake, spec.jerk)
    t_acc = 2 * tj_a + tc_a
    t_brk = 2 * tj_b + tc_b
    t_cruise = spec.run_time - t_acc - t_brk
    # breakpoints of the piecewise-linear acceleration
    knots_t = np.cumsum([0.0, tj_a, tc_a, tj_a, t_cruise, tj_b, tc_b, tj_b])
    knots_a = np.array([0.0, ap_a, ap_a, 0.0, 0.0, -ap_b, -ap_b, 0.0])
    n = int(round(spec.run_time / dt))
    t = np.union1d(np.linspace(0.0, spec.run_time, n + 1), knots_t)  # knots: exact integrals
    a = np.interp(t, knots_t, knots_a)
    h = np.diff(t)
    vv = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * h)])
    # s over a step with linear a: v0 h + h^2 (2 a0 + a1) / 6 (exact)
    ss = np.concatenate([[0.0], np.cumsum(vv[:-1] * h + h * h * (2 * a[:-1] + a[1:]) / 6)])
    vv[-1] = 0.0 if abs(vv[-1]) < 1e-9 else vv[-1]
    return Profile(spec, v, t, ss, np.maximum(vv, 0.0), a)


def spec_for_cruise(v_cruise: float, cruise_time: float, accel: float, brake: float,
                    jerk: float) -> ProfileSpec:
    """The profile spec whose run cruises at ``v_cruise`` (m/s) for ``cruise_time`` (s).

    Used for a leader that "accelerates, cruises at 86 km/h for about 120 s and
    brakes to the next station" (paper 001 §4): distance and planned time follow.
    """
    ta, tb = phase_time(v_cruise, accel, jerk), phase_time(v_cruise, brake, jerk)
    return ProfileSpec(distance=v_cruise * ((ta + tb) / 2.0 + cruise_time),
                       v_limit=1.2 * v_cruise, accel=accel, brake=brake, jerk=jerk,
                       run_time=ta + tb + cruise_time)
