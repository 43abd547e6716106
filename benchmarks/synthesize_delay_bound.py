"""``workbench synthesize delay-bound``: where the time goes, serial against
pipelined, in one run (issue 36, item 4; helper synth36c).

In ONE process (imports and the numba / first-call costs excluded by a
warm-up sweep, as in a long-running session), the design's eps sweep
(:func:`workbench.synthesis.synthesize_delay_bound`, default
``designs/antiskid-cruise-dry.toml``) alternates between

* ``serial`` (``workbench.synthesis.PIPELINE = False``, the path before
  synth36c): every eps bisected, then its canonical gain and exact margins,
  one after the other;
* ``pipelined`` (the default): the canonical gain and exact margins of each
  eps in one forked worker while this process bisects the next eps.

For each it prints the best wall seconds, the CPU seconds of this process
and of the worker (``os.times`` of the joined child), the critical path
on an idle machine estimated from CPU seconds (the pipelined sweep's
own, plus the last eps's second half, which the worker computes after the
last bisection; a loaded machine stretches wall time), and whether the rows
are the same (every printed and ``--json`` field but ``seconds``, plus the
re-check margins and certificate of each canonical gain, bit for bit). The
solves are counted per eps: the delay bisection, the minimum-norm point
(tie-break), the rounded gain's own bisection. The serial sweep is split by
timers into the cvxpy compilations, cvxpy's parameter-to-data step, Clarabel's
setup (``DefaultSolver(...)``: KKT assembly, chordal analysis) and iterations
(``solve()``), cvxpy's unpacking, the exact margins and the rest; the start
of the worker (fork), one trivial item and its shutdown are timed on their own. Then the whole
command in fresh processes, serial and pipelined, and the largest imports of
the command (``python -X importtime``). Nothing here asserts a time.

Usage::

    python benchmarks/synthesize_delay_bound.py [designs/X.toml] [--repeat N]
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from synthesize_times import ROOT, _cpu, _timed, command_times, wrap

#: The two paths timed: (name, ``workbench.synthesis.PIPELINE``).
PATHS = (("serial", False), ("pipelined", True))
#: The exact-margin functions of :mod:`workbench.synthesis` timed as one part.
MARGINS = ("delay_margin_eig", "delay_margin_siso", "stability_windows")


def _children_cpu() -> float:
    t = os.times()
    return t.children_user + t.children_system


def _clarabel_timed(split: dict) -> None:
    """Split Clarabel's time into the setup (``DefaultSolver(...)``) and the
    iterations (``solve()``); cvxpy looks ``clarabel.DefaultSolver`` up at
    every solve, and never updates a solver here (refused with chordal
    decomposition on)."""
    import clarabel
    cls = clarabel.DefaultSolver

    class Timed:
        def __init__(self, *a, **k):
            c0 = _cpu()
            self._s = cls(*a, **k)
            split["clarabel setup"] = split.get("clarabel setup", 0.0) + _cpu() - c0

        def solve(self):
            c0 = _cpu()
            try:
                return self._s.solve()
            finally:
                split["clarabel iterations"] = (split.get("clarabel iterations", 0.0)
                                                + _cpu() - c0)

        def __getattr__(self, name):
            return getattr(self._s, name)
    clarabel.DefaultSolver = Timed


def _fingerprint(rows) -> str:
    """Every JSON field but ``seconds``, the bisection's outcome letters, and
    the canonical certificate with its re-check margins (exact reprs)."""
    out = []
    for r in rows:
        j = {k: v for k, v in r.to_json().items() if k != "seconds"}
        cert = {k: v.tobytes().hex() for k, v in sorted(r.certificate.items())}
        out.append([j, r.statuses, sorted(r.recheck.items()), cert])
    return json.dumps(out, sort_keys=True, default=repr)


def _solves(rows) -> dict:
    """Solver calls per kind, summed over the eps."""
    n = {"bisection": 0, "tie-break (minimum-norm point)": 0, "gain bisection": 0}
    for r in rows:
        n["bisection"] += len(r.statuses)
        if r.gain is not None:
            n["tie-break (minimum-norm point)"] += 1
            if r.gain.analysis is not None:
                n["gain bisection"] += r.gain.analysis.solves
    n["total (SynthesisRow.solves)"] = sum(r.solves for r in rows)
    return n


def worker(path: str, repeat: int) -> None:
    """Time the sweep on both paths in this process; one JSON line."""
    from workbench import synthesis
    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_cruise
    spec = load_design(path).spec
    lin = antiskid_cruise.operating_point(spec)[3]
    split: dict = {}
    _timed(split)
    _clarabel_timed(split)
    for name in MARGINS:
        wrap(synthesis, name, split, "exact margins")
    row_cpu: list = []               # CPU s of each row's second half, in this process
    f_row = synthesis._row

    def timed_row(*a, **k):
        c0 = time.process_time()
        try:
            return f_row(*a, **k)
        finally:
            row_cpu.append(time.process_time() - c0)
    synthesis._row = timed_row
    out = {name: {"cpu": [], "child": [], "wall": [], "splits": []} for name, _ in PATHS}
    for rep in range(repeat + 1):                # the first round warms up
        for name, pipelined in PATHS:
            synthesis.PIPELINE = pipelined
            split.clear()
            row_cpu.clear()
            c0, k0, w0 = _cpu(), _children_cpu(), time.perf_counter()
            rows = synthesis.synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
            cpu, child, wall = _cpu() - c0, _children_cpu() - k0, time.perf_counter() - w0
            r = out[name]
            r["table"], r["solves"] = _fingerprint(rows), _solves(rows)
            if rep == 0:
                continue
            r["cpu"].append(cpu)
            r["child"].append(child)
            r["wall"].append(wall)
            r["splits"].append(dict(split))
            r.setdefault("last_row", []).append(row_cpu[-1] if row_cpu else 0.0)
    for r in out.values():
        i = r["wall"].index(min(r["wall"]))
        best = r["splits"][i]
        best["data"] = best.get("data", 0.0) - best.get("compile", 0.0)  # compile runs inside
        clar = best.pop("clarabel", 0.0)       # cvxpy's solve_via_data, around setup + iterations
        best["clarabel interface"] = clar - best.get("clarabel setup", 0.0) - best.get(
            "clarabel iterations", 0.0)
        best["other"] = r["cpu"][i] - sum(best.values())
        r.update(split=best, cpu=r["cpu"][i], child=r["child"][i], wall=r["wall"][i],
                 rounds=len(r["wall"]), last_row=r["last_row"][i])
        del r["splits"]
    out["stage"] = stage_cost(repeat)
    print(json.dumps(out), flush=True)


def stage_cost(repeat: int) -> dict:
    """Best wall and CPU s (this process, by ``time.process_time``) of starting
    the worker (fork), one trivial item through it and its shutdown."""
    from workbench import synthesis
    from workbench.forked_stage import ForkedStage
    walls, cpus = [], []
    for _ in range(max(repeat, 3)):
        c0, w0 = time.process_time(), time.perf_counter()
        synthesis.PIPELINE = True
        stage = ForkedStage.start(lambda x: x, 2)
        stage.submit(1)
        stage.results(lambda x: x)
        cpus.append(time.process_time() - c0)
        walls.append(time.perf_counter() - w0)
    return {"wall": min(walls), "cpu": min(cpus)}


def import_times(imports: str, top: int = 8) -> list[tuple[str, float]]:
    """The ``top`` largest top-level imports (cumulative s) of ``python -X importtime``."""
    p = subprocess.run([sys.executable, "-X", "importtime", "-c", imports], cwd=ROOT,
                       capture_output=True, text=True, check=True)
    rows = []
    for line in p.stderr.splitlines():
        parts = line.split("|")
        if len(parts) != 3 or not parts[0].startswith("import time:"):
            continue
        name = parts[2]
        if name.startswith(" ") and not name.startswith("  "):    # depth 0
            try:
                rows.append((name.strip(), int(parts[1]) / 1e6))
            except ValueError:
                pass
    return sorted(rows, key=lambda r: -r[1])[:top]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/antiskid-cruise-dry.toml")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.worker:
        worker(args.design, args.repeat)
        return
    print(f"machine: {os.cpu_count()} CPUs; load average {os.getloadavg()[0]:.1f} at start")
    p = subprocess.run([sys.executable, __file__, "--worker", args.design, "--repeat",
                        str(args.repeat)], cwd=ROOT, capture_output=True, text=True)
    if p.returncode:
        sys.exit(f"worker exited {p.returncode}:\n{p.stderr[-3000:]}")
    res = json.loads([line for line in p.stdout.splitlines() if line.startswith("{")][-1])
    print(f"\nwarm sweep of {args.design} in one process, {res['serial']['rounds']} rounds "
          "per path alternated, the round of least wall:\n")
    stage = res.pop("stage")
    print("| path | wall s | CPU s this process | CPU s worker | CPU s total |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for name, r in res.items():
        print(f"| {name} | {r['wall']:.3f} | {r['cpu']:.3f} | {r['child']:.3f} | "
              f"{r['cpu'] + r['child']:.3f} |")
    print(f"\nworker start (fork) + one trivial item + shutdown, best: {stage['wall'] * 1e3:.1f} ms "
          f"wall, {stage['cpu'] * 1e3:.1f} ms CPU in this process")
    ser, pip = res["serial"], res["pipelined"]
    print(f"\ncritical path on an idle 2-core machine (estimate, CPU s): serial {ser['cpu']:.3f}; "
          f"pipelined {pip['cpu'] + ser['last_row']:.3f} = this process {pip['cpu']:.3f} + the "
          f"last row's second half {ser['last_row']:.3f} (timed on the serial path), which the "
          "worker computes after the last bisection")
    print(f"\nsame rows on both paths (bit for bit, but seconds): "
          f"{res['serial']['table'] == res['pipelined']['table']}")
    print("solves: " + ", ".join(f"{k} {v}" for k, v in res["serial"]["solves"].items()))
    print("serial sweep split, CPU s: " + " | ".join(
        f"{k} {v:.3f}" for k, v in res["serial"]["split"].items()))
    print("pipelined sweep, this process only, CPU s: " + " | ".join(
        f"{k} {v:.3f}" for k, v in res["pipelined"]["split"].items()))
    cmd = ["-m", "workbench", "synthesize", "delay-bound", args.design]
    for name, env in (("serial", "1"), ("pipelined", "0")):
        os.environ["WORKBENCH_SYNTH_SERIAL"] = env
        cpu, wall = command_times(cmd)
        print(f"\nwhole command in a fresh process, {name}: {cpu:.2f} CPU s (worker "
              f"included), {wall:.2f} s wall", end="")
    os.environ.pop("WORKBENCH_SYNTH_SERIAL", None)
    imports = ("import workbench.cli, workbench.synthesis, workbench.papers.p003.antiskid_cruise, "
               "workbench.kinds.delay_feedback.cli, workbench.design, control, cvxpy")
    print("\n\nlargest imports of the command (python -X importtime, cumulative s): " + ", ".join(
        f"{n} {s:.2f}" for n, s in import_times(imports)))


if __name__ == "__main__":
    main()
