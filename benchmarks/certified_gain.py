"""Issue 31 items 3 and 5: the cost of certifying the returned gain, and of the diagnosis.

Prints, for the API's Wirtinger synthesis of x' = 0.5 x + 2 u(t - h) and
x' = 3 x + u(t - h): the synthesis LMI's bound (unrounded solver gain), the
bound of the returned, rounded K (the same LMI with K fixed: one bisection
started from the design delay), the exact margin of that K, and the solves
and seconds of each part. Then the exact PBH diagnosis of x1' = x1,
x2' = -x2 + u (target: INFEASIBLE in under 1 s, no LMI solve) and of
random 8-state plants.

Usage: .venv/bin/python benchmarks/certified_gain.py
"""
from __future__ import annotations

import time

import numpy as np

import workbench
from workbench.lmi.diagnosis import uncontrollable_mode
from workbench.lmi.tight_synthesis import synthesize_tight
from workbench.margins import exact_margin


def main() -> None:
    print("returned gain = certified gain (Wirtinger synthesis, h_max = 10 s)")
    for a, b in ((0.5, 2.0), (3.0, 1.0)):
        A, B = np.array([[a]]), np.array([[b]])
        t0 = time.perf_counter()
        t = synthesize_tight(A, B, h_max=10.0)
        wall = time.perf_counter() - t0
        an = t.gain.analysis
        fixed_s = an.seconds
        h_star = exact_margin(A, B @ t.K).h
        print(f"  x' = {a:g} x + {b:g} u: synthesis h = {t.h_certified:.6f} s, K = {t.K[0, 0]:.4g}, "
              f"K's own h = {an.h_certified:.6f} s < exact {h_star:.6f} s: "
              f"{an.h_certified < h_star}; re-certification {an.solves} solves "
              f"{fixed_s:.3f} s of {wall:.3f} s")
    A, B = np.diag([1.0, -1.0]), np.array([[0.0], [1.0]])
    t0 = time.perf_counter()
    res = workbench.delay_bound(A, B, method="wirtinger", h_max=10)
    wall = time.perf_counter() - t0
    print(f"uncontrollable plant: status {res.status} in {wall:.3f} s "
          f"(target < 1 s: {'met' if wall < 1 else 'NOT met'}): {res.reason}")
    rng = np.random.default_rng(31)
    for n in (4, 8, 12):
        A = rng.normal(size=(n, n))
        A[n - 2:, :n - 2] = 0.0                      # an uncontrollable 2-state block
        B = np.vstack([rng.normal(size=(n - 2, 1)), np.zeros((2, 1))])
        t0 = time.perf_counter()
        d = uncontrollable_mode([(A, B)], 0.1)
        print(f"  PBH, {n} states: {time.perf_counter() - t0:.4f} s: "
              f"{'INFEASIBLE' if d else 'stabilisable'}")


if __name__ == "__main__":
    main()
