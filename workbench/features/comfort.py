"""Passenger comfort of a speed trajectory: acceleration, jerk, their peaks,
the time and the stretches above a limit (issues 19 and 35).

One implementation for every study that reports comfort; it knows a speed
signal and a step, nothing of the model that produced them.

Design table ``[comfort]`` (:func:`read_limits`; every limit carries its
source, since the papers state none)::

    [comfort]
    a_max    = { value = 1.0,  unit = "m/s^2", source = "..." }   # |a| of the train
    jerk_max = { value = 0.75, unit = "m/s^3", source = "..." }   # |da/dt|
    window   = { value = 1.0,  unit = "s",     source = "..." }   # averaging window

Two ways to the same quantities:

* a recorded trajectory (:func:`comfort_of_speed`): on a uniform grid of the
  record step, a(t) = (v(t + T/2) - v(t - T/2)) / T and
  j(t) = (a(t + T/2) - a(t - T/2)) / T, T the window (whole steps). The window
  averages out transients a few steps long, which the step does not resolve
  (their jerk moves with the step) and a passenger does not feel as one push;
* acceleration samples fed step by step over a batch of runs
  (:class:`RunningComfort`, a Monte Carlo that cannot keep every trajectory):
  the jerk is the step-to-step difference / step, the window one step.

Both use :func:`rate` for the differences, :func:`peak_abs` for the peaks and
count the samples above a limit times the step for the time above it.

A recorded run with an input (:func:`comfort_of`: the speed one of its
states) adds its largest |input| over a reference magnitude; a study that
runs each case at a step, its half and its quarter reports the half's
measures and whether the peaks converged (:func:`comfort_quantities`).
Tests on toy runs, no model: ``tests/test_comfort.py``.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..reader import Quantity, Reader

__all__ = ["ComfortLimits", "Comfort", "RunningComfort", "load_comfort", "peaks_converged",
           "read_limits", "rate", "peak_abs",
           "time_above", "stretches", "acceleration_jerk", "comfort_of_speed", "rate_units",
           "metric_units", "PEAKS", "TIMES", "RunComfort", "comfort_of", "RUN_MEASURES",
           "COMFORT_QUANTITIES", "comfort_quantities"]

#: Peak quantities: name -> attribute of :class:`Comfort` (|a|, |jerk|).
PEAKS = {"peak_abs_accel": "a_max_abs", "peak_abs_jerk": "jerk_max_abs"}
#: Time-above quantities (with a limit): name -> attribute of :class:`Comfort`.
TIMES = {"time_above_accel": "time_above_a", "time_above_jerk": "time_above_jerk"}


@dataclass(frozen=True)
class ComfortLimits:
    """``[comfort]``: limits on |a| and |jerk|, averaging window T (s); None: not given."""

    a_max: Quantity | None
    jerk_max: Quantity | None
    window: Quantity | None = None


def rate_units(speed_unit: str) -> tuple[str, str]:
    """Units of the acceleration and the jerk of a speed in ``speed_unit``
    ("m/s" -> "m/s^2", "m/s^3"; else "(u)/s", "(u)/s^2")."""
    base = speed_unit[:-2] if speed_unit.endswith("/s") else ""
    if base and "/" not in base and "(" not in base:
        return f"{base}/s^2", f"{base}/s^3"
    return f"({speed_unit})/s", f"({speed_unit})/s^2"


def read_limits(t: Reader, speed_unit: str = "m/s", *, required: bool = True,
                window: bool = True) -> ComfortLimits:
    """The limits of a ``[comfort]`` table (its reader ``t``; the caller
    reads its own keys first and calls ``t.finish()`` after).

    Parameters
    ----------
    t : Reader
        The ``[comfort]`` table.
    speed_unit : str
        Unit of the speed; the limits are in :func:`rate_units` of it.
    required : bool
        a_max and jerk_max must be given (else each is optional, None).
    window : bool
        Read the averaging ``window`` (s, at most 10 s; required with
        ``required``); False: the table has none.
    """
    ua, uj = rate_units(speed_unit)
    opt = {} if required else {"default": None}
    return ComfortLimits(t.quantity("a_max", ua, positive=True, **opt),
                         t.quantity("jerk_max", uj, positive=True, **opt),
                         t.quantity("window", "s", positive=True, hi=10.0, **opt)
                         if window else None)


def load_comfort(root: Reader) -> ComfortLimits | None:
    """The ``[comfort]`` table of a design with every limit and the window
    required (None when the design has none)."""
    if not root.has("comfort"):
        return None
    t = root.table("comfort")
    out = read_limits(t)
    t.finish()
    return out


def rate(new: np.ndarray, old: np.ndarray, T: float) -> np.ndarray:
    """Difference quotient (new - old) / T (acceleration of a speed, jerk of an acceleration)."""
    return (new - old) / T


def peak_abs(x: np.ndarray) -> float:
    """Largest |x| (nan for no sample)."""
    return float(np.max(np.abs(x))) if len(x) else float("nan")


def time_above(x: np.ndarray, limit: float, step: float) -> float:
    """Time (s) with |x| above ``limit``: samples above it times the step."""
    return float(np.sum(np.abs(x) > limit) * step)


def stretches(t: np.ndarray, x: np.ndarray, limit: float) -> tuple:
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


def acceleration_jerk(t: np.ndarray, v: np.ndarray, step: float, window: float) -> tuple:
    """(t_a, a, t_j, j) of a speed ``v`` recorded at times ``t`` (not
    necessarily uniform): v interpolated on a grid of ``step`` seconds, the
    window rounded to whole steps (at least one), centred differences."""
    tg = np.arange(t[0], t[-1] + step / 2, step)
    vg = np.interp(tg, t, v)
    w = max(1, int(round(window / step)))
    T = w * step
    a = rate(vg[w:], vg[:-w], T)
    t_a = tg[:-w] + T / 2
    j = rate(a[w:], a[:-w], T)
    return t_a, a, t_a[:-w] + T / 2, j


@dataclass(frozen=True)
class Comfort:
    """Acceleration and jerk of one recorded trajectory.

    Attributes
    ----------
    t_a, a : numpy.ndarray
        Times (s) and acceleration, window-averaged.
    t_j, j : numpy.ndarray
        Times (s) and jerk.
    a_max_abs, jerk_max_abs : float
        Largest |a| and |j| (nan for a run too short for the window).
    time_above_a, time_above_jerk : float
        Time (s) with |a| above its limit, with |j| above its limit.
    jerk_windows : tuple[tuple[float, float, float], ...]
        (start, end, peak |j|) of each stretch with |j| above the limit.
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


def comfort_of_speed(t: np.ndarray, v: np.ndarray, limits: ComfortLimits,
                     step: float) -> Comfort:
    """:class:`Comfort` of a speed ``v`` recorded at times ``t``, on a grid of
    ``step`` seconds with the window and limits of ``limits`` (all given)."""
    t_a, a, t_j, j = acceleration_jerk(t, v, step, limits.window.value)
    lim_a, lim_j = limits.a_max.value, limits.jerk_max.value
    return Comfort(t_a, a, t_j, j, peak_abs(a), peak_abs(j), time_above(a, lim_a, step),
                   time_above(j, lim_j, step), stretches(t_j, j, lim_j))


@dataclass(frozen=True)
class RunComfort(Comfort):
    """:class:`Comfort` of a recorded run's speed, and its input.

    Attributes
    ----------
    u_max_over_peak : float
        Largest |u| of the run's first input over a reference magnitude (the
        most the actuator or the contact transmits, say).
    """

    u_max_over_peak: float


def comfort_of(run, limits: ComfortLimits | None, u_peak: float, step: float,
               speed: int = 0) -> RunComfort | None:
    """:class:`RunComfort` of a recorded run (``run.t``, ``run.x[speed]`` the
    speed, ``run.u[0]`` the input) on a uniform grid of ``step`` seconds
    (:func:`comfort_of_speed`), the input over ``u_peak``; None without
    ``limits`` (a design with no comfort table)."""
    if limits is None:
        return None
    c = comfort_of_speed(run.t, run.x[speed], limits, step)
    u = np.asarray(run.u[0], float)
    return RunComfort(**{f.name: getattr(c, f.name) for f in fields(c)},
                      u_max_over_peak=float(np.max(np.abs(u))) / u_peak)


#: Relative tolerance of :func:`peaks_converged` (of the largest peak).
COMFORT_RTOL = 0.01


def peaks_converged(levels, rtol: float = COMFORT_RTOL) -> str | None:
    """Whether the |a| and |jerk| peaks of :class:`Comfort` results at a step,
    its half and its quarter (``levels``, three) converged: they pass
    :func:`workbench.features.refinement.screen` with a tolerance of ``rtol``
    times the largest peak. "yes", else None (not determined, INCONCLUSIVE)."""
    from .refinement import screen
    keys = ("a_max_abs", "jerk_max_abs")
    vals = {k: tuple(getattr(x, k) for x in levels) for k in keys}
    return screen(vals, {k: rtol * max(abs(x) for x in vals[k]) for k in keys})[0]


#: Per-case measures of a run (attributes of :class:`RunComfort`).
RUN_MEASURES = ("a_max_abs", "jerk_max_abs", "time_above_a", "time_above_jerk",
                "u_max_over_peak")
#: Quantities per case (prefixed ``cases[NAME].``): :data:`RUN_MEASURES` and the convergence flag.
COMFORT_QUANTITIES = RUN_MEASURES + ("comfort_converged",)


def comfort_quantities(name: str, fine: RunComfort, coarse: RunComfort,
                       quarter: RunComfort | None = None, rtol: float = COMFORT_RTOL) -> dict:
    """The :data:`COMFORT_QUANTITIES` of case ``name`` run at a step
    (``coarse``), its half (``fine``, the values reported) and its quarter.

    ``comfort_converged``: the peaks of the three pass :func:`peaks_converged`:
    "yes", else None (not determined, INCONCLUSIVE; also without a quarter
    run: a two-level agreement is no convergence, issue 33 item 4)."""
    b = f"cases[{name}]"
    conv = None if quarter is None else peaks_converged((coarse, fine, quarter), rtol)
    return {f"{b}.{k}": getattr(fine, k) for k in RUN_MEASURES} | {f"{b}.comfort_converged": conv}


class RunningComfort:
    """Peaks of |a| and |jerk| (and the time above the limits) of a batch of
    runs whose acceleration samples arrive one step at a time.

    Parameters
    ----------
    n : int
        Runs in the batch.
    step : float
        Time between samples (s).
    limits : ComfortLimits, optional
        Limits for the time above them (a missing limit: no such time).
    """

    def __init__(self, n: int, step: float, limits: ComfortLimits | None = None):
        self.step, self.limits = step, limits or ComfortLimits(None, None)
        self.a_peak, self.j_peak = np.zeros(n), np.zeros(n)
        self.n_a, self.n_j = np.zeros(n, np.int64), np.zeros(n, np.int64)
        self._prev = None

    def add(self, a: np.ndarray, active: np.ndarray) -> None:
        """Take the samples ``a`` (one per run) of the runs still ``active``."""
        self.a_peak = np.where(active, np.fmax(self.a_peak, np.abs(a)), self.a_peak)
        if self.limits.a_max is not None:
            self.n_a += active & (np.abs(a) > self.limits.a_max.value)
        if self._prev is not None:
            j = np.abs(rate(a, self._prev, self.step))
            self.j_peak = np.where(active, np.fmax(self.j_peak, j), self.j_peak)
            if self.limits.jerk_max is not None:
                self.n_j += active & (j > self.limits.jerk_max.value)
        self._prev = a

    def metrics(self) -> dict:
        """:data:`PEAKS` and, per limit given, its :data:`TIMES` entry -> array over the runs."""
        out = dict(zip(PEAKS, (self.a_peak, self.j_peak)))
        for (name, _), lim, n in zip(TIMES.items(), (self.limits.a_max, self.limits.jerk_max),
                                     (self.n_a, self.n_j)):
            if lim is not None:
                out[name] = n * self.step
        return out


def metric_units(speed_unit: str, limits: ComfortLimits | None) -> dict[str, str]:
    """name -> unit of the comfort metrics of a speed in ``speed_unit``
    (:data:`PEAKS`; the :data:`TIMES` of the limits given)."""
    u = speed_unit
    out = dict(zip(PEAKS, (f"({u})/s", f"({u})/s^2")))
    lims = (None, None) if limits is None else (limits.a_max, limits.jerk_max)
    out |= {name: "s" for name, lim in zip(TIMES, lims) if lim is not None}
    return out
