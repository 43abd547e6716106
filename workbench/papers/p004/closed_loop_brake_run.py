"""Simulation of the ``closed-loop-brake`` study (paper 004): the ATO, the
command generator with its axle-speed measurement, and the three brake modes,
batched over runs on the paper-000 brake plant.

:func:`simulate_brake` runs any set of cases (the error grid, the sensor
faults, the Monte Carlo); :func:`run_montecarlo` draws the Monte Carlo of
the ``[montecarlo]`` table for the ATO open loop and the closed loop.
"""
from __future__ import annotations

import numpy as np

from ...controllers.pid import PID
from ...features.montecarlo import draw
from ...kinds.stop_accuracy.pipeline import Factor, apply_factors, group_statistics
from ...sim.stopping import batch_params, simulate

MODES = ("open", "ato-open", "closed")
#: not a control mode: full service from t = 0, to test each corner's feasibility
FULL = "full-service"
CHANNELS = ("analogue", "3bit")
#: axle-sensor cases at the nominal corner: name -> states of the 4 axles:
#: o healthy, s sliding (reads low), f failed (reads 0), h reads high (calibration),
#: z stuck at its reading when braking starts
FAULTS = {"healthy": "oooo", "1 sliding": "sooo", "3 failed": "fffo",
          "2 sliding + 1 failed": "ssfo", "all 4 failed": "ffff", "all 4 sliding": "ssss",
          "1 reading high": "hooo", "1 stuck": "zooo"}
#: states the command generator detects (falls back to the ATO open loop when all 4 are)
DETECTED = ("s", "f")
#: Monte Carlo factors in draw order (a factor's stream is its position), and how each
#: acts on the plant (the stop-accuracy pipeline, :mod:`workbench.kinds.stop_accuracy.pipeline`)
MC_FACTORS = {f.name: f for f in (
    Factor("delay", "scale", ("T1", "T3"), "factor on the transmission delays T1, T3"),
    Factor("force_error", "force_error", (),
           "brake-force error (load weighing, force computation): kappa - 1"),
    Factor("friction", "scale", ("K1",), "factor on K1 (air-brake friction)"),
    Factor("gradient", "gradient", (), "station gradient (‰, + uphill)", "permille"))}
#: modes of the Monte Carlo
MC_MODES = ("ato-open", "closed")


def axle_speeds(states: np.ndarray, v: np.ndarray, v_first: np.ndarray, spec) -> np.ndarray:
    """Speeds (m/s) read by the 4 axle sensors, shape (n, 4), from the train
    speed ``v`` and the speed ``v_first`` when braking started."""
    return _axle_speeds(_state_masks(states), v, v_first, spec)


def _state_masks(states: np.ndarray) -> list:
    """Masks of the axle states read by :func:`_axle_speeds` (states are fixed per run)."""
    return [states == "o", states == "s", states == "h", states == "z"]


def _axle_speeds(masks: list, v: np.ndarray, v_first: np.ndarray, spec) -> np.ndarray:
    col = v[:, None]
    return np.select(masks, [col, col * (1 - spec.slide), col * spec.high_ratio,
                             np.broadcast_to(v_first[:, None], masks[0].shape)], 0.0)


class _ClosedPID:
    """One :class:`~workbench.controllers.pid.PID` per closed-loop run, stepped
    together: the arithmetic of ``PID.step`` (no output limits) elementwise,
    a run's loop reset or stepped only where the masks say so."""

    def __init__(self, gains: dict, dt: float, closed: np.ndarray):
        ref = PID(**gains, dt=dt)     # validates; its limits are infinite (never saturates)
        self.kp, self.ki, self.kd, self.dt = ref.kp, ref.ki, ref.kd, dt
        self.closed = closed
        n = len(closed)
        self.integral, self.prev, self.has_prev = np.zeros(n), np.zeros(n), np.zeros(n, bool)

    def reset(self, where: np.ndarray) -> None:
        m = where & self.closed
        self.integral = np.where(m, 0.0, self.integral)
        self.has_prev &= ~m

    def step(self, where: np.ndarray, e: np.ndarray, base: np.ndarray) -> np.ndarray:
        """``base`` plus the PID output where ``where`` (closed runs only), else ``base``."""
        m = where & self.closed
        deriv = np.where(self.has_prev, (e - self.prev) / self.dt, 0.0)
        u = self.kp * e + self.ki * (self.integral + e * self.dt) + self.kd * deriv
        self.prev = np.where(m, e, self.prev)
        self.has_prev |= m
        self.integral = np.where(m, self.integral + e * self.dt, self.integral)
        return np.where(m, base + u, base)


def simulate_brake(spec, *, v0, dist, mode, bits, states, overrides: dict, theta, kappa,
                   t_predict=None, debug: dict | None = None):
    """Brake ``n`` runs to their stopping points ``dist`` (m).

    Parameters
    ----------
    spec : Spec004
    v0, dist : ndarray
        Initial speed (m/s) and stopping point (m) per run.
    mode : ndarray of int
        Index into ``MODES + (FULL,)``.
    bits : ndarray of bool
        3-bit command channel.
    states : ndarray, shape (n, 4)
        Axle-sensor states (:data:`FAULTS`).
    overrides : dict
        Brake parameters per run (:func:`workbench.sim.stopping.batch_params`).
    theta, kappa : ndarray
        Gradient (permille) and load-weighing gain per run.
    t_predict : ndarray, optional
        The ATO's prediction horizon (s) per run (default: the design's).
    """
    n = len(v0)
    p = batch_params({k: q.value for k, q in spec.params.items()}, n, overrides)
    fallback = np.all(np.isin(states, DETECTED), axis=1)
    closed = (mode == 2) & ~fallback
    masks = _state_masks(states)
    pid = _ClosedPID(spec.pid, spec.dt_ctrl, closed)
    st = {"c": np.zeros(n), "a_f": np.zeros(n), "v_prev": None, "e_prev": np.zeros(n),
          "anchor": np.zeros(n), "in_pid": np.zeros(n, bool), "v_first": None}

    def policy(t, o):
        a_now = np.maximum(-o.a, 0.0)
        tp = spec.t_predict if t_predict is None else t_predict   # the ATO's horizon (s)
        v_p = np.maximum(o.v - a_now * tp, 0.0)
        d_go = dist - o.x - 0.5 * (o.v + v_p) * tp
        a_req = np.where(d_go > 0, v_p**2 / (2 * np.maximum(d_go, spec.d_min)), spec.c_full)
        if st["v_first"] is None:
            st["v_first"] = o.v.copy()
        v_m = _axle_speeds(masks, o.v, st["v_first"], spec).max(axis=1)
        if st["v_prev"] is None:
            st["v_prev"] = v_m.copy()
        raw = (st["v_prev"] - v_m) / spec.dt_ctrl
        st["v_prev"] = v_m
        k = spec.dt_ctrl / (spec.tau_filter + spec.dt_ctrl)
        st["a_f"] = st["a_f"] + k * (raw - st["a_f"])
        e = a_req - st["a_f"]
        de = (e - st["e_prev"]) / spec.dt_ctrl
        st["e_prev"] = e
        # closed loop: command = a_req (feed-forward) + correction; the correction is
        # integrated by the fuzzy increments, or set by PID around its value at the switch
        corr = st["c"]
        small = np.abs(e) <= spec.e_switch
        enter = small & ~st["in_pid"]
        st["anchor"] = np.where(enter, corr, st["anchor"])
        pid.reset(enter)
        fz = corr + spec.fuzzy.increment(e, de)
        pid_out = pid.step(small, e, st["anchor"])
        corr = np.clip(np.where(small, pid_out, fz), -spec.c_full, spec.c_full)
        st["in_pid"] = small
        st["c"] = np.where(closed, corr, 0.0)
        c_closed = a_req + corr
        c_new = np.where(mode == 0, spec.a_target, np.where(closed, c_closed, a_req))
        c_new = np.where(mode == 3, spec.c_full, c_new)
        if debug is not None:
            debug.setdefault("rows", []).append((t, a_req.copy(), st["a_f"].copy(), c_new.copy(),
                                                 d_go.copy(), o.v.copy()))
        c_new = np.clip(c_new, 0.0, spec.c_full)
        q = np.round(c_new / spec.c_full * 7) / 7 * spec.c_full
        return np.where(bits, q, c_new)

    return simulate(p, policy, n=n, t_end=float(2 * (v0 / spec.a_target).max() + 60), dt=spec.dt,
                    dt_ctrl=spec.dt_ctrl, dt_rec=0.5, v0=v0, theta=theta, kappa=kappa,
                    c_min=0.0, c_max=spec.c_full)


def run_montecarlo(spec, distance: dict) -> dict:
    """Stop statistics per (speed km/h, mode) over the Monte Carlo draws
    (analogue channel, healthy sensors; every mode and speed meets the same
    draws): {(speed, mode): StopStatistics}."""
    mc = spec.montecarlo
    d = draw(mc, tuple(MC_FACTORS), {k: f.nominal for k, f in MC_FACTORS.items()})
    N = mc.samples
    cases = [(s, m) for s in spec.speeds_kmh for m in MC_MODES]
    n = N * len(cases)
    over, theta, kappa = apply_factors({k: q.value for k, q in spec.params.items()},
                                       MC_FACTORS.values(),
                                       {k: np.tile(x, len(cases)) for k, x in d.items()}, n)
    dist = np.repeat([distance[s] for s, _ in cases], N)
    tr = simulate_brake(spec, v0=np.repeat([s / 3.6 for s, _ in cases], N), dist=dist,
                        mode=np.repeat([MODES.index(m) for _, m in cases], N),
                        bits=np.zeros(n, bool), states=np.full((n, 4), "o"), overrides=over,
                        theta=theta, kappa=kappa)
    return group_statistics(tr.x_stop - dist, cases, N, spec.tolerance)


def run_horizon_sweep(spec, distance: dict) -> tuple:
    """Stop error (m) of the closed loop (analogue) at the nominal corner for
    each ATO prediction horizon of ``spec.t_predict_sweep``: ((t_predict,
    speed km/h, error), ...)."""
    cases = [(tp, s) for s in spec.speeds_kmh for tp in spec.t_predict_sweep]
    n = len(cases)
    tr = simulate_brake(spec, v0=np.array([s / 3.6 for _, s in cases]),
                        dist=np.array([distance[s] for _, s in cases]),
                        mode=np.full(n, MODES.index("closed")), bits=np.zeros(n, bool),
                        states=np.full((n, 4), "o"), overrides={}, theta=np.zeros(n),
                        kappa=np.ones(n), t_predict=np.array([tp for tp, _ in cases]))
    return tuple((tp, s, float(x - distance[s])) for (tp, s), x in zip(cases, tr.x_stop))


__all__ = ["CHANNELS", "FAULTS", "FULL", "MC_FACTORS", "MC_MODES", "MODES", "axle_speeds",
           "run_horizon_sweep", "run_montecarlo", "simulate_brake"]
