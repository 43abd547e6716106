"""Benchmark: paper 000's per-section station stops (issue 7), through the
``stop-accuracy`` kind (designs/stopping-line5.toml).

Prints the wall time of the 7-section x 4-controller x REPEATS repeats run
as one batched simulation, and, as a baseline in the same process, the same
repeats run one controller at a time (4 batches, the same draws); checks both
give the same stop errors. Target: the batched repeats under 2 minutes on 2 cores.
"""
from __future__ import annotations

import sys
import time
from dataclasses import replace

import numpy as np

from workbench.design import load_design
from workbench.kinds.stop_accuracy.run import compile_laws, run_sections

REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 50


def main() -> None:
    spec = load_design("designs/stopping-line5.toml").spec
    spec = replace(spec, sections=replace(spec.sections, count=REPEATS))
    laws = compile_laws(spec)
    ctls = spec.sections.controllers
    ns = len(spec.sections.sections)
    run_sections(replace(spec, sections=replace(spec.sections, count=2)), laws, spec.dt)  # warm
    n = ns * len(ctls) * REPEATS

    t0 = time.perf_counter()
    batched = run_sections(spec, laws, spec.dt)
    t_batched = time.perf_counter() - t0
    t0 = time.perf_counter()
    alone = {}
    for c in ctls:
        alone |= run_sections(replace(spec, sections=replace(spec.sections, controllers=(c,))),
                              laws, spec.dt)
    t_alone = time.perf_counter() - t0

    same = all(np.allclose(batched[k].errors, alone[k].errors, atol=1e-9) for k in batched)
    print(f"paper 000 station stops: {ns} sections x {len(ctls)} controllers x {REPEATS} "
          f"repeats = {n} runs (dt {spec.dt} s)")
    print(f"  batched (one simulation)      {t_batched:8.2f} s   {1e3 * t_batched / n:7.2f} ms/run")
    print(f"  baseline (one per controller) {t_alone:8.2f} s   {1e3 * t_alone / n:7.2f} ms/run")
    print(f"  speed-up {t_alone / t_batched:.2f}x; identical stop errors: {same}; "
          f"target < 120 s: {'met' if t_batched < 120 else 'MISSED'}")
    print("  mean |stop error| (cm): " + ", ".join(
        f"{c} {np.mean([batched[i, c].mean_abs for i in range(ns)]):.1f}" for c in ctls))


if __name__ == "__main__":
    main()
