"""Per-part time of one antiskid-run design's ``workbench verify``, before and
after, in one run (issue 36, items 4 and 6).

Each column is a child process that evaluates the design as ``workbench
verify`` does (:func:`workbench.verify.evaluate_design`: the study, its
claims and the three-level refinement of its findings), with the study's
parts timed by wrapping their functions (CPU seconds of this process):

* ``compile``: loading (or compiling) the two numba kernels, before the study;
* ``cases``: the scalar case runs (every case at dt and dt/2, the claimed
  case at dt/4, ``AntiskidRun._cases``);
* ``linear``, ``sampled``, ``basin``: the linear checks, the ``[sampled]``
  section (``sampled: Radau`` is its scipy check, included in ``sampled``),
  the basin (cruise basin, k2 sweep, brake switch: ``run_basin``; ``basin:
  cruise`` and ``basin: k2 sweep`` are its first two, included in ``basin``);
* ``montecarlo``: the sweep and its step-halving check, in the study's
  process pool (the CPU of the child processes);
* ``refine``: the three-level refinement of the findings;
* ``rest``: everything else (imports, loading, gain synthesis, claims).

Columns: with ``--before REV``, the design at git revision REV (its tree
exported to a temporary folder by ``git archive``) and then at the working
tree, one process each; without it, the working tree twice (a first and a
second process: the second loads the kernels the first compiled). Every
process uses the same kernel disk cache (``--cache DIR``, default the
user's): the cache is keyed by the source, so a process of a tree that was
never compiled on this machine compiles (see ``compile``).

The CPU seconds are the figure to compare on a loaded machine; nothing here
asserts a time.

Usage::

    python benchmarks/antiskid_run_times.py [designs/antiskid-run-dry.toml]
        [--before REV] [--cache DIR]
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

from synthesize_times import wrap as timed_call

ROOT = Path(__file__).resolve().parents[1]
PARTS = ("compile", "cases", "linear", "sampled", "sampled: Radau", "basin", "basin: cruise",
         "basin: k2 sweep", "montecarlo", "refine", "rest")
#: parts inside another part (shown, not added to the total)
SUBPARTS = ("sampled: Radau", "basin: cruise", "basin: k2 sweep")


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def worker(path: str) -> None:
    """Evaluate the design in this process, timing its parts; one JSON line."""
    c_start, w_start = _cpu(), time.perf_counter()
    spent: dict = dict.fromkeys(PARTS, 0.0)

    def wrap(obj, name, part):
        timed_call(obj, name, spent, part)

    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_basin_run as BR
    from workbench.papers.p003 import antiskid_run as R
    from workbench.papers.p003 import antiskid_sampled as SA
    from workbench.papers.p003 import antiskid_sampled_kernel as SK
    from workbench.papers.p003.antiskid_kernel import compile_kernel
    from workbench.papers.p003.antiskid_run_spec import gain_for, sampled_context
    from workbench.verify import evaluate_design
    design = load_design(path)
    spec = design.spec
    K = gain_for(spec)[0]     # (memoised: the study's own call finds it)
    c0 = _cpu()
    compile_kernel()
    if spec.sampled is not None:
        SK.run_once(sampled_context(spec, K), 1000.0, SK.BRAKING_SCENARIO,
                    dt_p=spec.dt, t_cap=0.0)
    spent["compile"] = _cpu() - c0
    wrap(R.AntiskidRun, "_cases", "cases")
    wrap(R, "linear_check", "linear")
    wrap(R.AntiskidRun, "refine_levels", "refine")
    wrap(SA, "run_sampled", "sampled")
    wrap(SA, "radau_checks", "sampled: Radau")
    wrap(BR, "run_basin", "basin")
    wrap(BR, "cruise_basin", "basin: cruise")
    wrap(BR, "safe_k2_range", "basin: k2 sweep")
    evaluate_design(design)
    t = os.times()
    spent["montecarlo"] = t.children_user + t.children_system
    total = _cpu() - c_start + spent["montecarlo"]
    spent["rest"] = total - sum(spent[p] for p in PARTS if p != "rest" and p not in SUBPARTS)
    spent["total"] = total
    spent["wall"] = time.perf_counter() - w_start
    print(json.dumps(spent))


def _tree(rev: str, tmp: str) -> Path:
    """The tree of git revision ``rev``, exported under ``tmp``."""
    out = Path(tmp) / "tree"
    out.mkdir()
    arch = subprocess.run(["git", "archive", rev], cwd=ROOT, check=True, capture_output=True)
    subprocess.run(["tar", "-x", "-C", str(out)], input=arch.stdout, check=True)
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default="designs/antiskid-run-dry.toml")
    ap.add_argument("--before", metavar="REV", help="git revision of the 'before' column")
    ap.add_argument("--cache", help="numba cache directory (default: the user's)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        worker(a.design)
        return
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    if a.cache:
        env["WORKBENCH_CACHE_DIR"] = a.cache
    env.pop("WORKBENCH_NUMBA_CACHE", None)
    env.pop("WORKBENCH_STUDY_CACHE", None)
    with tempfile.TemporaryDirectory() as tmp:
        trees = ([(f"before ({a.before})", _tree(a.before, tmp))] if a.before else
                 [("first process", ROOT)]) + [("after" if a.before else "second process", ROOT)]
        runs = []
        for label, tree in trees:
            e = dict(env, PYTHONPATH=str(tree))
            out = subprocess.run([sys.executable, str(Path(__file__).resolve()), a.design,
                                  "--worker"], env=e, cwd=tree, check=True,
                                 capture_output=True, text=True).stdout
            runs.append((label, json.loads(out.strip().splitlines()[-1])))
            print(f"{label} done", file=sys.stderr, flush=True)
    print(f"{a.design}: CPU s per part of `workbench verify` (one process each); "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"| part | {' | '.join(lab for lab, _ in runs)} |")
    print("| :--- |" + " ---: |" * len(runs))
    for p in (*PARTS, "total"):
        print(f"| {p} | " + " | ".join(f"{r[p]:.1f}" for _, r in runs) + " |")
    print("| wall s | " + " | ".join(f"{r['wall']:.1f}" for _, r in runs) + " |")


if __name__ == "__main__":
    main()
