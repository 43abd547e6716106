"""Paper 004's runs (designs/closed-loop-brake-004.toml) on the
``stop-accuracy`` kind's general run (:func:`workbench.kinds.stop_accuracy.run.run`):
its error grid (``[grid]``, feasibility by ``feasible_with``), its axle-sensor
faults and the electric-brake loss (``[[faults]]``), and its Monte Carlo
(:func:`~workbench.kinds.stop_accuracy.run.montecarlo_statistics`).

What stays here, and why: the names its report and claims use for the modes,
channels and faults (``ato-open``, ``3bit``, "1 sliding"), the speed-distance
curves of two grid corners and the ATO-horizon sweep of ``[retuning]`` (runs
of paper 004's report that the kind does not make).
"""
from __future__ import annotations

import numpy as np

MODES = ("open", "ato-open", "closed")
#: not a control mode: full service from t = 0, to test each corner's feasibility
FULL = "full-service"
CHANNELS = ("analogue", "3bit")
#: the design's fault -> its name in the report (axle states: o healthy, s sliding (reads low),
#: f failed (reads 0), h reads high (calibration), z stuck at its reading when braking starts)
FAULT_NAMES = {"sliding_1": "1 sliding", "failed_3": "3 failed",
               "sliding_2_failed_1": "2 sliding + 1 failed", "failed_4": "all 4 failed",
               "sliding_4": "all 4 sliding", "high_1": "1 reading high", "stuck_1": "1 stuck"}
#: the design's fault that drops the electric brake
ELECTRIC_LOSS = "electric_loss"
#: modes of the Monte Carlo
MC_MODES = ("ato-open", "closed")
#: (mode, channel) -> the design's controller
CONTROLLERS = {("open", "analogue"): "open", ("ato-open", "analogue"): "ato_open",
               ("closed", "analogue"): "closed", ("closed", "3bit"): "closed_3bit",
               (FULL, "analogue"): "full_service"}


def faults(spec) -> dict:
    """The report's axle-sensor cases: name -> states of the 4 axles (healthy first)."""
    return {"healthy": "oooo", **{FAULT_NAMES[f.name]: f.axles for f in spec.faults
                                  if f.name in FAULT_NAMES}}


def _index(spec, mode: str, channel: str = "analogue") -> int:
    return [c.name for c in spec.controllers].index(CONTROLLERS[mode, channel])


def run_curves(spec, distance: dict, force_errors) -> list:
    """(mode, channel, force error, position - D (m), speed (m/s)) of every mode
    at the first speed and each of ``force_errors`` (gradient 0, friction x1),
    recorded every 0.5 s (:func:`~workbench.kinds.stop_accuracy.run.simulate_cases`)."""
    from ...kinds.stop_accuracy.run import compile_laws, simulate_cases
    s = spec.speeds_kmh[0]
    modes = [k for k in CONTROLLERS if k[0] != FULL]
    tr, D = simulate_cases(spec, compile_laws(spec), spec.dt,
                           [(s, _index(spec, *k), None, distance[s]) for k in modes],
                           {"force_error": np.array(force_errors, float)}, dt_rec=0.5)
    n = len(force_errors)
    return [(m, ch, fe, tr.x[:, j * n + k] - D[j * n + k], tr.v[:, j * n + k])
            for k, fe in enumerate(force_errors) for j, (m, ch) in enumerate(modes)]


def run_montecarlo(spec, distance: dict) -> dict:
    """Stop statistics per (speed km/h, mode) over the Monte Carlo draws
    (analogue channel, healthy sensors; every mode and speed meets the same
    draws), the kind's Monte Carlo batch
    (:func:`~workbench.kinds.stop_accuracy.run.montecarlo_statistics`):
    {(speed, mode): StopStatistics}."""
    from ...kinds.stop_accuracy.run import compile_laws, montecarlo_statistics
    cases = [(s, m) for s in spec.speeds_kmh for m in MC_MODES]
    return montecarlo_statistics(spec, compile_laws(spec), [
        (s, _index(spec, m), None, distance[s]) for s, m in cases], cases, dt_rec=0.5)


def run_horizon_sweep(spec, distance: dict) -> tuple:
    """Stop error (m) of the closed loop (analogue) at the nominal corner for
    each ATO prediction horizon (the constant ``t_p``) of ``[retuning]
    t_predict_sweep`` (:func:`~workbench.kinds.stop_accuracy.run.constant_sweep`):
    ((t_predict, speed km/h, error), ...)."""
    from ...kinds.stop_accuracy.run import constant_sweep
    return tuple((tp, s, e) for (tp, s), e in constant_sweep(
        spec, CONTROLLERS["closed", "analogue"], "t_p", spec.paper.t_predict_sweep, distance,
        dt_rec=0.5).items())


__all__ = ["CHANNELS", "CONTROLLERS", "ELECTRIC_LOSS", "FAULT_NAMES", "FULL", "MC_MODES", "MODES",
           "faults", "run_curves", "run_horizon_sweep", "run_montecarlo"]
