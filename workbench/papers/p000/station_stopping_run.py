"""Runs of designs/stopping-line5.toml (paper 000) through the ``stop-accuracy``
kind's simulation, collected into the paper's rows.

Every stop is the kind's (:mod:`workbench.kinds.stop_accuracy.run`): the
per-section repeats (:func:`~workbench.kinds.stop_accuracy.run.section_runs`),
the nominal plant and the Monte Carlo
(:func:`~workbench.kinds.stop_accuracy.run.simulate_cases`, every case
meeting the same draws), and so are the example stops of section 1
(:func:`~workbench.kinds.stop_accuracy.run.section_example`), the nominal
stops with their oscillation counts
(:func:`~workbench.kinds.stop_accuracy.tracked_stops.tracked_stops`), the damping of
the PIDs' linearised loops and the sign changes of their speed errors
(:mod:`workbench.kinds.stop_accuracy.loop_damping`). What stays here is
paper 000's: which runs make its rows (the paper names of
:mod:`.station_stopping_spec`), the nominal row's tracking window (the first
80 % of the planned braking) and dead band (:data:`SIGN_DEADBAND`), and the
result its report and claims read (:class:`StopResult`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...kinds.stop_accuracy.loop_damping import pid_damping, pid_dead_time
from ...kinds.stop_accuracy.tracked_stops import tracked_stops
from .station_stopping_spec import ABLATION, CONTROLLERS, DAMPING, MC_CONTROLLERS, VARIANTS

#: Speed errors below this (m/s; 0.18 km/h, below a speedometer's resolution) do not
#: count as a sign change (oscillation count).
SIGN_DEADBAND = 0.05


@dataclass(frozen=True)
class StopResult:
    spec: object                          # the kind's StopAccuracySpec
    sections: tuple                       # the kind's Section
    planned_time: tuple[float, ...]       # braking phase, s
    stats: dict                           # (controller, section index) -> CellStats
    example: dict                         # controller -> (t, x - x_stop, v, x_d, v_d) of one run
    theta_hat_final: tuple[float, float]  # SMARC estimate range at the end
    nominal: dict                         # paper name -> TrackedStop
    mc: dict                              # paper name -> StopStatistics (m)
    damping: dict                         # PID paper name -> Damping of its linearised loop
    tolerance: float                      # m

    def overall(self, ctl: str) -> float:
        """Mean over sections of the per-section mean |stop error| (cm)."""
        return float(np.mean([self.stats[ctl, i].mean_abs for i in range(len(self.sections))]))


def loop_dead_time(spec, name: str) -> float:
    """Dead time (s) of the linearised speed loop of PID ``name`` (the kind's
    :func:`~workbench.kinds.stop_accuracy.loop_damping.pid_dead_time`)."""
    return pid_dead_time(spec, VARIANTS[name][0])


def _sections(spec, laws):
    from ...kinds.stop_accuracy.run import section_example, section_runs, section_statistics
    tr, track, runs = section_runs(spec, laws, spec.dt)
    cells = section_statistics(spec, tr, runs)
    ns = len(spec.sections.sections)
    stats = {(k, s): cells[s, VARIANTS[k][0]] for s in range(ns) for k in CONTROLLERS}
    example = {k: section_example(spec, tr, runs, VARIANTS[k][0]) for k in CONTROLLERS}
    planned = tuple(spec.reference.braking(s.length, tr.t[:1])[2]
                    for s in spec.sections.sections)
    th = track.smarc[VARIANTS["smarc"][0]].theta_hat
    return stats, example, planned, (float(np.min(th)), float(np.max(th)))


def run_station_stops(spec) -> StopResult:
    """The per-section repeats, the nominal row (every controller) and the
    Monte Carlo (:data:`MC_CONTROLLERS`) of the design ``spec``."""
    from ...kinds.stop_accuracy.run import compile_laws, controller_index, montecarlo_statistics
    laws = compile_laws(spec)
    stats, example, planned, theta = _sections(spec, laws)
    (speed,), L = spec.speeds_kmh, spec.distance
    nom = MC_CONTROLLERS + ABLATION
    stops = tracked_stops(spec, laws, [VARIANTS[k][0] for k in nom], speed, L,
                          track_share=0.8, deadband=SIGN_DEADBAND)
    nominal = {k: stops[VARIANTS[k][0]] for k in nom}
    mcs = montecarlo_statistics(spec, laws, [(speed, controller_index(spec, VARIANTS[k][0]), None,
                                              L) for k in MC_CONTROLLERS], MC_CONTROLLERS)
    damp = {k: pid_damping(spec, VARIANTS[k][0]) for k in DAMPING}
    return StopResult(spec, spec.sections.sections, planned, stats, example, theta, nominal,
                      mcs, damp, spec.tolerance)


__all__ = ["StopResult", "loop_dead_time", "run_station_stops"]
