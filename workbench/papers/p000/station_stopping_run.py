"""Simulation of the ``station-stopping`` study: every controller variant of
:data:`~workbench.papers.p000.station_stopping.VARIANTS` over the per-section repeats,
the nominal plant and the Monte Carlo, batched into one simulation of the
paper-000 brake plant (:func:`workbench.sim.stopping.simulate`).

Runs are independent (every operation is elementwise over runs), so the
batching changes no result; ``batch="per-section"`` runs the repeats one
section at a time (the benchmark's baseline).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...features.montecarlo import StopStatistics, draw, stop_statistics
from ...kinds.stop_accuracy.pipeline import apply_factors
from ...kinds.stop_accuracy.sections import Section, batch_rates, cell_stats, draw_sections
from ...sim.stopping import TargetCurve, batch_params
from ...tuning.pid import Damping, damping, speed_loop
from .station_stopping_spec import (ABLATION, CONTROLLERS, DAMPING, FACTORS, MC_CONTROLLERS,
                                    MC_FACTORS, NOMINAL, UNCERTAIN, VARIANTS, StopSpec)

#: Speed errors below this (m/s; 0.18 km/h, below a speedometer's resolution) do not
#: count as a sign change (oscillation count).
SIGN_DEADBAND = 0.05


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
    """Uncertain factors per (section, repeat), seeded per section (the kind's
    :func:`~workbench.kinds.stop_accuracy.sections.draw_sections`)."""
    return draw_sections(spec.seed, [(k, *spec.ranges[k]) for k in UNCERTAIN], n_sections,
                         spec.repeats)


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


#: The laws as a ``stop-accuracy`` configuration (designs/stop-accuracy-000-line5.toml
#: writes the same): the speed PID with feed-forward and eq 22's SMC are expressions,
#: SMARC, the predictor and the terminal law named modules
#: (:mod:`workbench.kinds.stop_accuracy.modules`).
_PID = ("-a_d", ("v - v_d", "kp_{g}", "ki_{g}", "kd_{g}"))
_SMC = ((("e", "x - x_d"), ("de", "v - v_d"), ("z", "c_s*e + de")),
        "-((a_d - c_s*de) - k_s*z - eta*min(max(z/phi, -1), 1))")


def kind_spec(spec: StopSpec, t_end: float):
    """``spec`` as a ``stop-accuracy`` spec: one controller per variant of
    :data:`VARIANTS` (in order), the ATO curve as its ``[reference]``."""
    from ...kinds.stop_accuracy import Controller, StopAccuracySpec
    from ...kinds.stop_accuracy.modules import Reference, SmarcGains
    from ...reader import Quantity
    g = spec.sliding
    const = {"c_s": g.c, "k_s": g.k_s, "eta": g.eta, "phi": g.phi, "phi_0": 0.0,
             "lam": spec.smarc["lam"], "th_min": spec.smarc["theta_min"],
             "th_max": spec.smarc["theta_max"]}
    for name in ("pid", "pid_damped", "pid_compensated"):
        const |= {f"{k}_{name}": v for k, v in spec.gains(name).items()}
    ctls = []
    for name, v in VARIANTS.items():
        law, defs, pid, smarc = None, (), None, None
        if v.law == "pid":
            law, pid = _PID[0], tuple(x.format(g=v.gains) for x in _PID[1])
        elif v.law == "smc":
            defs, law = _SMC
        else:
            smarc = SmarcGains({"c": "c_s", "k_s": "k_s", "eta": "eta",
                                "phi": "phi_0" if v.law == "smarc-sgn" else "phi", "lam": "lam",
                                "theta_min": "th_min", "theta_max": "th_max"})
        ctls.append(Controller(name.replace("-", "_").replace("+", "_"), law, defs, pid, smarc,
                               v.predictor, v.terminal, v.gain_correction, pid_limited=False))
    return StopAccuracySpec(
        "<station-stopping>", spec.params, (spec.v_max.value * 3.6,), spec.tolerance.value,
        spec.c_max, spec.sections[0].length, None,
        {k: Quantity(x, "1", "") for k, x in const.items()}, tuple(ctls), FACTORS, (),
        spec.dt, spec.dt_ctrl, t_end,
        reference=Reference(spec.v_max.value, spec.a_acc.value, spec.a_dec.value),
        compensation=spec.compensation,
        c_min=spec.c_min)


def simulate_runs(spec: StopSpec, rs: dict):
    """Simulate the run set ``rs`` through the ``stop-accuracy`` kind's runs
    (:func:`workbench.kinds.stop_accuracy.run.simulate_runs`): (traces, SMARC
    estimates of the repeats, target curves, braking start times)."""
    from ...kinds.stop_accuracy.run import compile_laws
    from ...kinds.stop_accuracy.run import simulate_runs as run_batch
    n = len(rs["variant"])
    base = {k: q.value for k, q in spec.params.items()}
    over, theta, kappa = apply_factors(base, FACTORS, rs["factors"], n)
    lengths = rs["length"]
    tc = TargetCurve.build(lengths, v_max=spec.v_max.value, a_acc=spec.a_acc.value,
                           a_dec=spec.a_dec.value)
    tb = tc.t_brake
    x0, v0, _ = tc.at(tb)
    ks = kind_spec(spec, float((tc.t_final - tb).max()) + 30.0)
    ctl = np.array([list(VARIANTS).index(v) for v in rs["variant"]])
    tr, track = run_batch(ks, compile_laws(ks), spec.dt, batch_params(base, n, over), ctl,
                          lengths, x0=x0, v0=v0, ratio=np.ones(n), theta=theta, kappa=kappa)
    rep = rs["kind"][ctl == list(VARIANTS).index("smarc")] == "rep"
    return tr, track.smarc["smarc"].theta_hat[rep], tc, tb


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
    err_cm, rates = err * 100.0, batch_rates(tr, spec.dt_ctrl)
    rep = rs["kind"] == "rep"
    t_plan = tc.t_final - tb
    for s in np.unique(rs["section"][rep]):
        planned[int(s)] = float(t_plan[rep & (rs["section"] == s)][0])
        for name in CONTROLLERS:
            m = rep & (rs["variant"] == name) & (rs["section"] == s)
            stats[name, int(s)] = cell_stats(err_cm, tr, m, rates)
            if int(s) == 0:
                j = int(np.flatnonzero(m)[0])
                one = TargetCurve.build(rs["length"][j:j + 1], v_max=spec.v_max.value,
                                        a_acc=spec.a_acc.value, a_dec=spec.a_dec.value)
                xd, vd, _ = one.at(tr.t + tb[j])
                example[name] = (tr.t, tr.x[:, j] - rs["length"][j], tr.v[:, j],
                                 xd - rs["length"][j], vd)


__all__ = ["NominalRun", "StopResult", "draw_plants", "loop_dead_time",
           "run_station_stops", "simulate_runs"]
