"""Sampled-data implementation certificates (issue 34) on systems from the literature.

For each loop x' = A x + B u, u = K x(t_k) (ZOH): the certified aperiodic bound
of :mod:`workbench.lmi.sampled` (one quadratic Lyapunov function for every
lifted map, re-checked over the continuum of intervals), the input-delay
certificate (:func:`workbench.lmi.varying.certified_varying_delay`, the loop as
x' = A x + B K x(t - d(t)), d(t) in [0, T_max]), the exact first unstable
constant period (spectral radius of the lifted map), and the published
values with their sources; then the time of each.

Published values: only numbers whose source is named are printed; where a
value is quoted from issue 34's text rather than re-read from the paper, the
source says so.

Usage: .venv/bin/python benchmarks/sampled.py
"""
from __future__ import annotations

import math
import time

import numpy as np

from workbench.digital import implementation
from workbench.lmi.sampled import certified_sampling_bound
from workbench.lmi.varying import certified_varying_delay
from workbench.margins.sampled import periodic_stable_set

SYSTEMS = [
    ("standard example (Zhang, Branicky & Phillips 2001)",
     np.array([[0.0, 1.0], [0.0, -0.1]]), np.array([[0.0], [0.1]]), -np.array([[3.75, 11.5]]),
     "exact periodic ~1.73 (issue 34); input-delay approach 0.869 (Fridman, Seuret & Richard "
     "2004, as quoted in issue 34); looped functionals / Bessel-Legendre ~1.72 (Seuret 2012 and "
     "successors, as quoted in issue 34)"),
    ("first-order plant x' = x + u, u = -2x (Astrom & Wittenmark 1997, sec. 2.3 closed form)",
     np.array([[1.0]]), np.array([[1.0]]), np.array([[-2.0]]),
     f"exact: |2 - e^T| < 1 iff T < ln 3 = {math.log(3):.5f} (closed form; in 1-D a quadratic "
     "function is exact, so the aperiodic bound is also ln 3)"),
    ("double integrator x'' = u, u = -x - 2x' (PD state feedback, Astrom & Wittenmark 1997 "
     "ch. 4 plant)",
     np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), np.array([[-1.0, -2.0]]),
     "— (no published value re-read; the exact periodic bound is the reference)"),
    ("Hetel, Daafouz & Iung (2006) example, nominal (g1 = g2 = 0)",
     np.array([[1.0, 0.5], [0.0, -1.0]]), np.array([[1.0], [-1.0]]),
     -np.array([[2.6884, 0.8372]]),
     "— (published bounds are for the uncertain polytope; not re-read here)"),
]


def _floor(x: float, sig: int) -> str:
    """A certified (lower) bound rounded down to ``sig`` significant digits."""
    if not (x > 0 and math.isfinite(x)):
        return str(x)
    q = 10.0 ** (math.floor(math.log10(x)) - (sig - 1))
    return f"{math.floor(x / q) * q:.{max(sig - 1 - math.floor(math.log10(x)), 0)}f}"


def main() -> None:
    print("| system | certified T_max, lifted (s) | certified T_max, input-delay (s) | "
          "exact first unstable T (s) | ratio | jitter counterexample | published | "
          "seconds (lifted, input-delay, exact) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, A, B, K, published in SYSTEMS:
        t0 = time.perf_counter()
        sb = certified_sampling_bound(A, B, K, rel_tol=1e-5)
        t1 = time.perf_counter()
        vb = certified_varying_delay(A, B @ K, mu=None, windows="fixed", rel_tol=1e-4)
        t2 = time.perf_counter()
        top = 3.0 * sb.T_certified
        ps = periodic_stable_set(A, B, K, T_max=top, grid=300)
        t3 = time.perf_counter()
        res = implementation(A, K, B=B)
        jit = ("none" if res.jitter is None
               else f"T1 = {res.jitter[0]:.4g}, T2 = {res.jitter[1]:.4g}")
        first = ps.first_unstable
        ratio = sb.T_certified / first if math.isfinite(first) else float("nan")
        print(f"| {name} | {_floor(sb.T_certified, 5)} | {_floor(vb.h2, 3)} | {first:.6f} | "
              f"{_floor(ratio, 4)} | "
              f"{jit} | {published} | {t1 - t0:.1f}, {t2 - t1:.1f}, {t3 - t2:.1f} |")
    A, B, K = SYSTEMS[0][1:4]
    print("\nStandard example with a network delay tau (input-delay certificate over every "
          "tau_k in [0, tau]; exact first unstable period at the constant delays 0 and tau):\n")
    print("| tau (s) | certified T_max (s) | exact first unstable T (s) | seconds |")
    print("| --- | --- | --- | --- |")
    for tau in (0.1, 0.2, 0.4):
        t0 = time.perf_counter()
        r = implementation(A, K, B=B, network_delay=(0.0, tau))
        print(f"| {tau:g} | {_floor(r.T_certified, 3)} | {r.first_unstable:.4f} | "
              f"{time.perf_counter() - t0:.1f} |")
    cruise()


def cruise() -> None:
    """Paper 003's cruise loop: certified lowest rate on the linearisation next to the
    simulated lowest rate of the nonlinear laws (issue 20, reports/antiskid-run-dry.md)."""
    from workbench.design import load_design
    from workbench.features.sampled import published_row_sampling
    from workbench.papers.p003.antiskid_cruise import operating_point
    print("\nPaper 003 cruise loop, linearisation of designs/antiskid-cruise-dry.toml with the "
          "printed Table 3 gain (eps = 0.35):\n")
    print("| implementation | certified T_max (s) | certified lowest rate (Hz) | "
          "exact first unstable T (s) | simulated lowest rate, nonlinear laws (issue 20) | "
          "seconds |")
    print("| --- | --- | --- | --- | --- | --- |")
    t0 = time.perf_counter()
    spec = load_design("designs/antiskid-cruise-dry.toml").spec
    lin = operating_point(spec)[3]
    c = published_row_sampling(lin.A, lin.B, spec.sweep.published, 0.35, 0.002)
    sec = time.perf_counter() - t0
    for label, r, sim in (
            ("predictor (exact prediction: delay-free sampled loop)", c.predictor,
             "25 Hz (ZOH; bisected 23 fails / 25 meets)"),
            (f"no predictor, delay {c.h:g} + {c.measurement_delay:g} s", c.delayed,
             "55 Hz (ZOH, 8 N m quantisation, 2 ms measurement delay; 52 fails / 55 meets)")):
        cap = " (search cap)" if r.at_cap else ""
        rate = 1.0 / r.T_certified
        print(f"| {label} | >= {_floor(r.T_certified, 3)}{cap} | <= {rate:.3g} | "
              f"{r.first_unstable:.4g} | {sim} | {sec / 2:.1f} |")
    print("\nThe simulated rates come from the nonlinear run (traction from rest, braking entry "
          "with law 69), which the linearisation at cruise does not see.")


if __name__ == "__main__":
    main()
