"""Per-study time, before and after, in one run (issue 36, items 4 and 6).

Default: every shipped design's study (``designs/*.toml``), one after the
other in ONE process (as a ``workbench check`` worker runs them), and a
table of each study's wall and CPU seconds (the CPU of the Monte Carlo
worker processes included). With ``--before``, the same studies run first in
a second process on the old code paths that a switch still selects, and the
table gives both and their ratio:

* ``WORKBENCH_BASIN_EAGER=1``: the basin k2 sweep computes every certificate
  (Taylor ball and box cover) as before, instead of only those whose value can
  change a verdict or a fate, and the cruise basin covers every weight of its
  grid, instead of only those whose falsifier bound can beat the best score
  (the coarse pass; :mod:`workbench.papers.p003.antiskid_basin`).

With ``--cold``, each process starts on an empty disk cache of the compiled
kernels (``WORKBENCH_CACHE_DIR``: numba compiles them, as on a fresh clone).
Each study's row is also printed to stderr as soon as it is done.

The CPU seconds are the figure to compare on a loaded machine; nothing here
asserts a time. ``--check [--jobs N]`` instead times ``workbench check
--jobs 1`` against ``--jobs N`` (the pool of issue 36, item 3).

Usage::

    python benchmarks/check_times.py [--before] [--cold] [designs/X.toml ...]
    python benchmarks/check_times.py --check [--jobs N]
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
WB = [sys.executable, "-m", "workbench"]
#: Environment of the old code paths (module docstring).
BEFORE_ENV = {"WORKBENCH_BASIN_EAGER": "1"}
#: --cold: every process on an empty kernel cache.
COLD = False


def _cpu() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def worker(paths: list[str]) -> None:
    """Run each design's study in this process; one JSON line per study."""
    from workbench import memo
    from workbench.design import load_design
    from workbench.plants.lambdify_cache import cache_info
    from workbench.verify import evaluate_design
    for p in paths:
        d = load_design(p)
        w0, c0 = time.perf_counter(), _cpu()
        ev = evaluate_design(d)
        wall, cpu = time.perf_counter() - w0, _cpu() - c0
        print(json.dumps({"design": d.name, "kind": d.kind, "wall": wall, "cpu": cpu,
                          "claims_ok": ev.ok, "lambdify": cache_info()}), flush=True)
        memo.clear()


def run_studies(paths: list[str], env_extra: dict) -> dict:
    """{design: row} of a worker process (no run folder: every study computed)."""
    env = {k: v for k, v in os.environ.items() if k != "WORKBENCH_STUDY_CACHE"}
    env.update(env_extra)
    rows = []
    with tempfile.TemporaryDirectory(prefix="numba-cold-") as cold:
        if COLD:
            env["WORKBENCH_CACHE_DIR"] = cold
        with subprocess.Popen([sys.executable, __file__, "--worker", *paths], cwd=ROOT,
                              env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) as p:
            for line in p.stdout:
                if line.startswith("{"):
                    rows.append(json.loads(line))
                    r = rows[-1]
                    print(f"  {'before' if env_extra else 'after'}: {r['design']} "
                          f"{r['wall']:.1f} s wall, {r['cpu']:.1f} s CPU", file=sys.stderr,
                          flush=True)
            err = p.stderr.read()
    if p.returncode:
        sys.exit(f"worker exited {p.returncode}:\n{err[-3000:]}")
    return {r["design"]: r for r in rows}


def studies_table(paths: list[str], before: bool) -> None:
    """Print the per-study table (module docstring)."""
    old = run_studies(paths, BEFORE_ENV) if before else {}
    new = run_studies(paths, {})
    head = "| design | kind | wall s | CPU s |"
    if before:
        head += " wall s before | CPU s before | CPU before / after |"
    print(head)
    print("|" + " --- |" * (head.count("|") - 1))
    tot = [0.0, 0.0, 0.0, 0.0]
    for name, r in new.items():
        line = f"| {name} | {r['kind']} | {r['wall']:.1f} | {r['cpu']:.1f} |"
        tot[0] += r["wall"]
        tot[1] += r["cpu"]
        if before and name in old:
            o = old[name]
            tot[2] += o["wall"]
            tot[3] += o["cpu"]
            line += f" {o['wall']:.1f} | {o['cpu']:.1f} | {o['cpu'] / max(r['cpu'], 1e-9):.2f} |"
        print(line)
    line = f"| total | | {tot[0]:.1f} | {tot[1]:.1f} |"
    if before:
        line += f" {tot[2]:.1f} | {tot[3]:.1f} | {tot[3] / max(tot[1], 1e-9):.2f} |"
    print(line)
    last = list(new.values())[-1]["lambdify"] if new else {}
    print(f"\nlambdify cache at the end of the run: {last}")


def run_check(jobs: int) -> tuple[float, float, str]:
    """(wall s, CPU s of the process tree, the check's timing table)."""
    t0, c0 = time.perf_counter(), os.times()
    p = subprocess.run(WB + ["check", "--jobs", str(jobs)], cwd=ROOT, capture_output=True,
                       text=True)
    c1 = os.times()
    cpu = (c1.children_user + c1.children_system) - (c0.children_user + c0.children_system)
    table = p.stderr[p.stderr.rfind("\nper-"):] if "\nper-" in p.stderr else p.stderr[-3000:]
    if p.returncode not in (0, 1):
        sys.exit(f"workbench check --jobs {jobs} exited {p.returncode}:\n{p.stderr[-2000:]}")
    return time.perf_counter() - t0, cpu, table


def check_table(jobs: int) -> None:
    """``workbench check --jobs 1`` against ``--jobs N``."""
    results = {}
    for j in (1, jobs):
        wall, cpu, table = run_check(j)
        results[j] = (wall, cpu)
        print(f"\n== workbench check --jobs {j}: {wall:.1f} s wall, {cpu:.1f} s CPU")
        print(table.strip())
    (w1, c1), (wn, cn) = results[1], results[jobs]
    print(f"\nwall: {w1:.1f} s -> {wn:.1f} s (x {w1 / wn:.2f} faster); "
          f"CPU: {c1:.1f} s -> {cn:.1f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("designs", nargs="*", help="design files (default: designs/*.toml)")
    ap.add_argument("--before", action="store_true", help="also time the old code paths")
    ap.add_argument("--check", action="store_true", help="time workbench check --jobs 1 and N")
    ap.add_argument("--jobs", type=int, default=len(os.sched_getaffinity(0)))
    ap.add_argument("--cold", action="store_true",
                    help="each process on an empty compiled-kernel cache (a fresh clone)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    global COLD
    COLD = args.cold
    if args.worker:
        worker(args.designs)
        return
    print(f"machine: {os.cpu_count()} CPUs, {len(os.sched_getaffinity(0))} granted; "
          f"load average {os.getloadavg()[0]:.1f} at start")
    if args.check:
        check_table(args.jobs)
        return
    paths = args.designs or sorted(str(p) for p in (ROOT / "designs").glob("*.toml"))
    studies_table([str(Path(p).resolve()) for p in paths], args.before)


if __name__ == "__main__":
    main()
