"""Cost of a basin certificate (workbench/roa): wall and CPU time per estimate.

Prints, for each 2-state model, the bracket [c_certified, c_refuted], the
boxes of the interval cover and the time of the falsifier + verifier
(symbolic set-up included: the first estimate of a problem compiles its
interval functions). Target (issue 15): a 2-state model within 30 s on 2 cores.

Models: x' = -x + x^3, y' = -y (basin |x| < 1); Van der Pol in reversed
time; paper 003's cruise loop (law 61, dry and wet designs); the delay-free
loop of the delay-feedback design wheel-slip-burckhardt (2 states, Burckhardt
adhesion; its report's canonical gain), the certificate alone and the whole
basin section (certificate, sampled trajectories and the check from the
certified level's boundary).

Usage: .venv/bin/python benchmarks/basin.py
"""
from __future__ import annotations

import time

import numpy as np
import sympy as sp

from workbench.roa import BasinProblem, estimate_basin, lyapunov_P


def _timed(label, make, c_search):
    t0, c0 = time.perf_counter(), time.process_time()
    prob = make()
    est = estimate_basin(prob, c_search)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"| {label} | {est.c_certified:.6g} | {est.c_refuted:.6g} | {est.boxes} | "
          f"{est.samples} | {wall:.2f} | {cpu:.2f} |")


def main() -> None:
    x, y = sp.symbols("x y", real=True)
    print("| model | c_certified | c_refuted | boxes | falsifier points | wall s | cpu s |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    _timed("cubic x' = -x + x^3", lambda: BasinProblem(
        [-x + x**3, -y], (x, y), (0.0, 0.0), np.eye(2)), 4.0)
    _timed("Van der Pol reversed", lambda: BasinProblem(
        [-y, x - (1 - x**2) * y], (x, y), (0.0, 0.0),
        lyapunov_P(np.array([[0.0, -1.0], [1.0, -1.0]]))), 10.0)
    from workbench.plants.adhesion import NumericAdhesion
    from workbench.papers.p003 import antiskid_basin as AB
    dry = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
               c1=112.2, c2=2.6, g=9.8)                       # 003 Tables 1-2
    wet = dict(dry, a=0.2478, b=22.87, c=5.396)
    # gains: the workbench's certified syntheses (reports/antiskid-run-{dry,wet}.md)
    for rail, vals, v_d, K in (("dry", dry, 70.0, (-0.004575, 10.27)),
                               ("wet", wet, 60.0, (-0.003919, 3.921))):
        lam_opt = NumericAdhesion.from_dict(vals).lambda_opt()
        vt = tuple(sorted(vals.items()))
        for label in ("first (symbolic set-up)", "second (model cached)"):
            t0, c0 = time.perf_counter(), time.process_time()
            loop, lam_d, _ = AB.cruise_loop(vt, v_d)
            _, est = loop.estimate(K, 100.0, [(0.0, lam_opt - lam_d)])
            wall, cpu = time.perf_counter() - t0, time.process_time() - c0
            print(f"| 003 cruise law (61), {rail}, w = 100, {label} | {est.c_certified:.6g} | "
                  f"{est.c_refuted:.6g} | {est.boxes} | {est.samples} | {wall:.2f} | {cpu:.2f} |")
    _delay_feedback()


def _delay_feedback() -> None:
    """wheel-slip-burckhardt-delay-feedback: certificate and basin section."""
    from pathlib import Path

    from workbench.design import load_design
    from workbench.features.basin import delay_feedback_basin, run_basin
    from workbench.kinds.delay_feedback.model import PlantModel, solve_operating_point
    path = (Path(__file__).resolve().parents[1] / "designs"
            / "wheel-slip-burckhardt-delay-feedback.toml")
    spec = load_design(path).spec
    K = [[-0.03662, 0.007732]]         # reports/wheel-slip-burckhardt-delay-feedback.md
    values = spec.plant.values()
    dom = spec.basin.domain
    box = ([dom["omega"][0], dom["T"][0]], [dom["omega"][1], dom["T"][1]])
    for label in ("first (model built)", "second (model built again)"):
        t0, c0 = time.perf_counter(), time.process_time()
        model = PlantModel(spec.plant)
        op = solve_operating_point(model, values)
        est = delay_feedback_basin(model, values, op, K, c_search=float("inf"), domain=box).estimate
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        print(f"| wheel-slip delay-free loop, certificate, {label} | {est.c_certified:.6g} | "
              f"{est.c_refuted:.6g} | {est.boxes} | {est.samples} | {wall:.2f} | {cpu:.2f} |")
    t0, c0 = time.perf_counter(), time.process_time()
    b = run_basin(spec.basin, spec, model, values, op, K)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    est = b.check.estimate
    print(f"| wheel-slip, whole basin section (+ {len(b.sampled) + len(b.inside)} trajectories) | "
          f"{est.c_certified:.6g} | {est.c_refuted:.6g} | {est.boxes} | {est.samples} | "
          f"{wall:.2f} | {cpu:.2f} |")


if __name__ == "__main__":
    main()
