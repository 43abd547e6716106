"""Simulation of the ``station-stopping`` study: every controller variant of
:data:`~workbench.papers.p000.station_stopping.VARIANTS` over the per-section repeats,
the nominal plant and the Monte Carlo, batched into one simulation of the
paper-000 brake plant (:func:`workbench.sim.stopping.simulate`).

Runs are independent (every operation is elementwise over runs), so the
batching changes no result; ``batch="per-section"`` runs the repeats one
section at a time (the benchmark's baseline).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...controllers.pid import PID
from ...controllers.smarc import AdaptiveSlidingModeController
from ...controllers.smc import SlidingModeController
from ...controllers.stop_predictor import NominalBrakeModel
from ...features.montecarlo import StopStatistics, draw, stop_statistics
from ...kinds.stop_accuracy.pipeline import apply_factors
from ...sim.stopping import TargetCurve, batch_params, simulate
from ...tuning.pid import Damping, damping, speed_loop
from .station_stopping_spec import (ABLATION, CONTROLLERS, DAMPING, FACTORS, MC_CONTROLLERS,
                                    MC_FACTORS, NOMINAL, UNCERTAIN, VARIANTS, Section, StopSpec)

#: Speed errors below this (m/s; 0.18 km/h, below a speedometer's resolution) do not
#: count as a sign change (oscillation count).
SIGN_DEADBAND = 0.05


@dataclass(frozen=True)
class CellStats:
    """Stop statistics of one controller on one section (cm, cm^2, m/s^3, s)."""

    mean_abs: float
    mean: float
    var: float
    max_abs: float
    jerk_mean: float
    jerk_max: float
    run_time: float
    command_rate: float     # mean |dc/dt| of the brake command while moving (m/s^3)
    errors: tuple[float, ...]


@dataclass(frozen=True)
class NominalRun:
    """One stop on the nominal plant (no uncertainty).

    Attributes
    ----------
    error : float
        Stop error (m, + = overshoot).
    t, dx, v, v_d, c : ndarray
        Time from the braking start (s), position - stopping point (m),
        speed and target speed (m/s), brake command (m/s^2).
    sign_changes : int
        Sign changes of the speed error v - v_d while tracking (before the
        last 20 % of the planned braking time), errors below
        :data:`SIGN_DEADBAND` ignored: the oscillation count.
    """

    error: float
    t: np.ndarray
    dx: np.ndarray
    v: np.ndarray
    v_d: np.ndarray
    c: np.ndarray
    sign_changes: int


@dataclass(frozen=True)
class StopResult:
    sections: tuple[Section, ...]
    planned_time: tuple[float, ...]       # braking phase, s
    stats: dict                           # (controller, section index) -> CellStats
    example: dict                         # controller -> (t, x - x_stop, v, v_d) of one run
    theta_hat_final: tuple[float, float]  # SMARC estimate range at the end
    nominal: dict = None                  # variant -> NominalRun
    mc: dict = None                       # variant -> StopStatistics (m)
    damping: dict = None                  # PID variant -> Damping of its linearised loop
    tolerance: float = 0.3                # m

    def overall(self, ctl: str) -> float:
        """Mean over sections of the per-section mean |stop error| (cm)."""
        return float(np.mean([self.stats[ctl, i].mean_abs for i in range(len(self.sections))]))


def draw_plants(spec: StopSpec, n_sections: int) -> dict:
    """Uncertain factors per (section, repeat), seeded per section."""
    seqs = np.random.SeedSequence(spec.seed).spawn(n_sections)
    out = {k: np.empty((n_sections, spec.repeats)) for k in UNCERTAIN}
    for i, sq in enumerate(seqs):
        rng = np.random.default_rng(sq)
        for k in UNCERTAIN:
            out[k][i] = rng.uniform(*spec.ranges[k], spec.repeats)
    return out


def _runset(variants, kind, section, repeat, length, factors) -> dict:
    n = len(variants)
    full = {k: np.broadcast_to(np.asarray(factors.get(k, v), float), (n,)).copy()
            for k, v in NOMINAL.items()}
    return {"variant": np.asarray(variants, object), "kind": np.full(n, kind, object),
            "section": np.asarray(section, int), "repeat": np.asarray(repeat, int),
            "length": np.asarray(length, float), "factors": full}


def _concat(*sets) -> dict:
    out = {k: np.concatenate([s[k] for s in sets]) for k in sets[0] if k != "factors"}
    out["factors"] = {k: np.concatenate([s["factors"][k] for s in sets]) for k in NOMINAL}
    return out


def _repeat_runs(spec: StopSpec, draws: dict, secs: list[int]) -> dict:
    R, nc = spec.repeats, len(CONTROLLERS)
    ci = np.repeat(np.arange(nc), len(secs) * R)
    si = np.tile(np.repeat(secs, R), nc)
    ri = np.tile(np.arange(R), nc * len(secs))
    return _runset([CONTROLLERS[c] for c in ci], "rep", si, ri,
                   [spec.sections[i].length for i in si], {k: v[si, ri] for k, v in draws.items()})


def _extra_runs(spec: StopSpec) -> dict:
    """Nominal runs (every Monte Carlo controller and the ablation) and the
    Monte Carlo, on the braking phase of section 1 (every section reaches
    v_max before braking, so the braking phases are the same)."""
    L = spec.sections[0].length
    nom = list(MC_CONTROLLERS + ABLATION)
    sets = [_runset(nom, "nom", [0] * len(nom), [0] * len(nom), [L] * len(nom), {})]
    mc = spec.montecarlo
    d = draw(mc, tuple(MC_FACTORS), NOMINAL)
    N = mc.samples
    for name in MC_CONTROLLERS:
        sets.append(_runset([name] * N, "mc", [0] * N, np.arange(N), [L] * N, d))
    return _concat(*sets)


def simulate_runs(spec: StopSpec, rs: dict):
    """Simulate the run set ``rs``: (traces, SMARC estimates of the repeats,
    target curves, braking start times)."""
    n = len(rs["variant"])
    f = rs["factors"]
    var = [VARIANTS[v] for v in rs["variant"]]
    law = np.array([v.law for v in var], object)
    base = {k: q.value for k, q in spec.params.items()}
    over, theta, kappa = apply_factors(base, FACTORS, f, n)
    p = batch_params(base, n, over)
    lengths = rs["length"]
    tc = TargetCurve.build(lengths, v_max=spec.v_max.value, a_acc=spec.a_acc.value,
                           a_dec=spec.a_dec.value)
    tb = tc.t_brake
    x0, v0, _ = tc.at(tb)
    idx = {k: np.flatnonzero(law == k) for k in ("pid", "smc", "smarc", "smarc-sgn")}
    smc = SlidingModeController(spec.sliding)
    smarc = AdaptiveSlidingModeController(spec.sliding, dt=spec.dt_ctrl,
                                          theta0=np.ones(idx["smarc"].size), **spec.smarc)
    smarc_sgn = AdaptiveSlidingModeController(replace(spec.sliding, phi=0.0), dt=spec.dt_ctrl,
                                              theta0=np.ones(idx["smarc-sgn"].size), **spec.smarc)
    pids = [PID(**spec.gains(var[j].gains), dt=spec.dt_ctrl) for j in idx["pid"]]
    pred = np.array([v.predictor for v in var])
    term = np.array([v.terminal for v in var])
    M = np.flatnonzero(pred | term)                         # runs with the nominal model
    pm, tm = np.flatnonzero(pred[M]), term[M]
    comp = spec.compensation
    tau = np.array([comp.gain_tau if var[j].gain_correction else 0.0 for j in M])
    model = NominalBrakeModel(base, M.size, dt_ctrl=spec.dt_ctrl, gain_tau=tau,
                              gain_bounds=comp.gain_bounds)
    st = {"in_term": np.zeros(M.size, bool), "last": np.zeros(M.size)}

    def policy(t, obs):
        xp, vp, h = obs.x.copy(), obs.v.copy(), np.zeros(n)
        if M.size:
            model.update(obs.v[M], obs.a[M])
            if pm.size:
                mx, mv, mh = model.predict(obs.x[M], obs.v[M])
                xp[M[pm]], vp[M[pm]], h[M[pm]] = mx[pm], mv[pm], mh[pm]
        xd, vd, ad = tc.at(t + tb + h)
        e, de = xp - xd, vp - vd
        c = np.zeros(n)
        for k, ctl in (("smc", smc), ("smarc", smarc), ("smarc-sgn", smarc_sgn)):
            j = idx[k]
            if j.size:
                c[j] = -ctl.step(e[j], de[j], ad[j])
        j = idx["pid"]
        c[j] = -ad[j] + np.array([pid.step(err) for pid, err in zip(pids, de[j])])
        c = np.clip(c, spec.c_min, spec.c_max)
        if M.size:
            st["in_term"] |= tm & (lengths[M] - obs.x[M] < comp.d_terminal)
            rows = np.flatnonzero(st["in_term"] & ~obs.stopped[M])
            if rows.size:
                guess = np.where(st["last"][rows] > 0, st["last"][rows], c[M[rows]])
                c[M[rows]] = model.stopping_command(obs.x[M], obs.v[M], lengths[M], rows, guess,
                                                    c_lo=0.0, c_hi=spec.c_max)
            c = np.where(obs.stopped, 0.0, c)
            st["last"] = np.where(st["in_term"], c[M], 0.0)
            model.sent(c[M])
        return c

    t_end = float((tc.t_final - tb).max()) + 30.0
    tr = simulate(p, policy, n=n, t_end=t_end, dt=spec.dt, dt_ctrl=spec.dt_ctrl,
                  dt_rec=spec.dt_ctrl, x0=x0, v0=v0, theta=theta,
                  kappa=kappa, c_init=0.0, t_arm=0.0, c_min=spec.c_min,
                  c_max=spec.c_max)
    rep_smarc = (rs["kind"][idx["smarc"]] == "rep") & (rs["variant"][idx["smarc"]] == "smarc")
    return tr, smarc.theta_hat[rep_smarc], tc, tb


def run_station_stops(spec: StopSpec, *, batch: str = "all", extras: bool = True) -> StopResult:
    """Simulate every controller variant: per-section repeats, and (``extras``)
    the nominal runs and the Monte Carlo.

    Parameters
    ----------
    batch : {"all", "per-section"}
        One batched simulation of all runs, or the repeats one section at a
        time (the benchmark's baseline); results are identical.
    extras : bool
        Also the nominal runs and the Monte Carlo.
    """
    ns = len(spec.sections)
    draws = draw_plants(spec, ns)
    extra = [_extra_runs(spec)] if extras else []
    if batch == "all":
        sets = [_concat(_repeat_runs(spec, draws, list(range(ns))), *extra)]
    else:
        sets = [_repeat_runs(spec, draws, [i]) for i in range(ns)] + extra
    return _collect(spec, [(rs, *simulate_runs(spec, rs)) for rs in sets])


def loop_dead_time(spec: StopSpec, name: str) -> float:
    """Dead time (s) of the linearised speed loop of PID variant ``name``: the
    electric stage's T1 plus half a control period (sample and hold), or
    behind the Smith predictor (nominal model exact) the half period only."""
    hold = spec.dt_ctrl / 2
    return hold if VARIANTS[name].predictor else spec.params["T1"].value + hold


def _sign_changes(err: np.ndarray) -> int:
    s = np.sign(np.where(np.abs(err) < SIGN_DEADBAND, 0.0, err))
    s = s[s != 0]
    return int(np.sum(s[1:] != s[:-1]))


def _collect(spec: StopSpec, blocks) -> StopResult:
    stats, example, planned, th, nominal, mc = {}, {}, {}, [], {}, {}
    for rs, tr, theta_hat, tc, tb in blocks:
        err = tr.x_stop - rs["length"]
        th.extend(theta_hat.tolist())
        rep = rs["kind"] == "rep"
        if rep.any():
            _repeat_stats(spec, rs, tr, tc, tb, err, stats, example, planned)
        for k in np.flatnonzero(rs["kind"] == "nom"):
            t_plan = float(tc.t_final[k] - tb[k])
            one = TargetCurve.build(rs["length"][k:k + 1], v_max=spec.v_max.value,
                                    a_acc=spec.a_acc.value, a_dec=spec.a_dec.value)
            vd = one.at(tr.t + tb[k])[1]
            track = tr.t < 0.8 * t_plan
            nominal[rs["variant"][k]] = NominalRun(
                float(err[k]), tr.t, tr.x[:, k] - rs["length"][k], tr.v[:, k], vd, tr.c[:, k],
                _sign_changes((tr.v[:, k] - vd)[track]))
        for name in MC_CONTROLLERS:
            m = (rs["kind"] == "mc") & (rs["variant"] == name)
            if m.any():
                mc[name] = stop_statistics(err[m], spec.tolerance.value)
    plant = {k: q.value for k, q in spec.params.items()}
    damp = {name: damping(*speed_loop(**spec.gains(VARIANTS[name].gains), P1=plant["P1"],
                                      T2=plant["T2"]), loop_dead_time(spec, name))
            for name in DAMPING}
    return StopResult(spec.sections, tuple(planned[i] for i in range(len(spec.sections))),
                      stats, example, (float(np.min(th)), float(np.max(th))), nominal, mc, damp,
                      spec.tolerance.value)


def _repeat_stats(spec, rs, tr, tc, tb, err, stats, example, planned) -> None:
    err_cm = err * 100.0
    jerk = np.abs(np.diff(tr.a, axis=0)) / spec.dt_ctrl
    crate = np.abs(np.diff(tr.c, axis=0)) / spec.dt_ctrl
    moving = tr.t[1:, None] <= tr.t_stop[None, :]
    rep = rs["kind"] == "rep"
    t_plan = tc.t_final - tb
    for s in np.unique(rs["section"][rep]):
        planned[int(s)] = float(t_plan[rep & (rs["section"] == s)][0])
        for name in CONTROLLERS:
            m = rep & (rs["variant"] == name) & (rs["section"] == s)
            e = err_cm[m]
            jm = np.where(moving[:, m], jerk[:, m], np.nan)
            stats[name, int(s)] = CellStats(
                float(np.mean(np.abs(e))), float(np.mean(e)), float(np.var(e, ddof=1)),
                float(np.max(np.abs(e))), float(np.nanmean(jm)), float(np.nanmax(jm)),
                float(np.mean(tr.t_stop[m])),
                float(np.nanmean(np.where(moving[:, m], crate[:, m], np.nan))),
                tuple(float(x) for x in e))
            if int(s) == 0:
                j = int(np.flatnonzero(m)[0])
                one = TargetCurve.build(rs["length"][j:j + 1], v_max=spec.v_max.value,
                                        a_acc=spec.a_acc.value, a_dec=spec.a_dec.value)
                xd, vd, _ = one.at(tr.t + tb[j])
                example[name] = (tr.t, tr.x[:, j] - rs["length"][j], tr.v[:, j],
                                 xd - rs["length"][j], vd)


__all__ = ["CellStats", "NominalRun", "StopResult", "draw_plants", "loop_dead_time",
           "run_station_stops", "simulate_runs"]
