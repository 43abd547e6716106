"""Benchmark of the delay simulator on paper 003's dry run.

Prints, in one process:

1. the 400 s dry run (case ``compensated`` of designs/antiskid-run-dry.toml)
   at the design's converged step: simulated seconds per wall second;
2. a reference of matched accuracy: the same sampled controller with the
   plant integrated by ``scipy.integrate.solve_ivp`` (Radau, rtol 1e-8)
   between samples — the method of steps for an input delay (on each
   sample interval the delayed input is known history, so the interval is
   an ODE) — over the first ``--ref-horizon`` seconds, and the difference in
   the time to cruise;
3. batched Monte Carlo throughput (``workbench.studies.antiskid_montecarlo.sweep``,
   process pool) and the projected time for 1000 runs.

Usage: .venv/bin/python benchmarks/simulate.py [--samples N] [--workers W]
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from workbench.controllers.antiskid003 import Antiskid003
from workbench.design import load_design
from workbench.sim.history import DelayLine
from workbench.sim.wheel_slip import ScalarOps, model_functions, plant_forms
from workbench.studies import antiskid_run_spec as S
from workbench.studies.antiskid_montecarlo import sweep
from workbench.studies.antiskid_scenario import simulate_antiskid


def reference_run(rs, dt: float, t_end: float) -> tuple[float, float]:
    """(time to cruise, wall s): sampled controller, solve_ivp plant."""
    fns = model_functions("math")
    p = rs.plant_params
    ctrl = Antiskid003(rs.controller, rs.x0, rs.u_init, dt, None)
    line = DelayLine(rs.h, dt, rs.u_init)
    x = np.array(rs.x0, float)

    def rhs(t, y, u):
        f1, f20, f2u, *_ = plant_forms(max(y[0], 1e-3), y[1], p, fns, ScalarOps)
        return [f1, f20 + f2u * u]

    t0 = time.perf_counter()
    for n in range(int(round(t_end / dt))):
        t = n * dt
        u, _ = ctrl(t, (float(x[0]), float(x[1])), line)
        line.push(u)
        sol = solve_ivp(rhs, (t, t + dt), x, method="Radau", rtol=1e-8, atol=1e-11,
                        args=(line.delayed(),))
        x = sol.y[:, -1]
    return float(ctrl.m.t_cruise), time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--ref-horizon", type=float, default=40.0, help="s; > time to cruise")
    args = ap.parse_args()
    design = load_design("designs/antiskid-run-dry.toml")
    spec = design.spec
    K = S.gain_for(spec)[0]
    case = next(c for c in spec.cases if c.name == "compensated")
    rs = S.run_settings(spec, S.controller_settings(spec, K, case))
    dt = spec.dt

    t0 = time.perf_counter()
    _, m = simulate_antiskid(rs, dt, record_dt=None)
    wall = time.perf_counter() - t0
    sim_s = float(m.t_stop) if math.isfinite(m.t_stop) else spec.scenario["t_end"]
    print(f"dry run (compensated), dt = {dt} s: {sim_s:.1f} simulated s in {wall:.2f} s wall "
          f"= {sim_s / wall:.0f}x real time (target >= 100x)")

    import dataclasses
    short = dataclasses.replace(rs, t_end=args.ref_horizon)
    t0 = time.perf_counter()
    _, ms = simulate_antiskid(short, dt, record_dt=None)
    wall_ours = time.perf_counter() - t0
    t_ref, wall_ref = reference_run(rs, dt, args.ref_horizon)
    print(f"first {args.ref_horizon:g} s: ours {wall_ours:.2f} s wall, solve_ivp Radau "
          f"method of steps {wall_ref:.2f} s wall -> ratio {wall_ref / wall_ours:.0f}x; "
          f"time to cruise ours {float(ms.t_cruise):.4f} s, reference {t_ref:.4f} s "
          f"(difference {abs(float(ms.t_cruise) - t_ref):.1e} s)")

    res = sweep(design, args.samples, seed=1, workers=args.workers)
    per_run = res.seconds / args.samples
    mc_dt = spec.montecarlo.dt or dt
    print(f"Monte Carlo: {args.samples} runs of up to {spec.scenario['t_end']:g} s at "
          f"dt = {mc_dt:g} s, "
          f"{res.workers} workers, {res.seconds:.1f} s -> {args.samples / res.seconds * 60:.0f} "
          f"runs/min; projected 1000 runs: {1000 * per_run:.0f} s (target <= 300 s); vs the "
          f"solve_ivp reference run sequentially: {spec.scenario['t_end'] / args.ref_horizon * wall_ref * 1000 / 60:.0f} min")


if __name__ == "__main__":
    main()
