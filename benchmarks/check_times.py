"""Per-study time of `workbench check`, before and after, in one run.

Before: ``workbench check --jobs 1`` (every study in one process, as `make
test` ran it until issue 36). After: ``workbench check --jobs N`` (N = the
CPUs granted; a pool of N processes, each study with its report check in one
task). Both run here, one after the other, on the same tree; the script
prints each one's per-study table (wall and CPU seconds), the wall time of
each whole check and their ratio. The CPU seconds are the figure to compare
on a loaded machine; the wall times are the ones a developer waits for.

Usage: ``python benchmarks/check_times.py [--jobs N]``
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
WB = [sys.executable, "-m", "workbench"]


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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=len(os.sched_getaffinity(0)))
    args = ap.parse_args()
    print(f"machine: {os.cpu_count()} CPUs, {len(os.sched_getaffinity(0))} granted; "
          f"load average {os.getloadavg()[0]:.1f} at start")
    results = {}
    for jobs in (1, args.jobs):
        wall, cpu, table = run_check(jobs)
        results[jobs] = (wall, cpu)
        print(f"\n== workbench check --jobs {jobs}: {wall:.1f} s wall, {cpu:.1f} s CPU")
        print(table.strip())
    (w1, c1), (wn, cn) = results[1], results[args.jobs]
    print(f"\nwall: {w1:.1f} s -> {wn:.1f} s (x {w1 / wn:.2f} faster); "
          f"CPU: {c1:.1f} s -> {cn:.1f} s")


if __name__ == "__main__":
    main()
