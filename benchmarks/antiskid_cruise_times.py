"""CPU of the antiskid-cruise study with the printed rows' eps matching
decided by one solve per step (:mod:`workbench.features.eps_match`)
against the full delay bisection per step (:func:`workbench.synthesis.eps_for_bound`,
the path before issue 36), in one process, and whether the study's
quantities agree (they must: the two return the same eps bit for bit).

Prints wall and CPU seconds of each run (CPU is the figure to compare on a
loaded machine); asserts nothing about time.

Usage::

    python benchmarks/antiskid_cruise_times.py [--reverse] [designs/antiskid-cruise-dry.toml]

``--reverse`` runs the new path first (the first run also pays the lazy
imports and first compilations).
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def main(argv) -> int:
    from workbench.design import load_design
    from workbench.features import eps_match as M
    from workbench.papers.p003.antiskid_cruise import STUDY
    from workbench.synthesis import eps_for_bound
    rev = "--reverse" in argv
    argv = [a for a in argv if a != "--reverse"]
    path = argv[0] if argv else str(ROOT / "designs" / "antiskid-cruise-dry.toml")
    design = load_design(path)
    new = M.eps_matching
    old = lambda A, B, h, lo, hi, settings: eps_for_bound(A, B, h, lo, hi, settings=settings)
    out = {}
    runs = (("before (eps_for_bound)", old), ("after (eps_matching)", new))
    for name, fn in (runs[::-1] if rev else runs):
        M.eps_matching = fn
        w0, c0 = time.perf_counter(), _cpu()
        q = STUDY.quantities(STUDY.run(design))
        out[name] = (time.perf_counter() - w0, _cpu() - c0, q)
    M.eps_matching = new
    print(f"| {Path(path).stem} | wall (s) | CPU (s) |\n| :--- | ---: | ---: |")
    for name, (w, c, _) in out.items():
        print(f"| {name} | {w:.1f} | {c:.1f} |")
    qs = [q for _, _, q in out.values()]
    print("quantities identical:", qs[0] == qs[1])
    return 0 if qs[0] == qs[1] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
