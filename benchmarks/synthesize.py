"""Benchmark: the 5-eps sweep of paper 003's problem (60) (issue: foundation).

Prints wall time, solves and ms per solve of the sweep with the cvxpy problem
built once (DPP Parameters, re-solved), and of the same sweep with the
problem rebuilt at every bisection step, in the same process.
Target: the whole built-once sweep in under 0.5 s wall on 2 cores.
"""
from __future__ import annotations

import time

import numpy as np

from workbench.design import load_design
from workbench.lmi.core import bisect_delay
from workbench.lmi.freeweighting003 import FreeWeighting003
from workbench.plants.adhesion import NumericAdhesion
from workbench.symbolic.linearise import linearise_cruise
from workbench.synthesis import balancing, synthesize_delay_bound


def main() -> None:
    d = load_design("designs/antiskid-cruise-dry.toml")
    spec = d.spec
    plant = NumericAdhesion.from_dict({k: q.value for k, q in spec.params.items()})
    lin = linearise_cruise(plant, spec.v_d.value, plant.cruise_lambda(spec.v_d.value))
    synthesize_delay_bound(lin.A, lin.B, (0.35,), spec.settings)   # warm imports/caches

    t0 = time.perf_counter()
    rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
    built_once = time.perf_counter() - t0
    solves = sum(r.solves for r in rows)

    T = balancing(lin.A)
    Ti = np.diag(1 / np.diag(T))
    At, Bt = Ti @ lin.A @ T, Ti @ lin.B
    t0 = time.perf_counter()
    solves_rb, guess, hs = 0, None, []
    for eps in spec.eps:
        def decide(h, eps=eps):
            return FreeWeighting003(At, Bt, eps, margin=spec.settings.margin).solve_at(h)
        br = bisect_delay(decide, h_lo=spec.settings.h_min, h_hi=spec.settings.h_max,
                          rel_tol=spec.settings.rel_tol, guess=guess)
        guess = br.h_certified or guess
        solves_rb += br.solves
        hs.append(br.h_certified)
    rebuilt = time.perf_counter() - t0

    same = all(abs(a - r.h_certified) <= 1e-12 for a, r in zip(hs, rows))
    print("paper 003 problem (60), 5-eps sweep (dry, v_d = 70 m/s)")
    print(f"  built once (DPP): {built_once:7.3f} s  {solves:4d} solves  "
          f"{1e3 * built_once / solves:6.2f} ms/solve   target < 0.5 s: "
          f"{'met' if built_once < 0.5 else 'NOT met'}")
    print(f"  rebuilt per step: {rebuilt:7.3f} s  {solves_rb:4d} solves  "
          f"{1e3 * rebuilt / solves_rb:6.2f} ms/solve")
    print(f"  ratio rebuilt / built once: {rebuilt / built_once:5.2f}x   "
          f"same bounds: {same}")


if __name__ == "__main__":
    main()
