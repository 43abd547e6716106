"""Simulation of paper 004's runs (designs/closed-loop-brake-004.toml)
through the ``stop-accuracy`` kind: its modes are the design's controllers
(in the order of :data:`CONTROLLERS`), its command generator the kind's named
module ``deceleration_loop`` (:mod:`workbench.kinds.stop_accuracy.decel_loop`),
and every batch runs in :func:`workbench.kinds.stop_accuracy.run.simulate_runs`.

What stays here, and why: the report's run lists (the error grid with its
full-service feasibility runs, the sensor faults and the electric-brake loss
at the nominal corner, the Monte Carlo of two modes, the ATO-horizon sweep)
and the names its report and claims use (``ato-open``, ``3bit``, "1 sliding").
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np

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
#: modes of the Monte Carlo
MC_MODES = ("ato-open", "closed")
#: (mode, channel) -> the design's controller (index = its position in the design)
CONTROLLERS = {("open", "analogue"): "open", ("ato-open", "analogue"): "ato_open",
               ("closed", "analogue"): "closed", ("closed", "3bit"): "closed_3bit",
               (FULL, "analogue"): "full_service"}
def simulate_brake(spec, *, v0, dist, controller, states, overrides: dict, theta, kappa,
                   t_predict=None):
    """Brake ``n`` runs to their stopping points ``dist`` (m) through the
    kind's :func:`~workbench.kinds.stop_accuracy.run.simulate_runs`.

    Parameters
    ----------
    spec : Spec004
        The paper's view of the design (its ``kind``: the spec that runs).
    v0, dist : ndarray
        Initial speed (m/s) and stopping point (m) per run.
    controller : ndarray of int
        Index into :data:`CONTROLLERS`.
    states : ndarray, shape (n, 4)
        Axle-sensor states (:data:`FAULTS`).
    overrides : dict
        Brake parameters per run (:func:`workbench.sim.stopping.batch_params`).
    theta, kappa : ndarray
        Gradient (permille) and load-weighing gain per run.
    t_predict : ndarray, optional
        The ATO's prediction horizon (s) per run (default: the design's).

    Returns
    -------
    workbench.sim.stopping.Traces
        Recorded every 0.5 s.
    """
    from ...kinds.stop_accuracy.run import compile_laws, simulate_runs
    from ...sim.stopping import batch_params
    ks = spec.kind
    p = batch_params(ks.base(), len(v0), overrides)
    tr, _ = simulate_runs(ks, compile_laws(ks), spec.dt, p, np.asarray(controller),
                          np.asarray(dist, float), x0=0.0, v0=v0, ratio=1.0, theta=theta,
                          kappa=kappa, axles=states, dt_rec=0.5,
                          constants=None if t_predict is None else {"t_p": t_predict})
    return tr


def run_montecarlo(spec, distance: dict) -> dict:
    """Stop statistics per (speed km/h, mode) over the Monte Carlo draws
    (analogue channel, healthy sensors; every mode and speed meets the same
    draws), the kind's Monte Carlo batch
    (:func:`~workbench.kinds.stop_accuracy.run.montecarlo_statistics`) at the
    view's draws, tolerance and step: {(speed, mode): StopStatistics}."""
    from ...kinds.stop_accuracy.run import compile_laws, montecarlo_statistics
    names = list(CONTROLLERS.values())
    cases = [(s, m) for s in spec.speeds_kmh for m in MC_MODES]
    ks = replace(spec.kind, montecarlo=spec.montecarlo, tolerance=spec.tolerance, dt=spec.dt)
    return montecarlo_statistics(ks, compile_laws(ks), [
        (s, names.index(CONTROLLERS[m, "analogue"]), None, distance[s]) for s, m in cases],
        cases, dt_rec=0.5)


def run_horizon_sweep(spec, distance: dict) -> tuple:
    """Stop error (m) of the closed loop (analogue) at the nominal corner for
    each ATO prediction horizon of ``spec.t_predict_sweep``: ((t_predict,
    speed km/h, error), ...)."""
    cases = [(tp, s) for s in spec.speeds_kmh for tp in spec.t_predict_sweep]
    n = len(cases)
    tr = simulate_brake(spec, v0=np.array([s / 3.6 for _, s in cases]),
                        dist=np.array([distance[s] for _, s in cases]),
                        controller=np.full(n, list(CONTROLLERS).index(("closed", "analogue"))),
                        states=np.full((n, 4), "o"), overrides={}, theta=np.zeros(n),
                        kappa=np.ones(n), t_predict=np.array([tp for tp, _ in cases]))
    return tuple((tp, s, float(x - distance[s])) for (tp, s), x in zip(cases, tr.x_stop))


__all__ = ["CHANNELS", "CONTROLLERS", "FAULTS", "FULL", "MC_MODES", "MODES",
           "run_horizon_sweep", "run_montecarlo", "simulate_brake"]
