"""Fixed-step simulation of speed-profile tracking (paper 002); the platoon of
paper 001 is in :mod:`workbench.sim.platoon`.

The plants here are discrete-time / non-stiff: the 002 train is stepped at a
fine plant step ``dt`` (the lag integrated exactly for a demand held over the
step, the pure delay as a FIFO of whole steps; in the first-order reading the
lag acts on speed and its exact increment is limited to the acceleration
limits times ``dt``) and the controller runs every
``Ts = n_sub dt`` with zero-order hold. Every state is an array over a batch
of independent runs (controllers, parameter sets, stations), so a whole
parameter study is one loop over time.

A run ends, per batch element, at the first plant step after the profile's
braking has begun where the speed is 0: the train is then held by its parking
brake (the ATO stop), and that time and position define the quality indices.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Literal, Sequence

import numpy as np

from ..plants.train002 import FirstOrderTrain002, Train002, davis, static_map


@dataclass(frozen=True)
class Route:
    """A station-to-station route: distance (m) and a piecewise-constant gradient.

    Attributes
    ----------
    distance : float
        Stopping point (m).
    grade_from : tuple[float, ...]
        Positions (m) where each gradient section begins (first is 0).
    grade : tuple[float, ...]
        Gradient of each section (rise over run, up-hill positive).
    """

    distance: float
    grade_from: tuple[float, ...] = (0.0,)
    grade: tuple[float, ...] = (0.0,)

    def gradient_at(self, s: np.ndarray) -> np.ndarray:
        """Gradient (-) at positions ``s`` (m); the first section extends backwards."""
        return np.asarray(self.grade)[np.searchsorted(self.grade_from[1:], s, side="right")]


@dataclass(frozen=True)
class TrackingRun:
    """Sampled histories of a batch of tracking runs (rows = batch elements).

    Attributes
    ----------
    t : numpy.ndarray
        Sample times (s), shape (K,).
    v, s, a, u, target : numpy.ndarray
        Speed (m/s), position (m), net acceleration over the next sample
        (m/s^2), command, target speed (m/s); shape (N, K).
    stop_time, stop_pos : numpy.ndarray
        Time (s) and position (m) of the stop; nan when the train did not stop
        within the horizon. Shape (N,).
    traction_work : numpy.ndarray
        Integral of max(a_applied, 0) v dt up to the stop (J/kg), shape (N,);
        a_applied is the lag's output (integrating reading) or the realised
        traction/brake acceleration (first-order reading), before resistance.
    """

    t: np.ndarray
    v: np.ndarray
    s: np.ndarray
    a: np.ndarray
    u: np.ndarray
    target: np.ndarray
    stop_time: np.ndarray
    stop_pos: np.ndarray
    traction_work: np.ndarray

    def rows(self, idx) -> "TrackingRun":
        """The runs ``idx`` (a slice or index array) of the batch."""
        return TrackingRun(self.t, *(getattr(self, f)[idx] for f in
                                     ("v", "s", "a", "u", "target", "stop_time", "stop_pos",
                                      "traction_work")))


Controller = Callable[[int, np.ndarray, np.ndarray], np.ndarray]
"""``control(k, y, y_target_next) -> u`` for a batch (arrays of shape (N,))."""


def simulate_tracking(train: Train002 | Sequence[Train002], route: Route,
                      target: Callable[[np.ndarray], np.ndarray], control: Controller, n: int,
                      *, Ts: float, dt: float, horizon: float, brake_start: float,
                      kernel: Literal["compiled", "numpy"] | None = None) -> TrackingRun:
    """Track ``target(t)`` with ``control`` on a batch of ``n`` trains.

    Parameters
    ----------
    train : Train002 or sequence of Train002
        One train for the whole batch, or G trains of one model and one delay
        (e.g. a train and copies with nudged parameters,
        :func:`workbench.features.reproducible.nudged`): the batch is then G
        consecutive blocks of ``n / G`` runs, block g on train g. Every run
        does the arithmetic it does in a batch of its own train.
    route : Route
    target : callable
        Target speed (m/s) as a function of time (s), vectorised.
    control : callable
        Batch controller, called every ``Ts`` with the sample index, the
        measured speeds y(k) and the target y*(k+1).
    n : int
        Batch size.
    Ts, dt : float
        Control sample and plant step (s); ``Ts`` must be a multiple of ``dt``
        and ``train.delay`` a multiple of ``dt``.
    horizon : float
        Longest simulated time (s).
    brake_start : float
        Time (s) after which a standstill counts as the stop.
    kernel : {"compiled", "numpy"}, optional
        How the plant steps between two samples run: the numba kernel of
        :mod:`workbench.sim.tracking_jit` (the default when numba is
        installed) or numpy arrays; both give the same bits.
    """
    trains = (train,) if isinstance(train, Train002) else tuple(train)
    if not trains or n % len(trains) or len({(type(x), x.delay) for x in trains}) != 1:
        raise ValueError(f"{len(trains)} trains for a batch of {n}: expected trains of one "
                         f"model and one delay, and a batch that is a multiple of their number")
    if kernel not in (None, "compiled", "numpy"):
        raise ValueError(f"kernel = {kernel!r}; expected 'compiled' or 'numpy'")
    train = trains[0]
    n_sub = int(round(Ts / dt))
    n_delay = int(round(train.delay / dt))
    if not math.isclose(n_sub * dt, Ts) or not math.isclose(n_delay * dt, train.delay,
                                                            abs_tol=1e-12):
        raise ValueError(f"Ts = {Ts} and delay = {train.delay} must be multiples of dt = {dt}")
    step = _substeps_numpy if kernel == "numpy" else _compiled_or_numpy(kernel)
    K = int(math.ceil(horizon / Ts))
    first_order = isinstance(train, FirstOrderTrain002)
    p = _per_run(trains, n, dt, first_order, np.asarray(route.grade))
    fifo = np.zeros((n_delay + 1, n))              # demands of the last n_delay steps
    head = 0
    edges = np.asarray(route.grade_from[1:], float)
    v = np.zeros(n); s = np.zeros(n); a = np.zeros(n)
    work = np.zeros(n)
    stopped = np.zeros(n, bool)
    stop_time = np.full(n, np.nan); stop_pos = np.full(n, np.nan)
    t_hist = np.arange(K) * Ts
    H = {k: np.zeros((n, K)) for k in ("v", "s", "u", "target")}
    for k in range(K):
        t = k * Ts
        y_next = np.broadcast_to(target(np.array(t + Ts)), (n,))
        u = np.where(stopped, 0.0, control(k, v.copy(), y_next))
        H["v"][:, k], H["s"][:, k], H["u"][:, k] = v, s, u
        H["target"][:, k] = target(np.array(t))
        demand = static_map(np.clip(u, p["u_min"], p["u_max"]), p["f"], p["e"])
        head = step(n_sub, head, fifo, np.ascontiguousarray(demand, float), v, s, a, work,
                    stopped, stop_time, stop_pos, t, dt, brake_start, first_order, p["decay"],
                    p["gain_int"], p["lo"], p["hi"], p["c0"], p["c1"], p["c2"], edges,
                    p["grade_acc"])
        if stopped.all():
            K = k + 1
            break
    v_hist = H["v"][:, :K]
    acc = np.diff(np.concatenate([v_hist, v[:, None]], axis=1), axis=1) / Ts
    return TrackingRun(t_hist[:K], v_hist, H["s"][:, :K], acc, H["u"][:, :K],
                       H["target"][:, :K], stop_time, stop_pos, work)


def _per_run(trains, n: int, dt: float, first_order: bool, grade) -> dict:
    """Each train's constants of the plant step, one entry per run (block g of
    the batch on train g), computed per train as the one-train loop does."""
    def col(fn):
        return np.repeat(np.array([fn(x) for x in trains], float), n // len(trains), axis=0)
    decay = [math.exp(-dt / x.lag) for x in trains]
    return {"decay": col(lambda x: decay[trains.index(x)]),
            "gain_int": col(lambda x: x.lag * (1.0 - decay[trains.index(x)])),
            "lo": col(lambda x: x.a_min * dt if first_order else -math.inf),
            "hi": col(lambda x: x.a_max * dt if first_order else math.inf),
            "grade_acc": col(lambda x: x.grade(grade)),     # per section (m/s^2)
            **{k: col(lambda x, k=k: getattr(x, k))
               for k in ("c0", "c1", "c2", "f", "e", "u_min", "u_max")}}


def _substeps_numpy(n_sub, head, fifo, demand, v, s, a, work, stopped, stop_time, stop_pos,
                    t, dt, brake_start, first_order, decay, gain_int, lo, hi, c0, c1, c2,
                    edges, grade_acc):
    """The plant steps between two samples on numpy arrays (state updated in
    place; returns the FIFO's new head): the reference of
    :func:`workbench.sim.tracking_jit.substeps`."""
    rows = np.arange(v.size)
    for j in range(n_sub):
        fifo[head] = demand
        head = (head + 1) % fifo.shape[0]
        A = fifo[head]                          # demand of n_delay steps ago
        if first_order:     # exact lag increment of v, within the acceleration limits
            a_int = np.clip((A - v) * (1.0 - decay), lo, hi)
        else:               # exact lag over the step with A held: a(t+dt) and its integral
            a_int = A * dt + (a - A) * gain_int
            a[:] = A + (a - A) * decay
        acc_ext = davis(v, c0, c1, c2) + grade_acc[rows, np.searchsorted(edges, s, side="right")]
        v_new = np.maximum(v + a_int - acc_ext * dt, 0.0)   # no rolling back
        work += np.where(stopped, 0.0, np.maximum(a_int, 0.0) * v)
        s[:] = s + np.where(stopped, 0.0, 0.5 * (v + v_new) * dt)
        v[:] = np.where(stopped, 0.0, v_new)
        t_now = t + (j + 1) * dt
        now_stopped = ~stopped & (v <= 0.0) & (t_now >= brake_start)
        stop_time[:] = np.where(now_stopped, t_now, stop_time)
        stop_pos[:] = np.where(now_stopped, s, stop_pos)
        stopped |= now_stopped
    return head


def _compiled_or_numpy(kernel):
    """The compiled sub-step kernel, or the numpy one when numba is missing
    (``kernel="compiled"`` then raises)."""
    try:
        from .tracking_jit import substeps
    except ImportError:
        if kernel == "compiled":
            raise
        return _substeps_numpy
    return substeps


@dataclass(frozen=True)
class Objectives:
    """The four objectives of the multi-objective tuning (arrays over the batch;
    smaller is better; nan when the train did not stop).

    Paper 002's quality indices (eqs 10-13, formulas lost) are K_s, K_t, K_c,
    K_e; these are the same quantities in absolute units (K_t = punctuality /
    T_o, K_e = energy / S) except comfort, an RMS jerk instead of a mean
    absolute one.

    Attributes
    ----------
    stop_error : numpy.ndarray
        |s_t - S| (m).
    punctuality : numpy.ndarray
        |T_t - T_o| (s).
    comfort : numpy.ndarray
        RMS jerk (m/s^3) up to the stop, jerk(k) = (a(k+1) - a(k)) / Ts with
        a(k) = (v(k+1) - v(k)) / Ts.
    energy : numpy.ndarray
        Integral of max(a_applied, 0) v dt up to the stop (J/kg): positive
        traction power per unit mass.
    rms_speed_error : numpy.ndarray
        sqrt(mean (v - v*)^2) over the planned run time (m/s); shown, not an objective.
    peak_jerk : numpy.ndarray
        Peak |jerk| over 1 s windows up to the stop (m/s^3), |a(k + m) - a(k)| / (m Ts)
        with m Ts = 1 s: the comfort *constraint* of the tuning (issue 33, item 2;
        EN 12299 rates comfort by peak events, the limit is the design's choice).
    """

    stop_error: np.ndarray
    punctuality: np.ndarray
    comfort: np.ndarray
    energy: np.ndarray
    rms_speed_error: np.ndarray
    peak_jerk: np.ndarray

    NAMES = ("stop_error", "punctuality", "comfort", "energy")

    def matrix(self) -> np.ndarray:
        """The four objectives as columns, shape (N, 4)."""
        return np.column_stack([getattr(self, k) for k in self.NAMES])

    def row(self, i: int) -> "Objectives":
        """Batch element ``i`` as a batch of one."""
        return Objectives(*(np.asarray(getattr(self, f))[i:i + 1] for f in
                            (*self.NAMES, "rms_speed_error", "peak_jerk")))


def objectives(run: TrackingRun, distance: float, run_time: float) -> Objectives:
    """The four objectives (and the RMS speed error) of every run of a batch."""
    t_stop = run.stop_time
    dt = run.t[1] - run.t[0] if len(run.t) > 1 else 1.0
    rms_jerk = np.array([np.sqrt(np.mean((np.diff(a[run.t < ts]) / dt) ** 2))
                         if np.isfinite(ts) and np.sum(run.t < ts) > 1 else np.nan
                         for a, ts in zip(run.a, t_stop)])
    m = max(1, int(round(1.0 / dt)))
    peak = np.array([np.max(np.abs(a[m:][run.t[m:] < ts] - a[:-m][run.t[m:] < ts])) / (m * dt)
                     if np.isfinite(ts) and np.sum(run.t[m:] < ts) > 0 else np.nan
                     for a, ts in zip(run.a, t_stop)])
    planned = run.t <= run_time
    rms = np.sqrt(np.mean((run.v[:, planned] - run.target[:, planned]) ** 2, axis=1))
    energy = np.where(np.isfinite(t_stop), run.traction_work, np.nan)
    # a stop on the planned time is 0, not the 1e-14 s rounding of k dt - T: the
    # Pareto dominance of runs tied at 0 must not depend on last bits (issue 36)
    late = np.abs(t_stop - run_time)
    late = np.where(late <= 1e-9 * abs(run_time), 0.0, late)
    return Objectives(np.abs(run.stop_pos - distance), late, rms_jerk, energy, rms, peak)
