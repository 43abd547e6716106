"""Per-part time of one antiskid-run design, first and second process (issue 36, item 4).

Runs the parts of the design's study (:class:`workbench.papers.p003.antiskid_run.AntiskidRun`)
one after the other in a child process, twice, with the same new (empty)
numba disk cache (:mod:`workbench.sim.jit_cache`): the first process compiles
the kernels and writes them, the second loads them. Parts, each its CPU and
wall seconds:

* ``compile``: the Monte Carlo kernel (:func:`~workbench.papers.p003.antiskid_kernel.compile_kernel`)
  and the sampled-data loop (its first call, a run cut at t = 0);
* ``cases``: the scalar case runs (4 cases x dt, dt/2, ``AntiskidRun._cases``);
* ``linear``, ``sampled``, ``basin``: the linear checks, the ``[sampled]``
  section, the basin;
* ``montecarlo``: the sweep and the step-halving check, in this process
  (one core; ``workbench verify`` runs them in a pool meanwhile).

The CPU seconds are the figure to compare on a loaded machine; nothing here
asserts a time.

Usage::

    python benchmarks/antiskid_run_times.py [designs/antiskid-run-dry.toml] [--cache DIR]

``--cache DIR`` uses (and keeps) DIR as the cache instead of a new temporary one.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PARTS = ("import", "compile", "cases", "linear", "sampled", "basin", "montecarlo")


def _cpu() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def worker(path: str) -> None:
    """Time each part of the design's study in this process; one JSON line."""
    times = {}
    c0, w0 = _cpu(), time.perf_counter()

    def lap(name):
        nonlocal c0, w0
        c, w = _cpu(), time.perf_counter()
        times[name] = (c - c0, w - w0)
        c0, w0 = c, w

    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_sampled_kernel as S
    from workbench.papers.p003.antiskid_basin_run import run_basin
    from workbench.papers.p003.antiskid_halving import start_halving
    from workbench.papers.p003.antiskid_kernel import compile_kernel
    from workbench.papers.p003.antiskid_montecarlo import start_sweep
    from workbench.papers.p003.antiskid_run import STUDY, linear_check
    from workbench.papers.p003.antiskid_run_spec import (controller_settings, gain_for,
                                                         nominal_cruise, plant_values,
                                                         sampled_context)
    from workbench.papers.p003.antiskid_sampled import run_sampled
    design = load_design(path)
    spec = design.spec
    nominal, _, lin = nominal_cruise(spec)
    K = gain_for(spec)[0]
    lap("import")
    compile_kernel()
    if spec.sampled is not None:
        S.run_once(sampled_context(spec, K), 1000.0, S.BRAKING_SCENARIO, dt_p=spec.dt,
                   t_cap=0.0)
    lap("compile")
    cases = STUDY._cases(spec, K)
    lap("cases")
    linear_check(spec, lin.A, lin.B, K)
    lap("linear")
    if spec.sampled is not None:
        run_sampled(spec.sampled, sampled_context(spec, K), spec.dt)
    lap("sampled")
    if spec.basin is not None:
        run_basin(spec.basin, plant_values(spec), spec.scenario["v_d"], K,
                  nominal.lambda_opt(), cases, spec.mass_factor,
                  profile=controller_settings(spec, K, spec.cases[0]).profile, k_de=spec.k_de)
    lap("basin")
    ms = spec.montecarlo
    if ms is not None:
        mc = start_sweep(design, ms.samples, ms.seed, workers=1, chunk=ms.chunk, pool=False,
                         K=K).result()
        if ms.halving:
            start_halving(design, ms.halving, K=K, pool=False, coarse=False).result()(mc)
    lap("montecarlo")
    print(json.dumps(times))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/antiskid-run-dry.toml")
    ap.add_argument("--cache", help="numba cache directory (default: a new temporary one)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        worker(a.design)
        return
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, WORKBENCH_CACHE_DIR=a.cache or tmp, OPENBLAS_NUM_THREADS="1")
        env.pop("WORKBENCH_NUMBA_CACHE", None)
        runs = []
        for which in ("first", "second"):
            out = subprocess.run([sys.executable, __file__, a.design, "--worker"], env=env,
                                 cwd=ROOT, check=True, capture_output=True, text=True).stdout
            runs.append(json.loads(out.strip().splitlines()[-1]))
            print(f"{which} process done", file=sys.stderr, flush=True)
    print(f"{a.design}: CPU s (wall s) per part; load average {os.getloadavg()[0]:.1f}")
    print(f"| part | first process | second process |\n| :--- | ---: | ---: |")
    for p in (*PARTS, "total"):
        cells = []
        for r in runs:
            c, w = (sum(v[i] for v in r.values()) for i in (0, 1)) if p == "total" else r[p]
            cells.append(f"{c:.1f} ({w:.1f})")
        print(f"| {p} | {cells[0]} | {cells[1]} |")


if __name__ == "__main__":
    main()
