"""CPU seconds of paper 003's two compiled loops, before and after a change,
in one run (issue 35, kern48): the batch Monte Carlo kernel (the dry
design's first ``--samples`` sweep runs, one chunk, compiled path) and the
sampled loop (a braking run and a traction run of the dry design's
``[sampled]`` section, ``zoh``, at each of :data:`SAMPLED_RATES_HZ`).

Each column is a child process importing the package from a tree: with
``--before REV`` the tree of git revision REV (exported by ``git archive``)
and the working tree, alternately, ``--rounds`` times each; the kernels are
compiled (or loaded from the disk cache) and run once before the timed
calls, so neither compilation nor loading is in the figures. The figure is
``time.process_time()`` of the calls; the ratio after / before is printed.
Nothing here asserts a time.

Usage::

    python benchmarks/antiskid_kernels_cpu.py --before e73b02e [--samples 256] [--rounds 2]
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

from antiskid_run_times import _tree

ROOT = Path(__file__).resolve().parents[1]
DRY = ROOT / "designs" / "antiskid-run-dry.toml"
#: Rates (Hz) of the timed sampled runs (a braking and a traction run each).
SAMPLED_RATES_HZ = (1000.0, 2000.0, 5000.0)


def worker(samples: int) -> None:
    """Time the two loops in this process; one JSON line on stdout."""
    import workbench
    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_montecarlo as M
    from workbench.papers.p003.antiskid_run_spec import gain_for, sampled_context
    from workbench.papers.p003.antiskid_sampled_kernel import run_once
    design = load_design(DRY)
    spec = design.spec
    inp = M.sweep_inputs(design, samples, spec.montecarlo.seed, gain_for(spec)[0])
    payload = M.chunk_payload(inp, 0, samples, inp["dt"], kernel="compiled")
    M.chunk_worker(M.chunk_payload(inp, 0, 1, inp["dt"], kernel="compiled"))   # compile/load
    ctx = sampled_context(spec, spec.K_table)
    kw = dict(dt_p=1e-4, predictor_step=1e-3)          # the dry design's [sampled] steps
    run_once(ctx, 1000.0, 0, t_cap=0.05, **kw)                                 # compile/load
    out = {"tree": str(Path(workbench.__file__).parents[1])}
    c0 = time.process_time()
    M.chunk_worker(payload)
    out["batch"] = time.process_time() - c0
    c0 = time.process_time()
    for rate in SAMPLED_RATES_HZ:
        run_once(ctx, rate, 1, **kw)
        run_once(ctx, rate, 0, **kw)
    out["sampled"] = time.process_time() - c0
    print(json.dumps(out))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", metavar="REV", required=False)
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.worker:
        worker(a.samples)
        return
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        trees = [("after", ROOT)]
        if a.before:
            trees.insert(0, (f"before ({a.before})", _tree(a.before, tmp)))
        got = {label: [] for label, _ in trees}
        for _ in range(a.rounds):
            for label, tree in trees:
                r = subprocess.run([sys.executable, __file__, "--worker", "--samples",
                                    str(a.samples)], env=dict(env, PYTHONPATH=str(tree)),
                                   check=True, capture_output=True, text=True, cwd=tmp)
                got[label].append(json.loads(r.stdout.strip().splitlines()[-1]))
                print(label, got[label][-1], flush=True)
    for part in ("batch", "sampled"):
        cols = {k: min(x[part] for x in v) for k, v in got.items()}
        line = ", ".join(f"{k} {c:.2f} CPU s" for k, c in cols.items())
        if len(cols) == 2:
            b, c = cols.values()
            line += f", after / before {c / b:.3f}"
        print(f"{part} (least of {a.rounds}): {line}")


if __name__ == "__main__":
    main()
