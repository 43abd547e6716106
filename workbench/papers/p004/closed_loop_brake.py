"""Paper 004's deceleration feedback against the open-loop brake, over an
error grid, on the paper-000 brake plant (designs/closed-loop-brake-004.toml):
the ``[analysis]`` module of a ``stop-accuracy`` design.

The design is a configuration of the general kind
(:mod:`workbench.kinds.stop_accuracy`): the modes are its controllers (the
ATO law an expression, the command generator its named module
``deceleration_loop``), the grid its ``[grid]``, the Monte Carlo its
``[montecarlo]``, the sensor faults and the electric-brake loss its
``[[faults]]``; the grid, the faults and the nominal stops are the kind's
general run (:func:`workbench.kinds.stop_accuracy.run.run`, kept whole in
:attr:`Result004.kind` and read under the report's names through
:mod:`workbench.kinds.stop_accuracy.kind_view`), the rest its batches
(:mod:`.closed_loop_brake_run`).
What stays here is paper 004's: the worked numbers of section 1.3 (sympy
expressions written here once, ``[worked]``), the names of its report's
runs (``open``, ``ato-open``, ``closed``; channels ``analogue`` and
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

from dataclasses import dataclass, replace

from ...features.quantities import Declared
from ...kinds.stop_accuracy.analysis import Analysis
from ...kinds.stop_accuracy.kind_view import KindView, kind_quantity, per_speed
from ...kinds.stop_accuracy.loop_damping import loop_damping
from ...kinds.stop_accuracy.quantities import mc_family
from ...kinds.stop_accuracy.run import grid_corners, run
from ...tuning.pid import Damping
from .closed_loop_brake_run import (CHANNELS, CONTROLLERS, ELECTRIC_LOSS, FACTORS, FAULT_NAMES,
                                    MC_MODES, run_curves, run_horizon_sweep, run_montecarlo)
from .closed_loop_brake_render import render
from .closed_loop_brake_spec import compute_worked, load

__all__ = ["ANALYSIS", "NOMINAL", "Result004", "compute_worked", "run_grid", "TABLE"]

#: the nominal corner (force error, gradient permille, friction factor)
NOMINAL = (0.0, 0.0, 1.0)
#: a sensor fault's name in the report -> the design's fault
_FAULT_KEYS = {v: k for k, v in FAULT_NAMES.items()}


@dataclass(frozen=True)
class Result004(KindView):
    """The kind's general run and what paper 004's report adds to it."""

    kind: object            # StopAccuracyResult: grid per (speed, controller), faults, nominal
    worked: dict
    curves: tuple = ()      # (mode, channel, force error, position - D (m), speed (m/s))
    mc: dict | None = None  # (speed km/h, mode) -> StopStatistics of the Monte Carlo
    damping: Damping | None = None   # of the linearised deceleration PID loop
    sweep: dict | None = None  # (ATO horizon s, speed km/h) -> nominal closed-loop stop error m

    def corners(self) -> list:
        """(force error, gradient, friction) of every grid corner, in the grid's order."""
        return grid_corners(self.spec, FACTORS)

    def grid(self, s, mode: str, channel: str = "analogue") -> tuple:
        """Stop errors (m) of a mode at every grid corner (healthy sensors)."""
        return self.kind.grid[s, CONTROLLERS[mode, channel]]

    def stop(self, s, mode: str = "closed", channel: str = "analogue",
             fault: str = "healthy") -> float:
        """Stop error (m) at the nominal corner: healthy, under a sensor fault
        (its report name) or a fault of the design (``electric_loss``)."""
        c = CONTROLLERS[mode, channel]
        if fault == "healthy":
            return self.kind.nominal[s, c]
        return self.kind.faults[s, c, _FAULT_KEYS.get(fault, fault)]


def run_grid(spec, *, montecarlo: bool = True) -> Result004:
    """The kind's general run (error grid, sensor faults, electric-brake loss,
    without its Monte Carlo) and the curves; with ``montecarlo`` also the
    Monte Carlo of :data:`MC_MODES` and the horizon sweep."""
    res = run(replace(spec, montecarlo=None, convergence=False))
    cs = grid_corners(spec, FACTORS)
    fe = sorted({min(c[0] for c in cs), 0.0} & {c[0] for c in cs if c[1:] == NOMINAL[1:]})
    return Result004(res, compute_worked(spec.paper.worked),
                     tuple(run_curves(spec, res.distance, fe)),
                     run_montecarlo(spec, res.distance) if montecarlo else None,
                     loop_damping(spec, _CLOSED),
                     run_horizon_sweep(spec, res.distance) if montecarlo else None)


#: the report's names -> the design's controllers
_MODES = [{"m": m, "c": CONTROLLERS[m, "analogue"]} for m in ("open", "ato-open")]
_CH = [{"ch": ch, "c": CONTROLLERS["closed", ch]} for ch in CHANNELS]
_FAULTS = [{"f": v, "k": k} for k, v in FAULT_NAMES.items()]
_CLOSED = CONTROLLERS["closed", "analogue"]

#: The quantities paper 004's claims name, declared once: the grid's, the faults' and the
#: nominal stops' are the kind's quantities (:mod:`workbench.kinds.stop_accuracy.quantities`)
#: under the report's names.
TABLE = (
    Declared("worked.{k}", "{u}", lambda r, k, u: r.worked[k], over=lambda spec: [
        {"k": k, "u": "%" if k.startswith("share") else "m/s^2" if k.startswith("a2") else "m"}
        for k in compute_worked(spec.paper.worked)]),
    Declared("{b}.{m}.max_abs_m", "m", kind_quantity("{b}.{c}.grid.max_abs_m"), over=per_speed(*_MODES)),
    *(Declared("{b}.closed.{ch}.%s" % name, unit, kind_quantity("{b}.{c}.grid.%s" % name),
               over=per_speed(*_CH))
      for name, unit in (("max_abs_m", "m"), ("failing_corners", "1"),
                         ("failing_feasible_corners", "1"), ("feasible_max_abs_m", "m"))),
    Declared("{b}.closed.3bit_minus_analogue_m", "m", lambda r, b, s: None if None in (
        x := [r.kind_values[f"{b}.{c['c']}.grid.feasible_max_abs_m"] for c in _CH]) else
        x[1] - x[0], over=per_speed()),
    Declared("{b}.fault[{f}].abs_m", "m", kind_quantity("{b}.%s.fault[{k}].error_m" % _CLOSED, abs),
             over=per_speed(*_FAULTS)),
    Declared("{b}.fault[{f}].error_m", "m", kind_quantity("{b}.%s.fault[{k}].error_m" % _CLOSED),
             over=per_speed(*_FAULTS)),
    Declared("{b}.fault[{f}].change_vs_healthy_m", "m",
             kind_quantity("{b}.%s.fault[{k}].change_m" % _CLOSED), over=per_speed(*_FAULTS)),
    Declared("{b}.nominal.closed.{ch}.abs_m", "m", kind_quantity("{b}.{c}.nominal_m", abs),
             over=per_speed(*_CH)),
    Declared("{b}.nominal.ato-open.abs_m", "m", kind_quantity("{b}.%s.nominal_m" % _MODES[1]["c"], abs),
             over=per_speed()),
    Declared("{b}.electric_loss.{m}.abs_m", "m",
             kind_quantity("{b}.{c}.fault[%s].error_m" % ELECTRIC_LOSS, abs), over=per_speed(
                 *({"m": m, "c": CONTROLLERS[m, "analogue"]} for m in ("closed", "ato-open")))),
    mc_family("{b}.mc.{m}", per_speed(*({"m": m} for m in MC_MODES)),
              lambda r, b, s, m: r.mc[s, m]),
    Declared("{b}.mc.closed_minus_ato-open_p", "1",
             lambda r, b, s: r.mc[s, "closed"].p - r.mc[s, "ato-open"].p, over=per_speed()),
    Declared("pid.damping_zeta", "1", lambda r: r.damping.zeta),
)


#: the analysis of ``[analysis] module = "p004.closed_loop_brake"``
ANALYSIS = Analysis(TABLE, load, run_grid, render)
