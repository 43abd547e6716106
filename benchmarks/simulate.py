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
3. batched Monte Carlo throughput (``workbench.papers.p003.antiskid_montecarlo.sweep``,
   process pool) of both stepping paths side by side, the same runs: the
   batched numpy reference and the compiled kernel (numba; compiled once in
   this process before the pool forks, which is not in its time), runs/min
   and their ratio, with the machine's load average (the figures are only
   comparable within one run); for the design as shipped and for the same
   sweep without its perturbations (longer runs: the issue's workload).

Usage: .venv/bin/python benchmarks/simulate.py [--samples N] [--workers W] [--skip-single]
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from workbench.controllers.antiskid003 import Antiskid003
from workbench.design import load_design
from workbench.papers.p003 import antiskid_run_spec as S
from workbench.papers.p003.antiskid_montecarlo import sweep
from workbench.papers.p003.antiskid_scenario import MetricsRecorder, simulate_antiskid
from workbench.sim.history import DelayLine
from workbench.sim.wheel_slip import PARAM_ORDER, ScalarOps, model_functions, plant_forms


def reference_run(rs, dt: float, t_end: float) -> tuple[float, float]:
    """(time to cruise, wall s): sampled controller, solve_ivp plant."""
    fns = model_functions("math")
    p = rs.plant_params
    rec = MetricsRecorder(rs.controller, rs.x0, None, p[PARAM_ORDER.index("r")], dt)
    ctrl = Antiskid003(rs.controller, rs.x0, rs.u_init, dt, None, recorder=rec)
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
    return float(rec.m.t_cruise), time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--ref-horizon", type=float, default=40.0, help="s; > time to cruise")
    ap.add_argument("--skip-single", action="store_true",
                    help="only the Monte Carlo throughput of the two paths")
    args = ap.parse_args()
    design = load_design("designs/antiskid-run-dry.toml")
    spec = design.spec
    K = S.gain_for(spec)[0]
    case = next(c for c in spec.cases if c.name == "compensated")
    rs = S.run_settings(spec, S.controller_settings(spec, K, case))
    dt = spec.dt

    if not args.skip_single:
        single_runs(rs, spec, dt, args.ref_horizon)
    montecarlo(design, spec, args.samples, args.workers)


def single_runs(rs, spec, dt: float, ref_horizon: float) -> None:
    """Items 1 and 2 of the module docstring."""
    t0 = time.perf_counter()
    _, m = simulate_antiskid(rs, dt, record_dt=None)
    wall = time.perf_counter() - t0
    sim_s = float(m.t_stop) if math.isfinite(m.t_stop) else spec.scenario["t_end"]
    print(f"dry run (compensated), dt = {dt} s: {sim_s:.1f} simulated s in {wall:.2f} s wall "
          f"= {sim_s / wall:.0f}x real time (target >= 100x)")

    import dataclasses
    short = dataclasses.replace(rs, t_end=ref_horizon)
    t0 = time.perf_counter()
    _, ms = simulate_antiskid(short, dt, record_dt=None)
    wall_ours = time.perf_counter() - t0
    t_ref, wall_ref = reference_run(rs, dt, ref_horizon)
    print(f"first {ref_horizon:g} s: ours {wall_ours:.2f} s wall, solve_ivp Radau "
          f"method of steps {wall_ref:.2f} s wall -> ratio {wall_ref / wall_ours:.0f}x; "
          f"time to cruise ours {float(ms.t_cruise):.4f} s, reference {t_ref:.4f} s "
          f"(difference {abs(float(ms.t_cruise) - t_ref):.1e} s)")

    print(f"solve_ivp reference run, whole {spec.scenario['t_end']:g} s horizon (projected): "
          f"{spec.scenario['t_end'] / ref_horizon * wall_ref:.0f} s per run")


def unperturbed(design):
    """The design without its sweep's perturbations (noise, gradient, varying
    delay): the workload of issue 17's figures (1000 runs at dt = 0.005 s in
    166 s), whose runs are longer (fewer diverge early)."""
    import dataclasses
    ms = dataclasses.replace(design.spec.montecarlo, perturb=None)
    return dataclasses.replace(design, spec=dataclasses.replace(design.spec, montecarlo=ms))


def montecarlo(design, spec, samples: int, workers: int) -> None:
    """Item 3: the same sweep by both paths, runs/min side by side, for the
    design as shipped and without its perturbations."""
    import os
    import resource

    from workbench.papers.p003.antiskid_kernel import LANES, compiled_available
    mc_dt = spec.montecarlo.dt or spec.dt
    print(f"Monte Carlo: {samples} runs of up to {spec.scenario['t_end']:g} s at dt = {mc_dt:g} s, "
          f"seed 1, {workers} workers; compiled batches keep {LANES} runs in flight")
    paths = ("numpy", "compiled") if compiled_available() else ("numpy",)
    workloads = [("as shipped (perturbations on)", design)]
    if spec.montecarlo.perturb is not None:
        workloads.append(("without perturbations", unperturbed(design)))
    for label, d in workloads:
        print(f" {label}; load average before: {os.getloadavg()[0]:.2f}")
        rates = {}
        for kernel in paths:
            cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
            res = sweep(d, samples, seed=1, workers=workers, kernel=kernel, progress=False)
            cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - cpu0   # the workers
            rates[kernel] = samples / res.seconds * 60
            print(f"  {kernel:>8}: {res.seconds:7.1f} s -> {rates[kernel]:6.0f} runs/min "
                  f"({rates[kernel] / 60 / res.workers:.1f} runs/s per worker); "
                  f"projected 1000 runs: {1000 / rates[kernel] * 60:.0f} s; workers' CPU "
                  f"{cpu:.1f} s = {samples / cpu:.1f} runs per CPU-second (on {workers} idle "
                  f"cores: {samples / cpu * 60 * workers:.0f} runs/min)")
        if len(rates) == 2:
            print(f"  ratio compiled / numpy: {rates['compiled'] / rates['numpy']:.1f}x "
                  f"(target: compiled >= 3000 runs/min on 2 cores); "
                  f"load average after: {os.getloadavg()[0]:.2f}")
        else:
            print("  compiled: numba not installed (pip install 'traincontrol-workbench[fast]')")


if __name__ == "__main__":
    main()
