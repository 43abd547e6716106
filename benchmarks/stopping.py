"""Benchmark: paper 000's station-stop study (issue 7).

Prints the wall time of the full 7-section x 3-controller x REPEATS study run
as one batched simulation, and, as a baseline in the same process, the same
study run one section at a time (7 batches); checks both give the same stop
errors. Target: the batched study under 2 minutes on 2 cores.
"""
from __future__ import annotations

import sys
import time
from dataclasses import replace

import numpy as np

from workbench.design import load_design
from workbench.papers.p000.station_stopping_run import run_station_stops
from workbench.papers.p000.station_stopping_spec import CONTROLLERS

REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 50


def main() -> None:
    spec = replace(load_design("designs/stopping-line5.toml").spec, repeats=REPEATS)
    run_station_stops(replace(spec, repeats=2), extras=False)    # warm lambdify caches
    n = len(spec.sections) * len(CONTROLLERS) * REPEATS

    t0 = time.perf_counter()
    batched = run_station_stops(spec, extras=False)
    t_batched = time.perf_counter() - t0
    t0 = time.perf_counter()
    per_section = run_station_stops(spec, batch="per-section", extras=False)
    t_sections = time.perf_counter() - t0

    same = all(np.allclose(batched.stats[k].errors, per_section.stats[k].errors, atol=1e-9)
               for k in batched.stats)
    print(f"paper 000 station stops: {len(spec.sections)} sections x {len(CONTROLLERS)} "
          f"controllers x {REPEATS} repeats = {n} runs (dt {spec.dt} s)")
    print(f"  batched (one simulation)      {t_batched:8.2f} s   {1e3 * t_batched / n:7.2f} ms/run")
    print(f"  baseline (one per section)    {t_sections:8.2f} s   {1e3 * t_sections / n:7.2f} ms/run")
    print(f"  speed-up {t_sections / t_batched:.2f}x; identical stop errors: {same}; "
          f"target < 120 s: {'met' if t_batched < 120 else 'MISSED'}")
    print("  mean |stop error| (cm): " + ", ".join(
        f"{c} {batched.overall(c):.1f}" for c in CONTROLLERS))


if __name__ == "__main__":
    main()
