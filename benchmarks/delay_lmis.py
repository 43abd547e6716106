"""Per-method solver calls and time of the delay-LMI benchmark suite.

Runs the suite of ``designs/delay-benchmarks.toml`` (Bessel-Legendre orders
0..5 and the automatic mode) and prints, per method, the solver calls and
seconds summed over the examples, then the same suite's baseline in this
process: the exact margins alone (two methods per example). Target
(issue 4): whole suite, N up to 5, under 30 s on 2 cores.

Run: ``.venv/bin/python benchmarks/delay_lmis.py``
"""
from __future__ import annotations

import time
from collections import defaultdict
from pathlib import Path

import numpy as np

from workbench.benchmark import run_benchmark
from workbench.design import load_design
from workbench.margins import delay_margin_eig, delay_margin_sweep
from workbench.report.markdown import md_table

DESIGN = Path(__file__).resolve().parents[1] / "designs" / "delay-benchmarks.toml"


def main() -> None:
    design = load_design(DESIGN)
    spec = design.spec
    t0 = time.perf_counter()
    for ex in spec.examples:                       # baseline: exact margins only
        delay_margin_eig(np.array(ex.A), np.array(ex.Ad))
        delay_margin_sweep(np.array(ex.A), np.array(ex.Ad))
    base = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = run_benchmark(spec.examples, spec.settings)
    total = time.perf_counter() - t0
    solves, secs = defaultdict(int), defaultdict(float)
    for e in res.examples:
        for r in e.rows:
            key = f"{r.method} N={r.N}" if r.method == "bessel-legendre" else r.method
            solves[key] += r.solves
            secs[key] += r.seconds
    rows = [[k, solves[k], f"{secs[k]:.2f}", f"{1e3 * secs[k] / max(solves[k], 1):.1f}"]
            for k in solves]
    print(f"delay-LMI suite: {len(res.examples)} examples, exact re-check "
          f"{'on' if spec.settings.exact_check else 'off'}")
    print(md_table(["method", "solves", "s", "ms/solve"], rows, "lrrr"))
    print("(bessel-legendre-auto: the orders it needed, already counted in the rows above)")
    print(f"\nwhole suite {total:.2f} s (target < 30 s); exact margins alone {base:.3f} s "
          f"(suite / baseline = {total / base:.0f}x)")


if __name__ == "__main__":
    main()
