"""Passenger comfort and wheel torque of an antiskid run (issue 19, item 5).

Design table ``[comfort]`` (optional; paper 003 states no comfort limit, so
the limits are the design's choice and carry their source)::

    [comfort]
    a_max    = { value = 1.0,  unit = "m/s^2", source = "..." }   # |a| of the train
    jerk_max = { value = 0.75, unit = "m/s^3", source = "..." }   # |da/dt|
    window   = { value = 1.0,  unit = "s",     source = "..." }   # averaging window

Everything is computed from the runs the study records anyway (every case
at dt and dt/2, recorded every ``record_dt``; no extra simulation). On a
uniform grid of the record step: the train's acceleration
a(t) = (v(t + T/2) - v(t - T/2)) / T and its jerk
j(t) = (a(t + T/2) - a(t - T/2)) / T, T the window. The window averages out
transients a few steps long, which the step does not resolve (their jerk
moves with the step) and a passenger does not feel as one push.

The torque is the controller's commanded u(t) against the peak adhesion
torque T_adh = mu(lambda_opt) m g r of the nominal model (the most the rail
transmits in steady state) and the design's ``torque_range`` x T_adh (its
bound of a physical torque: a run that commands more has diverged).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...reader import Quantity, Reader


@dataclass(frozen=True)
class ComfortSpec:
    """``[comfort]``: limits on |a| (m/s^2) and |jerk| (m/s^3), window T (s)."""

    a_max: Quantity
    jerk_max: Quantity
    window: Quantity


def load_comfort(root: Reader) -> ComfortSpec | None:
    """The ``[comfort]`` table of a run design (None when absent)."""
    if not root.has("comfort"):
        return None
    t = root.table("comfort")
    out = ComfortSpec(t.quantity("a_max", "m/s^2", positive=True),
                      t.quantity("jerk_max", "m/s^3", positive=True),
                      t.quantity("window", "s", positive=True, hi=10.0))
    t.finish()
    return out


@dataclass(frozen=True)
class Comfort:
    """Acceleration, jerk and torque of one recorded run.

    Attributes
    ----------
    t_a, a : numpy.ndarray
        Times (s) and train acceleration (m/s^2), window-averaged.
    t_j, j : numpy.ndarray
        Times (s) and jerk (m/s^3).
    a_max_abs, jerk_max_abs : float
        Largest |a| and |j| (nan for a run too short for the window).
    time_above_a, time_above_jerk : float
        Time (s) with |a| above the limit, with |j| above the limit.
    jerk_windows : tuple[tuple[float, float, float], ...]
        (start, end, peak |j|) of each stretch with |j| above the limit.
    u_max_over_peak : float
        Largest commanded |u| over the peak adhesion torque.
    """

    t_a: np.ndarray
    a: np.ndarray
    t_j: np.ndarray
    j: np.ndarray
    a_max_abs: float
    jerk_max_abs: float
    time_above_a: float
    time_above_jerk: float
    jerk_windows: tuple
    u_max_over_peak: float


def _stretches(t: np.ndarray, x: np.ndarray, limit: float) -> tuple:
    """(start, end, peak |x|) of each run of consecutive samples with |x| > limit."""
    out, above = [], np.abs(x) > limit
    k = 0
    while k < len(x):
        if not above[k]:
            k += 1
            continue
        e = k
        while e + 1 < len(x) and above[e + 1]:
            e += 1
        out.append((float(t[k]), float(t[e]), float(np.max(np.abs(x[k:e + 1])))))
        k = e + 1
    return tuple(out)


def comfort_of(run, spec: ComfortSpec, u_peak: float, step: float) -> Comfort:
    """:class:`Comfort` of a recorded run (``run.t``, ``run.x[0]`` = v,
    ``run.u``) on a uniform grid of ``step`` seconds."""
    tg = np.arange(run.t[0], run.t[-1] + step / 2, step)
    vg = np.interp(tg, run.t, run.x[0])
    w = max(1, int(round(spec.window.value / step)))
    T = w * step
    a = (vg[w:] - vg[:-w]) / T
    t_a = tg[:-w] + T / 2
    j = (a[w:] - a[:-w]) / T
    t_j = t_a[:-w] + T / 2
    lim_a, lim_j = spec.a_max.value, spec.jerk_max.value
    peak = lambda x: float(np.max(np.abs(x))) if len(x) else float("nan")
    u = np.asarray(run.u[0], float)
    return Comfort(t_a, a, t_j, j, peak(a), peak(j),
                   float(np.sum(np.abs(a) > lim_a) * step), float(np.sum(np.abs(j) > lim_j) * step),
                   _stretches(t_j, j, lim_j), float(np.max(np.abs(u))) / u_peak)


#: Quantities per case (prefixed ``cases[NAME].``) when a design has ``[comfort]``.
COMFORT_QUANTITIES = ("a_max_abs", "jerk_max_abs", "time_above_a", "time_above_jerk",
                      "u_max_over_peak", "comfort_converged")


#: Relative tolerance of the Richardson estimate of the |a| and |jerk| peaks
#: over dt, dt/2, dt/4 for ``comfort_converged``.
COMFORT_RTOL = 0.01


def comfort_quantities(name: str, fine: Comfort, coarse: Comfort, quarter: Comfort | None = None,
                       rtol: float = COMFORT_RTOL) -> dict:
    """The :data:`COMFORT_QUANTITIES` of one case (reported from dt/2).

    ``comfort_converged``: the |a| and |jerk| peaks at dt, dt/2 and dt/4
    (``quarter``) pass :func:`workbench.refinement.screen` with tolerance
    ``rtol`` times the largest peak: "yes", else None (not determined,
    INCONCLUSIVE; also without a dt/4 run: a two-level agreement is no
    convergence, issue 33 item 4)."""
    b = f"cases[{name}]"
    conv = None
    if quarter is not None:
        from ...features.refinement import screen
        keys = ("a_max_abs", "jerk_max_abs")
        vals = {k: tuple(getattr(x, k) for x in (coarse, fine, quarter)) for k in keys}
        conv = screen(vals, {k: rtol * max(abs(x) for x in vals[k]) for k in keys})[0]
    return {f"{b}.a_max_abs": fine.a_max_abs, f"{b}.jerk_max_abs": fine.jerk_max_abs,
            f"{b}.time_above_a": fine.time_above_a, f"{b}.time_above_jerk": fine.time_above_jerk,
            f"{b}.u_max_over_peak": fine.u_max_over_peak,
            f"{b}.comfort_converged": conv}
