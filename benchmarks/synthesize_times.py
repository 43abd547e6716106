"""``workbench synthesize delay-bound`` time, before and after, in one run (issue 36, item 4).

Times :func:`workbench.synthesis.synthesize_delay_bound` for a design's eps
sweep (default ``designs/antiskid-cruise-dry.toml``, the issue's headline
command) on three paths, interleaved in ONE process (imports and first
compilations excluded by a warm-up, as in a long-running session):

* ``before issue 36``: ``WORKBENCH_SYNTH_UNSHARED=1`` (a new fixed-gain LMI,
  hence a new cvxpy compilation, for the canonical gain of every eps), every
  solve unpacked by cvxpy's ``Problem.solve`` (duals too:
  ``workbench.lmi.primal.FULL_UNPACK``) and every probe of the gain's
  bisection solved (``workbench.lmi.gain.IMPLIED_PROBES = False``);
* ``before synth36``: the shared fixed-gain LMI, the other two as above;
* ``before synth36b``: primal-only unpacking and the gain's probes at or
  above the synthesis's refuted delay decided without a solve, every solve
  through cvxpy's ``get_problem_data`` and ``unpack_results``
  (``workbench.lmi.primal.LEAN = False``);
* ``after``: the same with repeat solves on the lean path (the compiled
  parameter map applied directly, the values taken from Clarabel's ``x``:
  :mod:`workbench.lmi.primal`).

It prints the best CPU and wall seconds of each, the solver calls, and
whether the three paths printed the same table (they must: the same data
reach Clarabel and the bisections visit the same delays). Then where the
time of the command goes (issue 36: target 0.5 s): the CPU and wall seconds
of the whole command ``workbench synthesize delay-bound`` in a fresh process
(imports included) against the imports alone, and the best sweep after
split into the cvxpy compilations, the parameter-to-data step of each solve,
Clarabel (``solve_via_data``), cvxpy's unpacking of the solution and the
rest (re-checks, exact margins). With ``--study [DESIGN ...]`` also the CPU
and wall seconds of ``workbench verify`` of each design (default
``designs/delay-benchmarks.toml``) in fresh processes, before synth36 (full
unpacking, every gain probe solved) and after. With ``--examples NAME,...``
the delay benchmark's examples (``designs/delay-benchmarks.toml``) are run
in ONE process, cvxpy's per-solve path (``primal.LEAN = False``) and the lean
repeat solve alternated for ``--repeat`` rounds: at a high machine load two
fresh processes do not resolve a 15 % difference, the alternation does.
Nothing here asserts a time.

Usage::

    python benchmarks/synthesize_times.py [designs/X.toml] [--repeat N] [--study [DESIGN ...]]
        [--examples classic-2x2,scalar-a1-b2]
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
def _cpu() -> float:
    t = os.times()
    return t.user + t.system


#: Functions timed in the sweep's split: (module, class, attribute, label).
SPLIT = (("cvxpy.reductions.chain", "Chain", "apply", "compile"),
         ("cvxpy.problems.problem", "Problem", "get_problem_data", "data"),
         ("cvxpy.reductions.solvers.conic_solvers.clarabel_conif", "CLARABEL", "solve_via_data",
          "clarabel"),
         ("cvxpy.problems.problem", "Problem", "unpack_results", "unpack"))


def wrap(owner, attr: str, split: dict, label: str) -> None:
    """Replace ``owner.attr`` by a function adding its CPU seconds to ``split[label]``."""
    f = getattr(owner, attr)

    def g(*a, **k):
        c0 = _cpu()
        try:
            return f(*a, **k)
        finally:
            split[label] = split.get(label, 0.0) + _cpu() - c0
    setattr(owner, attr, g)


def _timed(split: dict) -> None:
    """Wrap the functions of :data:`SPLIT` to add their CPU seconds to ``split``."""
    import importlib
    for mod, cls, attr, label in SPLIT:
        wrap(getattr(importlib.import_module(mod), cls), attr, split, label)


#: The paths timed (module docstring): (name, WORKBENCH_SYNTH_UNSHARED,
#: ``primal.FULL_UNPACK``, ``gain.IMPLIED_PROBES``, ``primal.LEAN``).
PATHS = (("before issue 36 (unshared fixed-K LMI)", "1", True, False, False),
         ("before synth36", "0", True, False, False),
         ("before synth36b", "0", False, True, False),
         ("after", "0", False, True, True))


def _set_path(unshared: str, full: bool, implied: bool, lean: bool) -> None:
    from workbench.lmi import gain, primal
    os.environ["WORKBENCH_SYNTH_UNSHARED"] = unshared
    primal.FULL_UNPACK, gain.IMPLIED_PROBES, primal.LEAN = full, implied, lean


def worker(path: str, repeat: int) -> None:
    """Time the sweep on every path of :data:`PATHS` in this process; one JSON line."""
    split: dict = {}
    _timed(split)
    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_cruise
    from workbench.synthesis import synthesize_delay_bound
    spec = load_design(path).spec
    lin = antiskid_cruise.operating_point(spec)[3]
    out = {name: {"cpu": [], "wall": [], "splits": []} for name, *_ in PATHS}
    for rep in range(repeat + 1):                # the first round warms up
        for name, *flags in PATHS:
            _set_path(*flags)
            split.clear()
            c0, w0 = _cpu(), time.perf_counter()
            rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
            cpu, wall = _cpu() - c0, time.perf_counter() - w0
            r = out[name]
            r["table"] = repr([(r_.eps, r_.h_certified, r_.h_refuted, r_.K, r_.h_gain,
                                r_.status.value) for r_ in rows])
            r["solves"] = sum(r_.solves for r_ in rows)
            if rep == 0:
                r["first_cpu"], r["first_wall"] = cpu, wall
                continue
            r["cpu"].append(cpu)
            r["wall"].append(wall)
            r["splits"].append(dict(split))
    for r in out.values():
        best = r["splits"][r["cpu"].index(min(r["cpu"]))]
        best["data"] = best.get("data", 0.0) - best.get("compile", 0.0)  # compile runs inside
        best["other"] = min(r["cpu"]) - sum(best.values())
        r.update(split=best, cpu=min(r["cpu"]), wall=min(r["wall"]))
        del r["splits"]
    print(json.dumps(out), flush=True)


def examples_worker(names: str, repeat: int) -> None:
    """CPU s of ``run_example`` per example, full and lean path alternated; one JSON line."""
    from workbench import benchmark as bm
    from workbench.design import load_design
    from workbench.lmi import primal
    design = load_design("designs/delay-benchmarks.toml")
    out = {}
    for name in names.split(","):
        ex = next((e for e in design.spec.examples if e.name == name), None)
        if ex is None:
            sys.exit(f"--examples: {name!r} is not an example of designs/delay-benchmarks.toml")
        out[name] = {"full": [], "lean": []}
        for _ in range(repeat):
            for path, lean in (("full", False), ("lean", True)):
                primal.LEAN = lean
                c0 = _cpu()
                bm.run_example(ex, design.spec.settings)
                out[name][path].append(round(_cpu() - c0, 2))
    print(json.dumps(out), flush=True)


def command_times(args: list[str]) -> tuple[float, float]:
    """(CPU s as user + system, wall s) of a fresh Python process running ``args``."""
    before, w0 = os.times(), time.perf_counter()
    subprocess.run([sys.executable] + args, cwd=ROOT, capture_output=True, check=True)
    after = os.times()
    return (after.children_user - before.children_user
            + after.children_system - before.children_system), time.perf_counter() - w0


def run(path: str, repeat: int) -> dict:
    p = subprocess.run([sys.executable, __file__, "--worker", path, "--repeat", str(repeat)],
                       cwd=ROOT, capture_output=True, text=True)
    if p.returncode:
        sys.exit(f"worker exited {p.returncode}:\n{p.stderr[-3000:]}")
    return json.loads([line for line in p.stdout.splitlines() if line.startswith("{")][-1])


#: ``workbench verify`` of a design in a fresh process: (name, code) before
#: synth36 (cvxpy's full unpacking, every gain probe solved), before synth36b
#: (no lean repeat solves) and after.
VERIFY = (("before synth36", "import sys, workbench.lmi.primal as p, workbench.lmi.gain as g; "
           "p.FULL_UNPACK, g.IMPLIED_PROBES, p.LEAN = True, False, False; "
           "from workbench.cli import main; sys.exit(main(sys.argv[1:]))"),
          ("before synth36b", "import sys, workbench.lmi.primal as p; p.LEAN = False; "
           "from workbench.cli import main; sys.exit(main(sys.argv[1:]))"),
          ("after", "import sys; from workbench.cli import main; sys.exit(main(sys.argv[1:]))"))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/antiskid-cruise-dry.toml")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--study", nargs="*", metavar="DESIGN",
                    help="also time workbench verify of these designs, before and after "
                         "(default designs/delay-benchmarks.toml)")
    ap.add_argument("--skip-oldest", action="store_true",
                    help="with --study: leave out the path before synth36")
    ap.add_argument("--examples", metavar="NAME,...",
                    help="delay-benchmark examples to time in one process, full and lean "
                         "path alternated")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        if args.examples:
            examples_worker(args.examples, args.repeat)
        else:
            worker(args.design, args.repeat)
        return
    print(f"machine: {os.cpu_count()} CPUs, {len(os.sched_getaffinity(0))} granted; "
          f"load average {os.getloadavg()[0]:.1f} at start")
    res = run(args.design, args.repeat)
    print("| path | first sweep CPU s | best sweep CPU s | best wall s | solver calls |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, r in res.items():
        print(f"| {name} | {r['first_cpu']:.2f} | {r['cpu']:.2f} | {r['wall']:.2f} | "
              f"{r['solves']} |")
    tables = {r["table"] for r in res.values()}
    print(f"\nsame table on every path: {len(tables) == 1}")
    imports = ("import workbench.cli, workbench.synthesis, workbench.papers.p003.antiskid_cruise, "
               "workbench.kinds.delay_feedback.cli, workbench.margins, control, cvxpy")
    whole = command_times(["-m", "workbench", "synthesize", "delay-bound", args.design])
    bare = command_times(["-c", imports])
    print(f"\nwhole command in a fresh process: {whole[0]:.2f} CPU s ({whole[1]:.2f} s wall), "
          f"of which the imports {bare[0]:.2f} CPU s ({bare[1]:.2f} s wall) (cvxpy, "
          "python-control with matplotlib, sympy for the adhesion model)")
    new = res["after"]
    parts = " | ".join(f"{k} {v:.2f}" for k, v in new["split"].items())
    print(f"best sweep after, CPU s: {parts} (total {new['cpu']:.2f}; {new['solves']} solves)")
    if args.examples:
        p = subprocess.run([sys.executable, __file__, "--worker", "--examples", args.examples,
                            "--repeat", str(args.repeat)], cwd=ROOT, capture_output=True,
                           text=True)
        if p.returncode:
            sys.exit(f"worker exited {p.returncode}:\n{p.stderr[-3000:]}")
        res = json.loads([line for line in p.stdout.splitlines() if line.startswith("{")][-1])
        print("\n| example | cvxpy per-solve path, CPU s per round | lean, CPU s per round |")
        print("| --- | ---: | ---: |")
        for name, r in res.items():
            print(f"| {name} | {', '.join(map(str, r['full']))} | "
                  f"{', '.join(map(str, r['lean']))} |")
    if args.study is not None:
        for design in args.study or ["designs/delay-benchmarks.toml"]:
            for name, code in VERIFY[1:] if args.skip_oldest else VERIFY:
                cpu, wall = command_times(["-c", code, "verify", design])
                print(f"workbench verify {design}, {name}: {cpu:.1f} CPU s, {wall:.1f} s wall",
                      flush=True)


if __name__ == "__main__":
    main()
