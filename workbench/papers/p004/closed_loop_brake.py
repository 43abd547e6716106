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
from dataclasses import dataclass, replace

import numpy as np

from ...features.quantities import Declared, names, units, values
from ...kinds.stop_accuracy.quantities import mc_family
from ...kinds.stop_accuracy.run import speed_key
from ...reader import Reader
from ...tuning.pid import Damping, damping, deceleration_loop
from .closed_loop_brake_run import (CHANNELS, CONTROLLERS, ELECTRIC_LOSS, FAULT_NAMES, FULL,
                                    MC_MODES, run_curves, run_horizon_sweep, run_montecarlo)
from .closed_loop_brake_spec import Paper004, compute_worked, load, loop_values

__all__ = ["ANALYSIS", "NOMINAL", "Result004", "Run", "compute_worked", "decel_damping",
           "run_grid", "TABLE"]

#: the nominal corner (force error, gradient permille, friction factor)
NOMINAL = (0.0, 0.0, 1.0)


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


def run_grid(spec, *, montecarlo: bool = True) -> Result004:
    """The error grid, the sensor faults and the electric-brake loss (the
    kind's general run, without its Monte Carlo); with ``montecarlo`` also the
    Monte Carlo of :data:`MC_MODES` and the horizon sweep."""
    from ...kinds.stop_accuracy.quantities import feasible
    from ...kinds.stop_accuracy.run import run
    res = run(replace(spec, montecarlo=None, convergence=False))
    keys = [k for k, _ in spec.grid]
    corners = [dict(zip(keys, c)) for c in itertools.product(*(v for _, v in spec.grid))]
    corners = [(c["force_error"], c["gradient"], c["friction"]) for c in corners]
    runs, errors, feas = [], [], []
    for s in spec.speeds_kmh:
        ok = feasible(res, s)
        for k, corner in enumerate(corners):
            for (m, ch), name in CONTROLLERS.items():
                if m != FULL:
                    runs.append(Run(s, m, ch, *corner, "healthy", True))
                    errors.append(res.grid[s, name][k])
                    feas.append(ok[k])
        ok = ok[corners.index(NOMINAL)] if NOMINAL in corners else True
        for f, label in FAULT_NAMES.items():
            runs.append(Run(s, "closed", "analogue", *NOMINAL, label, True))
            errors.append(res.faults[s, CONTROLLERS["closed", "analogue"], f])
            feas.append(ok)
        for m in ("ato-open", "closed"):
            runs.append(Run(s, m, "analogue", *NOMINAL, "healthy", False))
            errors.append(res.faults[s, CONTROLLERS[m, "analogue"], ELECTRIC_LOSS])
            feas.append(ok)
    fe = sorted({min(c[0] for c in corners), 0.0} & {c[0] for c in corners if c[1:] == (0.0, 1.0)})
    curves = tuple((Run(spec.speeds_kmh[0], m, ch, f, 0.0, 1.0, "healthy", True), dx, v)
                   for m, ch, f, dx, v in run_curves(spec, res.distance, fe))
    return Result004(compute_worked(spec.paper.worked), res.distance, tuple(runs),
                     tuple(errors), spec.tolerance, tuple(feas), curves,
                     run_montecarlo(spec, res.distance) if montecarlo else None,
                     decel_damping(spec),
                     run_horizon_sweep(spec, res.distance) if montecarlo else (), spec)


def decel_damping(spec) -> Damping:
    """Damping of the linearised deceleration PID loop (electric stage, dead
    time T1 plus one control period: sample and hold, and the backward
    difference of the measured speed)."""
    p, loop = {k: q.value for k, q in spec.params.items()}, loop_values(spec)
    return damping(*deceleration_loop(loop["kp"], loop["ki"], P1=p["P1"], T2=p["T2"],
                                      tau=loop["tau_filter"]), p["T1"] + spec.dt_ctrl)


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


_FAULTS = tuple(FAULT_NAMES.values())
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
        return run_grid(spec)

    def quantities(self, res: Result004) -> dict:
        return values(TABLE, res.spec, res)

    def render(self, design, res):
        from .closed_loop_brake_render import render
        return render(design, res)


ANALYSIS = ClosedLoopBrake()
