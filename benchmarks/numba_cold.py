"""Cold against warm compilation of the two compiled antiskid kernels (issue 36, item 3).

Each measurement runs in a fresh process with ``WORKBENCH_CACHE_DIR`` set to
an empty folder (cold: numba compiles and writes the disk cache of
:mod:`workbench.sim.jit_cache`) and then again with the same folder (warm:
the kernel is loaded). Prints wall and CPU seconds of the first call of each
kernel, nothing asserted.

Usage::

    python benchmarks/numba_cold.py
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _first_call(which: str) -> dict:
    """In this process: (wall, CPU) of importing and first-calling ``which``."""
    w0, c0 = time.perf_counter(), time.process_time()
    from workbench.papers.p003.antiskid_warm import WARMERS
    WARMERS[which]()
    return {"kernel": which, "wall": time.perf_counter() - w0, "cpu": time.process_time() - c0}


def main() -> None:
    if len(sys.argv) == 3 and sys.argv[1] == "--worker":
        print(json.dumps(_first_call(sys.argv[2])))
        return
    print("| kernel | cold wall s | cold CPU s | warm wall s | warm CPU s |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for which in ("batch", "sampled"):
        with tempfile.TemporaryDirectory(prefix="numba-cold-") as d:
            env = dict(os.environ, WORKBENCH_CACHE_DIR=d, OPENBLAS_NUM_THREADS="1")
            rows = []
            for _ in ("cold", "warm"):
                p = subprocess.run([sys.executable, __file__, "--worker", which], cwd=ROOT,
                                   env=env, capture_output=True, text=True, check=True)
                rows.append(json.loads(p.stdout.strip().splitlines()[-1]))
        c, w = rows
        print(f"| {which} | {c['wall']:.1f} | {c['cpu']:.1f} | {w['wall']:.1f} | {w['cpu']:.1f} |")


if __name__ == "__main__":
    main()
