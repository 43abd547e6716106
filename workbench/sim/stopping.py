"""Batched fixed-step simulation of the paper-000 brake plant under a policy.

Each call simulates ``n`` runs at once (numpy arrays of shape ``(n,)``): the
repeats of a Monte-Carlo study, the flies of a fitting population, or the
corners of an error grid. The plant is non-stiff (time constants >= 0.3 s),
so explicit Euler at ``dt`` = 0.01 s with exact (linearly interpolated)
transmission delays is adequate; x is advanced with the trapezoid rule.

The policy (a controller, or a logged command profile) is sampled every
``dt_ctrl`` seconds with zero-order hold: ``policy(t, obs) -> command``,
``obs`` an :class:`Observation` of the true state (policies that measure
imperfectly, e.g. through axle sensors, build their own measurement from it).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..plants.brake000 import PARAMETER_UNITS, brake_rhs


@dataclass(frozen=True)
class Observation:
    """What a policy may look at, per run (arrays of shape ``(n,)``).

    Attributes
    ----------
    x, v, a : ndarray
        Position (m), speed (m/s) and acceleration (m/s^2, negative braking).
    stopped : ndarray of bool
        Runs already at standstill (final).
    """

    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    stopped: np.ndarray


@dataclass(frozen=True)
class Traces:
    """Recorded trajectories, shape ``(n_samples, n)``, every ``dt_rec`` s.

    Attributes
    ----------
    t : ndarray, shape (n_samples,)
    x, v, a, c : ndarray
        Position (m), speed (m/s), acceleration (m/s^2), command (m/s^2).
    t_stop, x_stop : ndarray, shape (n,)
        Time (s) and position (m) of the final standstill (nan if none).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    a: np.ndarray
    c: np.ndarray
    t_stop: np.ndarray
    x_stop: np.ndarray


Policy = Callable[[float, Observation], np.ndarray]


def batch_params(base: dict, n: int, overrides: dict | None = None) -> dict:
    """Brake parameters as arrays of shape ``(n,)``: ``base`` broadcast, then
    ``overrides`` (name -> array) applied."""
    out = {k: np.full(n, float(base[k])) for k in PARAMETER_UNITS}
    for k, val in (overrides or {}).items():
        if k not in out:
            raise KeyError(f"{k!r} is not a brake parameter ({', '.join(PARAMETER_UNITS)})")
        out[k] = np.broadcast_to(np.asarray(val, float), (n,)).copy()
    return out


def brake_step(v, b_e, b_a, cap, ce, ca, theta, kappa, params: dict, dt: float, on_air):
    """One explicit-Euler step of the brake stages with the hand-over of eq 8.

    Parameters
    ----------
    v : ndarray
        Speed (m/s) at the start of the step.
    b_e, b_a : ndarray
        Achieved electric and air brake (m/s^2).
    cap : ndarray
        Electric cap (m/s^2): ``inf`` above the hand-over, then falling at
        ``k_bra`` from the electric brake achieved at the hand-over.
    ce, ca : ndarray
        Command as it reaches the electric stage (after T1) and the air stage
        (after T3), m/s^2.
    theta, kappa : ndarray or float
        Gradient (permille) and load-weighing gain.
    params : dict
        Brake parameters (floats or arrays that broadcast).
    dt : float
        Step (s).
    on_air : ndarray of bool
        Runs with an air stage (v_ho > 0).

    Returns
    -------
    dv, b_e, b_a, cap
        Acceleration over the step (m/s^2, from eqs 5, 10) and the stepped
        brake states and cap.
    """
    cap_inf = bool(np.isinf(cap).all())     # lets the cap steps be skipped (same bits)
    return _brake_step(v, b_e, b_a, cap, ce, ca, theta, kappa, params, dt, on_air, cap_inf)[:4]


def standstill(x, v, a, x_new, dt: float):
    """Exact standstill within a step of constant deceleration ``a``: position
    (m; ``x_new`` where the run does not brake) and time into the step (s)."""
    braking = a < 0
    x_hit = np.where(braking, x - v * v / (2 * np.where(braking, a, -1.0)), x_new)
    return x_hit, np.where(braking, v / np.maximum(-a, 1e-12), dt)


#: steps per block of precomputed delay-line indices and weights
_CHUNK = 256


def _uniform(a):
    """``a`` (an array, or a dict of arrays) with every array whose entries are
    bitwise equal replaced by that entry as a Python float."""
    if isinstance(a, dict):
        return {k: _uniform(val) for k, val in a.items()}
    arr = np.asarray(a)
    if arr.ndim == 1 and arr.size and arr.dtype == np.float64:
        bits = arr.view(np.int64)
        if (bits == bits[0]).all():
            return float(arr[0])
    return a


def _delay_plan(d, k0: int, k1: int, pad: int, n: int):
    """Linear interpolation of the command history at steps k0 .. k1-1 for
    delays of ``d`` steps (shape (2, n)): weights (1 - w, w) and flat indices
    of the two history rows, each of shape (k1 - k0, 2, n); the arithmetic
    of ``k + pad - d`` per step, done for a block at once."""
    kp = np.arange(k0 + pad, k1 + pad)[:, None, None]
    idx = kp - d
    i0 = np.floor(idx).astype(int)
    w = idx - i0
    lo = i0 * n + np.arange(n)
    if d.min() >= 1.0:    # then idx <= kp - 1 (rounding is monotonic): row i0 + 1 is written
        return 1 - w, lo, w, lo + n
    return 1 - w, lo, w, lo + (np.minimum(i0 + 1, kp) - i0) * n


def _brake_step(v, b_e, b_a, cap, ce, ca, theta, kappa, params, dt, on_air, cap_inf=False):
    """:func:`brake_step` for :func:`simulate`: ``on_air`` may be ``True``
    (every run has an air stage) and parameters Python floats (:func:`_uniform`);
    the same operations in the same order. ``cap_inf``: every cap is still
    infinite; then, while no run fades, the cap steps are skipped (they leave
    it infinite, ``min(c, inf)`` is ``c``). Returns also the new ``cap_inf``."""
    fading = on_air & (v < params["v_ho"])
    if cap_inf and not fading.any():
        e_in, air_in = ce, np.maximum(ca - ca, 0.0)
    else:
        fading &= np.isinf(cap)
        cap = np.where(fading, np.maximum(b_e, 0.0), cap)
        cap = np.where(np.isinf(cap), cap, np.maximum(cap - params["k_bra"] * dt, 0.0))
        e_in = np.minimum(ce, cap)
        air_in = np.maximum(ca - np.minimum(ca, cap), 0.0)
        cap_inf = False
    if on_air is not True:
        air_in = np.where(on_air, air_in, 0.0)
    dv, dbe, dba = brake_rhs(v, b_e, b_a, e_in, air_in, theta, kappa, params)
    return dv, b_e + dt * dbe, b_a + dt * dba, cap, cap_inf


def _compact_views(per_run: dict):
    """Brake parameters, theta, kappa and the air-stage flag of the stepped runs
    for :func:`_brake_step` (bitwise equal values as Python floats: the same
    IEEE operations, fewer on arrays)."""
    pe = _uniform({k: per_run[k] for k in PARAMETER_UNITS})
    on_air = per_run["on_air"]
    return pe, _uniform(per_run["theta"]), _uniform(per_run["kappa"]), bool(on_air.all()) or on_air


def _spread(done: dict, act, x, v, a, stopped):
    """Full-batch x, v, a, stopped from the stepped runs ``act`` and the final
    values of the others (at standstill: v = a = 0)."""
    n = len(done["x"])
    out = [done["x"].copy(), done["v"].copy(), np.zeros(n), np.ones(n, bool)]
    for full, val in zip(out, (x, v, a, stopped)):
        full[act] = val
    return tuple(out)


def simulate(params: dict, policy: Policy, *, n: int, t_end: float, dt: float = 0.01,
             dt_ctrl: float = 0.1, dt_rec: float = 0.1, v0=0.0, x0=0.0,
             theta=0.0, kappa=1.0, c_init=0.0, t_arm: float = 0.0,
             c_min: float = -np.inf, c_max: float = np.inf) -> Traces:
    """Simulate ``n`` runs of the brake plant driven by ``policy``.

    Parameters
    ----------
    params : dict
        Brake parameters (see :func:`batch_params`), arrays of shape (n,).
    policy : callable
        ``policy(t, obs) -> command`` (m/s^2, shape (n,)), called every ``dt_ctrl``.
    n : int
        Number of runs.
    t_end : float
        Simulated time limit (s).
    dt, dt_ctrl, dt_rec : float
        Integration step, control period, recording period (s); ``dt_ctrl``
        and ``dt_rec`` are rounded to multiples of ``dt``.
    v0, x0 : float or ndarray
        Initial speed (m/s) and position (m); the brake states start at the
        steady value of ``c_init`` (command before t = 0, m/s^2).
    theta, kappa : float or ndarray
        Gradient (permille, + uphill) and load-weighing gain (-).
    t_arm : float
        A run ends at its first standstill after ``t_arm`` (s): the holding
        brake is applied there.
    c_min, c_max : float
        Command limits (m/s^2).
    """
    shape = (n,)
    f = lambda z: np.broadcast_to(np.asarray(z, float), shape).copy()
    x, v = f(x0), f(v0)
    theta, kappa, c_init = f(theta), f(kappa), f(c_init)
    steps = int(round(t_end / dt))
    k_ctrl = max(1, int(round(dt_ctrl / dt)))
    k_rec = max(1, int(round(dt_rec / dt)))
    d13 = np.stack([params["T1"] / dt, params["T3"] / dt])
    pad = int(np.ceil(d13.max())) + 2
    hist = np.empty((steps + pad + 1, n))
    hist[:pad + 1] = c_init
    cap = np.full(shape, np.inf)
    on_air = params["v_ho"] > 0
    b_e = np.where(v > params["v_ho"], c_init, 0.0)
    b_a = np.zeros(shape)
    a = np.zeros(shape)
    stopped = np.zeros(shape, bool)
    t_stop, x_stop = np.full(shape, np.nan), np.full(shape, np.nan)
    rec_t, rec = [], {k: [] for k in "xvac"}
    c = c_init.copy()
    # Runs at standstill since an earlier step are final (x = x_stop, v = a = 0): once they
    # are a quarter of the batch they are dropped from the stepped arrays (``act``: the
    # runs still stepped; ``done``: the final values of all runs, read where not in ``act``).
    # Every operation is elementwise, so each run's numbers do not depend on the others.
    act, done = np.arange(n), None
    per_run = dict(params, theta=theta, kappa=kappa, on_air=on_air, delay1=d13[0], delay3=d13[1])
    pe, th, kap, air = _compact_views(per_run)
    plan, flat = None, hist.reshape(-1)   # a view: rows written into hist show here
    cap_inf, any_stopped = True, False
    for k in range(steps + 1):
        t = k * dt
        if k % k_ctrl == 0 or k % k_rec == 0:
            full = (x, v, a, stopped) if done is None else _spread(done, act, x, v, a, stopped)
        if k % k_ctrl == 0:
            c = np.clip(np.asarray(policy(t, Observation(*full)), float), c_min, c_max)
            c = np.where(full[3], 0.0, c)
        hist[k + pad] = c if done is None else c[act]
        if k % k_rec == 0:
            rec_t.append(t)
            for key, val in zip("xvac", (*full[:3], c)):
                rec[key].append(val.copy())
        if k == steps or stopped.all():
            break
        if plan is None or k >= plan[0] + len(plan[1]):
            plan = (k, *_delay_plan(np.stack([per_run["delay1"], per_run["delay3"]]), k,
                                    min(k + _CHUNK, steps), pad, len(act)))
        j = k - plan[0]
        ce, ca = plan[1][j] * flat[plan[2][j]] + plan[3][j] * flat[plan[4][j]]
        dv, b_e, b_a, cap, cap_inf = _brake_step(v, b_e, b_a, cap, ce, ca, th, kap, pe, dt, air,
                                                 cap_inf)
        # (while no run is at standstill the masks below select nothing: skipped)
        a = np.where(stopped, 0.0, dv) if any_stopped else dv
        v_new = np.maximum(v + dt * a, 0.0)
        x_new = x + 0.5 * (v + v_new) * dt
        hit = v_new <= 0.0
        if any_stopped:
            hit &= ~stopped
        if not t + dt > t_arm:
            hit[:] = False
        final = stopped
        struck = hit.any()
        if struck:
            x_hit, t_hit = standstill(x, v, a, x_new, dt)
            x_new = np.where(hit, x_hit, x_new)
            t_stop = np.where(hit, t + t_hit, t_stop)
            x_stop = np.where(hit, x_new, x_stop)
            stopped = stopped | hit
            any_stopped = True
        if any_stopped:
            x = np.where(stopped, x_stop, x_new)
            v = np.where(stopped, 0.0, v_new)
        else:
            x, v = x_new, v_new
        if struck and 4 * np.count_nonzero(final) >= len(act) and not stopped.all():
            if done is None:
                done = {"x": x.copy(), "v": v.copy(), "t_stop": t_stop.copy(),
                        "x_stop": x_stop.copy()}
            gone, keep = act[final], ~final
            for key, val in (("x", x), ("v", v), ("t_stop", t_stop), ("x_stop", x_stop)):
                done[key][gone] = val[final]
            act = act[keep]
            x, v, a, stopped, t_stop, x_stop, b_e, b_a, cap = (
                z[keep] for z in (x, v, a, stopped, t_stop, x_stop, b_e, b_a, cap))
            per_run = {key: val[keep] for key, val in per_run.items()}
            pe, th, kap, air = _compact_views(per_run)
            rows = hist[k + 1:k + pad + 1, keep]
            hist = np.empty((steps + pad + 1, len(act)))
            hist[k + 1:k + pad + 1] = rows       # the rows the delay line still reads
            plan, flat = None, hist.reshape(-1)
            any_stopped = bool(stopped.any())
    if done is not None:
        done["t_stop"][act], done["x_stop"][act] = t_stop, x_stop
        t_stop, x_stop = done["t_stop"], done["x_stop"]
    return Traces(np.array(rec_t), *(np.array(rec[k]) for k in "xvac"), t_stop, x_stop)


@dataclass(frozen=True)
class TargetCurve:
    """Trapezoidal ATO target: accelerate at ``a_acc``, cruise at ``v_top``,
    brake at ``a_dec`` to stop exactly at ``length`` (arrays of shape (n,)).

    ``v_top`` is lowered where the section is too short to reach ``v_max``.
    """

    length: np.ndarray
    v_top: np.ndarray
    a_acc: float
    a_dec: float

    @classmethod
    def build(cls, length, *, v_max: float, a_acc: float, a_dec: float) -> "TargetCurve":
        length = np.asarray(length, float)
        v_reach = np.sqrt(length / (1 / (2 * a_acc) + 1 / (2 * a_dec)))
        return cls(length, np.minimum(v_max, v_reach), a_acc, a_dec)

    @property
    def t_brake(self) -> np.ndarray:
        """Time the target starts braking (s)."""
        v = self.v_top
        cruise = self.length - v**2 / (2 * self.a_acc) - v**2 / (2 * self.a_dec)
        return v / self.a_acc + cruise / v

    @property
    def t_final(self) -> np.ndarray:
        """Planned run time (s)."""
        return self.t_brake + self.v_top / self.a_dec

    def at(self, t: float):
        """Target position (m), speed (m/s) and acceleration (m/s^2) at time t."""
        v, t1, tb, tf = self.v_top, self.v_top / self.a_acc, self.t_brake, self.t_final
        acc = t < t1
        brk = (t >= tb) & (t < tf)
        done = t >= tf
        x_acc = 0.5 * self.a_acc * np.asarray(t) ** 2
        x_cru = v**2 / (2 * self.a_acc) + v * (t - t1)
        tr = np.maximum(tf - t, 0.0)
        x_brk = self.length - 0.5 * self.a_dec * tr**2
        x = np.where(acc, x_acc, np.where(brk | done, x_brk, x_cru))
        vd = np.where(acc, self.a_acc * t, np.where(brk | done, self.a_dec * tr, v))
        ad = np.where(acc, self.a_acc, np.where(brk, -self.a_dec, 0.0))
        return x, vd, ad
