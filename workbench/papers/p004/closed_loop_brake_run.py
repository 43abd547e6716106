"""Paper 004's runs (designs/closed-loop-brake-004.toml) on the
``stop-accuracy`` kind's general run (:func:`workbench.kinds.stop_accuracy.run.run`):
its error grid (``[grid]``, feasibility by ``feasible_with``), its axle-sensor
faults and the electric-brake loss (``[[faults]]``), its Monte Carlo
(:func:`~workbench.kinds.stop_accuracy.run.controller_montecarlo`), the
speed-distance curves (:func:`~workbench.kinds.stop_accuracy.run.factor_traces`)
and the horizon sweep (:func:`~workbench.kinds.stop_accuracy.run.constant_sweep`).

What stays here, and why: the names its report and claims use for the modes,
channels and faults (``ato-open``, ``3bit``, "1 sliding"), and which runs its
report makes: the curves of two grid corners, the Monte Carlo of two modes
(recorded every 0.5 s) and the ATO-horizon sweep of ``[retuning]``.
"""
from __future__ import annotations

MODES = ("open", "ato-open", "closed")
#: the factors of the error grid, in the report's order
FACTORS = ("force_error", "gradient", "friction")
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
#: (mode, channel) -> controller of the report's runs (every one but full service)
RUNS = {k: c for k, c in CONTROLLERS.items() if k[0] != FULL}


def faults(spec) -> dict:
    """The report's axle-sensor cases: name -> states of the 4 axles (healthy first)."""
    return {"healthy": "oooo", **{FAULT_NAMES[f.name]: f.axles for f in spec.faults
                                  if f.name in FAULT_NAMES}}


def run_curves(spec, distance: dict, force_errors) -> list:
    """(mode, channel, force error, position - D (m), speed (m/s)) of every mode
    at the first speed and each of ``force_errors`` (gradient 0, friction x1),
    recorded every 0.5 s (:func:`~workbench.kinds.stop_accuracy.run.factor_traces`)."""
    from ...kinds.stop_accuracy.run import factor_traces
    s = spec.speeds_kmh[0]
    tr = factor_traces(spec, list(RUNS.values()), s, distance[s], "force_error", force_errors,
                       dt_rec=0.5)
    return [(m, ch, fe, *tr[fe, c]) for fe in force_errors for (m, ch), c in RUNS.items()]


def run_montecarlo(spec, distance: dict) -> dict:
    """Stop statistics per (speed km/h, mode) over the Monte Carlo draws
    (analogue channel, healthy sensors; every mode and speed meets the same
    draws), the kind's Monte Carlo batch
    (:func:`~workbench.kinds.stop_accuracy.run.controller_montecarlo`):
    {(speed, mode): StopStatistics}."""
    from ...kinds.stop_accuracy.run import controller_montecarlo
    st = controller_montecarlo(spec, [CONTROLLERS[m, "analogue"] for m in MC_MODES], distance,
                               dt_rec=0.5)
    return {(s, m): st[s, CONTROLLERS[m, "analogue"]] for s in spec.speeds_kmh for m in MC_MODES}


def run_horizon_sweep(spec, distance: dict) -> dict:
    """Stop error (m) of the closed loop (analogue) at the nominal corner for
    each ATO prediction horizon (the constant ``t_p``) of ``[retuning]
    t_predict_sweep`` (:func:`~workbench.kinds.stop_accuracy.run.constant_sweep`):
    {(t_predict, speed km/h): error}."""
    from ...kinds.stop_accuracy.run import constant_sweep
    return constant_sweep(spec, CONTROLLERS["closed", "analogue"], "t_p",
                          spec.paper.t_predict_sweep, distance, dt_rec=0.5)


__all__ = ["CHANNELS", "CONTROLLERS", "ELECTRIC_LOSS", "FACTORS", "FAULT_NAMES", "FULL", "MC_MODES",
           "MODES", "RUNS", "faults", "run_curves", "run_horizon_sweep", "run_montecarlo"]
