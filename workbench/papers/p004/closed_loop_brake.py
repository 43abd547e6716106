"""Paper 004's deceleration feedback against the open-loop brake, over an
error grid, on the paper-000 brake plant (designs/closed-loop-brake-004.toml):
the ``[analysis]`` module of a ``stop-accuracy`` design.

The design is a configuration of the general kind
(:mod:`workbench.kinds.stop_accuracy`): the modes are its controllers (the
ATO law an expression, the command generator its named module
``deceleration_loop``), the grid its ``[grid]``, the Monte Carlo its
``[montecarlo]``, every run its simulation (:mod:`.closed_loop_brake_run`).
What stays here is paper 004's: the worked numbers of section 1.3 (sympy
expressions written here once, ``[worked]``), the runs of its report and
their names (``open``, ``ato-open``, ``closed``; channels ``analogue`` and
``3bit``; the axle-sensor cases of section 2.7 and the electric-brake loss at
the nominal corner; the ATO-horizon sweep of ``[retuning]``), the quantities
its claims name and the report's wording. The modes:

``open``
    one brake command a_target, held (the "large open loop" of section 1);
``ato-open``
    the ATO re-commands a_req = v^2 / (2 d_go) every cycle, the brake
    executes it open loop (today's practice, and the fallback of section 2.7);
``closed``
    the ATO's a_req is the *target deceleration* of the command generator,
    which measures the deceleration from the axle speeds (train speed = max
    of 4 axles) and closes the loop: incremental fuzzy control when
    |error| > e_switch, PID otherwise (section 2.5); all four axles failed
    or sliding -> fallback to ``ato-open``.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ...features.quantities import Declared, names, units, values
from ...kinds.stop_accuracy.pipeline import open_loop_distance
from ...kinds.stop_accuracy.quantities import mc_family
from ...kinds.stop_accuracy.run import speed_key
from ...reader import Reader
from ...tuning.pid import Damping, damping, deceleration_loop
from .closed_loop_brake_run import (CHANNELS, CONTROLLERS, FAULTS, FULL, MC_MODES,
                                    run_horizon_sweep, run_montecarlo, simulate_brake)
from .closed_loop_brake_spec import Paper004, Spec004, compute_worked, load, view

__all__ = ["ANALYSIS", "Result004", "Run", "Spec004", "compute_worked", "decel_damping",
           "run_grid", "stopping_point", "TABLE", "view"]


@dataclass(frozen=True)
class Run:
    """One simulated case."""

    speed_kmh: float
    mode: str
    channel: str
    force_error: float
    gradient: float
    friction: float
    fault: str
    electric: bool


@dataclass(frozen=True)
class Result004:
    worked: dict
    distance: dict          # speed -> stopping point D (m)
    runs: tuple             # Run
    errors: tuple           # stop error (m) per run (nan: no stop)
    tolerance: float        # m, platform-door tolerance
    feasible: tuple         # per run: full service can hold a_target on that corner
    curves: tuple = ()      # (Run, position - D (m), speed (m/s)) of the curve corners
    mc: dict | None = None  # (speed km/h, mode) -> StopStatistics of the Monte Carlo
    damping: Damping | None = None   # of the linearised deceleration PID loop
    sweep: tuple = ()       # (ATO horizon s, speed km/h, nominal closed-loop stop error m)
    spec: object = None     # the design's StopAccuracySpec

    def failing(self, **kw) -> list[tuple[Run, float]]:
        """Runs (with errors) outside the tolerance among those selected."""
        return [(r, e) for r, e in self.select(**kw) if not abs(e) <= self.tolerance]

    def select(self, **kw) -> list[tuple[Run, float]]:
        return [(r, e) for r, e in zip(self.runs, self.errors)
                if all(getattr(r, k) == v for k, v in kw.items())]

    def max_abs(self, **kw) -> float:
        errs = [abs(e) for _, e in self.select(**kw)]
        return float(max(errs)) if errs and all(np.isfinite(errs)) else float("nan")


def _cases(spec: Spec004) -> list[Run]:
    runs = []
    for s in spec.speeds_kmh:
        for fe, gr, fr in itertools.product(spec.force_error, spec.gradient, spec.friction):
            runs.append(Run(s, "open", "analogue", fe, gr, fr, "healthy", True))
            runs.append(Run(s, FULL, "analogue", fe, gr, fr, "healthy", True))
            runs.append(Run(s, "ato-open", "analogue", fe, gr, fr, "healthy", True))
            for ch in CHANNELS:
                runs.append(Run(s, "closed", ch, fe, gr, fr, "healthy", True))
        for f in FAULTS:
            if f != "healthy":
                runs.append(Run(s, "closed", "analogue", 0.0, 0.0, 1.0, f, True))
        for mode in ("ato-open", "closed"):
            runs.append(Run(s, mode, "analogue", 0.0, 0.0, 1.0, "healthy", False))
    return runs


def stopping_point(spec: Spec004, v0: float) -> float:
    """Nominal open-loop stopping distance of the single command (m)."""
    return open_loop_distance({k: q.value for k, q in spec.params.items()}, spec.a_target, v0,
                              dt=spec.dt, dt_ctrl=spec.dt_ctrl)


def run_grid(spec: Spec004, *, montecarlo: bool = True) -> Result004:
    """The error grid, the sensor faults, the electric-brake loss; with
    ``montecarlo`` also the Monte Carlo and the horizon sweep."""
    runs = _cases(spec)
    n = len(runs)
    D = {s: stopping_point(spec, s / 3.6) for s in spec.speeds_kmh}
    arr = lambda f: np.array([f(r) for r in runs], float)
    base = {k: q.value for k, q in spec.params.items()}
    dist = arr(lambda r: D[r.speed_kmh])
    tr = simulate_brake(
        spec, v0=arr(lambda r: r.speed_kmh / 3.6), dist=dist,
        controller=np.array([list(CONTROLLERS).index((r.mode, r.channel)) for r in runs]),
        states=np.array([list(FAULTS[r.fault]) for r in runs]),
        overrides={"K1": base["K1"] * arr(lambda r: r.friction),
                   "v_ho": np.where(arr(lambda r: r.electric) > 0, base["v_ho"], 1e3)},
        theta=arr(lambda r: r.gradient), kappa=1 + arr(lambda r: r.force_error))
    err = tr.x_stop - dist
    full = {(r.speed_kmh, r.force_error, r.gradient, r.friction): e
            for r, e in zip(runs, err) if r.mode == FULL}
    feasible = [bool(full.get((r.speed_kmh, r.force_error, r.gradient, r.friction), -1.0)
                     <= -spec.tolerance) for r in runs]
    keep = [k for k, r in enumerate(runs) if r.mode != FULL]
    corners = {(0.0, 0.0, 1.0), (min(spec.force_error), 0.0, 1.0)}
    curves = tuple((r, tr.x[:, k] - dist[k], tr.v[:, k]) for k, r in enumerate(runs)
                   if r.speed_kmh == spec.speeds_kmh[0] and r.fault == "healthy" and r.electric
                   and (r.force_error, r.gradient, r.friction) in corners and r.mode != FULL)
    return Result004(compute_worked(spec.worked), D, tuple(runs[k] for k in keep),
                     tuple(float(err[k]) for k in keep), spec.tolerance,
                     tuple(feasible[k] for k in keep), curves,
                     run_montecarlo(spec, D) if montecarlo else None, decel_damping(spec),
                     run_horizon_sweep(spec, D) if montecarlo else (), spec.kind)


def decel_damping(spec: Spec004) -> Damping:
    """Damping of the linearised deceleration PID loop (electric stage, dead
    time T1 plus one control period: sample and hold, and the backward
    difference of the measured speed)."""
    p = {k: q.value for k, q in spec.params.items()}
    return damping(*deceleration_loop(spec.pid["kp"], spec.pid["ki"], P1=p["P1"], T2=p["T2"],
                                      tau=spec.tau_filter), p["T1"] + spec.dt_ctrl)


def _speeds(spec, **more) -> list:
    """Per speed ``s`` (km/h): ``{"b": "v<s>", "s": s}``, times the members ``more``."""
    out = [{"b": speed_key(s), "s": s} for s in spec.speeds_kmh]
    for k, vals in more.items():
        out = [x | {k: v} for x in out for v in vals]
    return out


#: The error grid of one mode and channel at a speed (healthy sensors, electric brake on).
def _grid(r, s, m, ch="analogue") -> dict:
    return dict(speed_kmh=s, mode=m, channel=ch, fault="healthy", electric=True)


def _nominal(r, s, **kw) -> float:
    """Stop error (m) at the nominal corner (closed loop, analogue, healthy unless ``kw``)."""
    return r.select(**{**dict(speed_kmh=s, mode="closed", channel="analogue", force_error=0.0,
                              gradient=0.0, friction=1.0, electric=True, fault="healthy"),
                       **kw})[0][1]


def _feasible_abs(r, s, ch) -> list:
    return [abs(e) for x, e in r.select(**_grid(r, s, "closed", ch))
            if r.feasible[r.runs.index(x)]]


def _feasible_max(r, s, ch):
    feas = _feasible_abs(r, s, ch)
    return max(feas) if feas else None


_FAULTS = tuple(f for f in FAULTS if f != "healthy")
_CH = {"ch": CHANNELS}

#: The quantities paper 004's claims name, declared once.
TABLE = (
    Declared("worked.{k}", "{u}", lambda r, k, u: r.worked[k], over=lambda spec: [
        {"k": k, "u": "%" if k.startswith("share") else "m/s^2" if k.startswith("a2") else "m"}
        for k in compute_worked(spec.paper.worked)]),
    *(Declared("{b}.%s.max_abs_m" % m, "m", lambda r, b, s, m=m: r.max_abs(**_grid(r, s, m)),
               over=_speeds) for m in ("open", "ato-open")),
    Declared("{b}.closed.{ch}.max_abs_m", "m",
             lambda r, b, s, ch: r.max_abs(**_grid(r, s, "closed", ch)),
             over=lambda spec: _speeds(spec, **_CH)),
    Declared("{b}.closed.{ch}.failing_corners", "1",
             lambda r, b, s, ch: float(len(r.failing(**_grid(r, s, "closed", ch)))),
             over=lambda spec: _speeds(spec, **_CH)),
    Declared("{b}.closed.{ch}.failing_feasible_corners", "1", lambda r, b, s, ch: float(sum(
        r.feasible[r.runs.index(x)] for x, _ in r.failing(**_grid(r, s, "closed", ch)))),
             over=lambda spec: _speeds(spec, **_CH)),
    Declared("{b}.closed.{ch}.feasible_max_abs_m", "m",
             lambda r, b, s, ch: _feasible_max(r, s, ch), over=lambda spec: _speeds(spec, **_CH)),
    Declared("{b}.closed.3bit_minus_analogue_m", "m",
             lambda r, b, s: _feasible_max(r, s, "3bit") - _feasible_max(r, s, "analogue"),
             over=_speeds),
    Declared("{b}.fault[{f}].abs_m", "m", lambda r, b, s, f: r.max_abs(speed_kmh=s, fault=f),
             over=lambda spec: _speeds(spec, f=_FAULTS)),
    Declared("{b}.fault[{f}].error_m", "m", lambda r, b, s, f: _nominal(r, s, fault=f),
             over=lambda spec: _speeds(spec, f=_FAULTS)),
    Declared("{b}.fault[{f}].change_vs_healthy_m", "m",
             lambda r, b, s, f: abs(_nominal(r, s, fault=f) - _nominal(r, s)),
             over=lambda spec: _speeds(spec, f=_FAULTS)),
    Declared("{b}.nominal.closed.analogue.abs_m", "m", lambda r, b, s: abs(_nominal(r, s)),
             over=_speeds),
    Declared("{b}.nominal.closed.3bit.abs_m", "m",
             lambda r, b, s: abs(_nominal(r, s, channel="3bit")), over=_speeds),
    Declared("{b}.nominal.ato-open.abs_m", "m",
             lambda r, b, s: abs(_nominal(r, s, mode="ato-open")), over=_speeds),
    Declared("{b}.electric_loss.{m}.abs_m", "m",
             lambda r, b, s, m: r.max_abs(speed_kmh=s, mode=m, electric=False),
             over=lambda spec: _speeds(spec, m=("closed", "ato-open"))),
    mc_family("{b}.mc.{m}", lambda spec: _speeds(spec, m=MC_MODES),
              lambda r, b, s, m: r.mc[s, m]),
    Declared("{b}.mc.closed_minus_ato-open_p", "1",
             lambda r, b, s: r.mc[s, "closed"].p - r.mc[s, "ato-open"].p, over=_speeds),
    Declared("pid.damping_zeta", "1", lambda r: r.damping.zeta),
)


class ClosedLoopBrake:
    """The analysis of ``[analysis] module = "p004.closed_loop_brake"``."""

    def load(self, root: Reader, spec) -> Paper004:
        return load(root, spec)

    def quantity_names(self, spec) -> set[str]:
        return names(TABLE, spec)

    def quantity_units(self, spec) -> dict[str, str]:
        return units(TABLE, spec)

    def run(self, spec) -> Result004:
        return run_grid(view(spec))

    def quantities(self, res: Result004) -> dict:
        return values(TABLE, res.spec, res)

    def render(self, design, res):
        from .closed_loop_brake_render import render
        return render(design, res)


ANALYSIS = ClosedLoopBrake()
