"""``workbench synthesize delay-bound`` time, before and after, in one run (issue 36, item 4).

Times :func:`workbench.synthesis.synthesize_delay_bound` for a design's eps
sweep (default ``designs/antiskid-cruise-dry.toml``, the issue's headline
command) in two fresh processes: one on the old path, selected by
``WORKBENCH_SYNTH_UNSHARED=1`` (a new fixed-gain LMI, hence a new cvxpy
compilation, for the canonical gain of every eps), and one on the current
path (one fixed-gain LMI with the gain and eps as parameters, shared across
the sweep). Each process runs the sweep ``--repeat`` times after one warm-up
(imports and first compilations excluded, as in a long-running session) and
prints the best CPU and wall seconds, the solve count, and whether the two
paths printed the same table (they must: only the compiled problem is
reused). Nothing here asserts a time.

Then where the time of the command goes (issue 36: target 0.5 s): the CPU
seconds of the whole command ``workbench synthesize delay-bound`` in a
fresh process (imports included) against the imports alone, and the best
sweep split into the cvxpy compilations, the parameter-to-data step of each
solve, Clarabel (``solve_via_data``), cvxpy's unpacking of the solution
(primal and dual values) and the rest (re-checks, exact margins).

Usage::

    python benchmarks/synthesize_times.py [designs/X.toml] [--repeat N]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: Environment of the old code path (module docstring).
BEFORE_ENV = {"WORKBENCH_SYNTH_UNSHARED": "1"}


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


#: Functions timed in the sweep's split: (module, class, attribute, label).
SPLIT = (("cvxpy.reductions.chain", "Chain", "apply", "compile"),
         ("cvxpy.problems.problem", "Problem", "get_problem_data", "data"),
         ("cvxpy.reductions.solvers.conic_solvers.clarabel_conif", "CLARABEL", "solve_via_data",
          "clarabel"),
         ("cvxpy.problems.problem", "Problem", "unpack_results", "unpack"))


def _timed(split: dict) -> None:
    """Wrap the functions of :data:`SPLIT` to add their CPU seconds to ``split``."""
    import importlib
    for mod, cls, attr, label in SPLIT:
        owner = getattr(importlib.import_module(mod), cls)
        f = getattr(owner, attr)

        def g(*a, _f=f, _label=label, **k):
            c0 = _cpu()
            try:
                return _f(*a, **k)
            finally:
                split[_label] = split.get(_label, 0.0) + _cpu() - c0
        setattr(owner, attr, g)


def worker(path: str, repeat: int) -> None:
    """Time the sweep in this process; one JSON line."""
    split: dict = {}
    _timed(split)
    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_cruise
    from workbench.synthesis import synthesize_delay_bound
    spec = load_design(path).spec
    lin = antiskid_cruise.operating_point(spec)[3]
    c0, w0 = _cpu(), time.perf_counter()
    rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
    first = (_cpu() - c0, time.perf_counter() - w0)
    cpu, wall, splits = [], [], []
    for _ in range(repeat):
        split.clear()
        c0, w0 = _cpu(), time.perf_counter()
        rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
        cpu.append(_cpu() - c0)
        wall.append(time.perf_counter() - w0)
        splits.append(dict(split))
    table = [(r.eps, r.h_certified, r.h_refuted, r.K, r.status.value) for r in rows]
    best = splits[cpu.index(min(cpu))]
    best["data"] = best.get("data", 0.0) - best.get("compile", 0.0)  # compile runs inside it
    best["other"] = min(cpu) - sum(best.values())
    print(json.dumps({"first_cpu": first[0], "first_wall": first[1], "cpu": min(cpu),
                      "wall": min(wall), "solves": sum(r.solves for r in rows),
                      "split": best, "table": repr(table)}), flush=True)


def command_cpu(args: list[str]) -> float:
    """CPU seconds (user + system) of a fresh Python process running ``args``."""
    before = os.times()
    subprocess.run([sys.executable] + args, cwd=ROOT, capture_output=True, check=True)
    after = os.times()
    return (after.children_user - before.children_user
            + after.children_system - before.children_system)


def run(path: str, repeat: int, env_extra: dict) -> dict:
    env = {**os.environ, **env_extra}
    p = subprocess.run([sys.executable, __file__, "--worker", path, "--repeat", str(repeat)],
                       cwd=ROOT, env=env, capture_output=True, text=True)
    if p.returncode:
        sys.exit(f"worker exited {p.returncode}:\n{p.stderr[-3000:]}")
    return json.loads([line for line in p.stdout.splitlines() if line.startswith("{")][-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/antiskid-cruise-dry.toml")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.design, args.repeat)
        return
    print(f"machine: {os.cpu_count()} CPUs, {len(os.sched_getaffinity(0))} granted; "
          f"load average {os.getloadavg()[0]:.1f} at start")
    old, new = run(args.design, args.repeat, BEFORE_ENV), run(args.design, args.repeat, {})
    print("| path | first sweep CPU s | best sweep CPU s | best wall s | solves |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, r in (("before (WORKBENCH_SYNTH_UNSHARED=1)", old), ("after", new)):
        print(f"| {name} | {r['first_cpu']:.2f} | {r['cpu']:.2f} | {r['wall']:.2f} | "
              f"{r['solves']} |")
    print(f"\nsame table on both paths: {old['table'] == new['table']}")
    imports = ("import workbench.cli, workbench.synthesis, workbench.papers.p003.antiskid_cruise, "
               "workbench.kinds.delay_feedback.cli, workbench.margins, control, cvxpy")
    whole = command_cpu(["-m", "workbench", "synthesize", "delay-bound", args.design])
    bare = command_cpu(["-c", imports])
    print(f"\nwhole command in a fresh process: {whole:.2f} CPU s, of which the imports "
          f"{bare:.2f} (cvxpy, python-control with matplotlib, sympy for the adhesion model)")
    parts = " | ".join(f"{k} {v:.2f}" for k, v in new["split"].items())
    print(f"best sweep after, CPU s: {parts} (total {new['cpu']:.2f}; {new['solves']} solves)")


if __name__ == "__main__":
    main()
