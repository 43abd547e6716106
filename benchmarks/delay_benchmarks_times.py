"""Delay-benchmarks study time per example, before and after, in one run (issue 36, item 4).

Runs :func:`workbench.benchmark.run_example` for every example of a
delay-benchmark design (default ``designs/delay-benchmarks.toml``) in two
fresh processes: one on the old path, selected by
``WORKBENCH_BENCHMARK_UNSHARED=1`` (a new criterion, hence a new cvxpy
compilation, for every point search, interval search and settled interval
end; every Bessel-Legendre order's interval searched), and one on the
current path (each criterion and interval LMI of an example compiled once,
later uses are forks with a solver state of their own:
:class:`workbench.benchmark_windows.Compiled`; order N + 1's interval not
searched when order N's already fills the one exact window on the printed
grid: :func:`workbench.benchmark_windows.implies_next`). Prints the CPU
seconds per example and in total, the number of cvxpy compilations, solves
and interval searches implied, and whether both paths gave the same results:
every field of ``--json`` except the seconds and the interval solve counts
(they must: each solve made is the one a new criterion would make, and an
implied row is the row a search gives). Nothing here asserts a time.

Usage::

    python benchmarks/delay_benchmarks_times.py [designs/X.toml] [--examples a,b]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Environment of the old code path (module docstring).
BEFORE_ENV = {"WORKBENCH_BENCHMARK_UNSHARED": "1"}


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def worker(path: str, names: list[str]) -> None:
    """Time every example in this process; one JSON line."""
    from cvxpy.reductions.chain import Chain

    from workbench.benchmark import BenchmarkResult, run_example
    from workbench.design import load_design
    compiles = [0]
    apply = Chain.apply

    def counted(self, *a, **k):            # one cvxpy compilation per call
        compiles[0] += 1
        return apply(self, *a, **k)
    Chain.apply = counted
    spec = load_design(path).spec
    times, results = {}, []
    for ex in spec.examples:
        if names and ex.name not in names:
            continue
        c0 = _cpu()
        results.append(run_example(ex, spec.settings))
        times[ex.name] = _cpu() - c0
    data = BenchmarkResult(spec.settings, tuple(results)).to_json()
    solves, implied = 0, 0
    for e in data["examples"]:
        for m in e["methods"]:
            m.pop("seconds")
            solves += m["solves"] + m["interval_solves"]
            implied += m["interval_solves"] == 0 and m["certified_interval"] is not None \
                and m["method"] == "bessel-legendre" and m["N"] > 0
            m.pop("interval_solves")
    print(json.dumps({"times": times, "compiles": compiles[0], "solves": solves,
                      "implied": implied,
                      "result": json.dumps(data, sort_keys=True)}), flush=True)


def run(path: str, names: list[str], env_extra: dict) -> dict:
    env = {**os.environ, **env_extra}
    cmd = [sys.executable, __file__, "--worker", path] + (["--examples", ",".join(names)]
                                                         if names else [])
    p = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    if p.returncode:
        sys.exit(f"worker exited {p.returncode}:\n{p.stderr[-3000:]}")
    return json.loads([line for line in p.stdout.splitlines() if line.startswith("{")][-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/delay-benchmarks.toml")
    ap.add_argument("--examples", default="", help="comma-separated example names (default all)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    names = [n for n in args.examples.split(",") if n]
    if args.worker:
        worker(args.design, names)
        return
    print(f"machine: {os.cpu_count()} CPUs, {len(os.sched_getaffinity(0))} granted; "
          f"load average {os.getloadavg()[0]:.1f} at start")
    old = run(args.design, names, BEFORE_ENV)
    new = run(args.design, names, {})
    print("| example | before CPU s | after CPU s | after / before |")
    print("| :--- | ---: | ---: | ---: |")
    for name, t in old["times"].items():
        u = new["times"][name]
        print(f"| {name} | {t:.1f} | {u:.1f} | {u / t:.2f} |")
    t, u = sum(old["times"].values()), sum(new["times"].values())
    print(f"| total | {t:.1f} | {u:.1f} | {u / t:.2f} |")
    print(f"\ncvxpy compilations: {old['compiles']} before, {new['compiles']} after; "
          f"solves: {old['solves']} before, {new['solves']} after; Bessel-Legendre interval "
          f"searches implied by the order below: {old['implied']} before, {new['implied']} after")
    print(f"same results on both paths (every --json field but seconds and interval_solves): "
          f"{old['result'] == new['result']}")


if __name__ == "__main__":
    main()
