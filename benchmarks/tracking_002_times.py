"""Paper 002's study (``workbench verify designs/ato-mfac-pid-002.toml``), before
and after the cuts of issue 36, item 4 (helper speed36h), in one process.

Three configurations, each the whole verification (the study at dt and the
refinement's two runs at dt/2 and dt/4, claims included), the memo cleared
in between:

* **before**: the plant sub-steps on numpy arrays and each tuning grid run
  three times (nominal train, +NUDGE, -NUDGE), as the code did before;
* **fused numpy**: the grid and its two nudged copies in one batch (one
  time loop of three times the width), sub-steps on numpy arrays;
* **after** (the shipped path): fused, and the sub-steps compiled
  (:mod:`workbench.sim.tracking_jit`; its compilation, or its load from the
  disk cache, is in the first timed call unless ``--warm``).

Prints the wall and CPU seconds of each and whether the three give the same
value of every quantity (they must: the cuts change no bit). Nothing here
asserts a time.

Usage::

    python benchmarks/tracking_002_times.py [--only after] [--warm]
"""
from __future__ import annotations

import argparse
import math
import time
from contextlib import contextmanager

from workbench import memo
from workbench.design import load_design
from workbench.kinds.tracking import run as R
from workbench.sim import tracking
from workbench.sim.tracking import Objectives
from workbench.verify import evaluate_design

DESIGN = "designs/ato-mfac-pid-002.toml"


@contextmanager
def _patched(numpy_steps: bool, separate: bool):
    """The old code paths (module docstring), restored on exit."""
    saved = tracking._compiled_or_numpy, R._grid_run
    if numpy_steps:
        tracking._compiled_or_numpy = lambda kernel: tracking._substeps_numpy
    if separate:
        fused = saved[1]

        def one_by_one(spec, reading, trains, sec, prof, kind, P):
            outs = [fused(spec, reading, (tr,), sec, prof, kind, P) for tr in trains]
            q = Objectives(*(__import__("numpy").concatenate([getattr(o[2], f) for o in outs])
                             for f in ("stop_error", "punctuality", "comfort", "energy",
                                       "rms_speed_error", "peak_jerk")))
            return outs[0][0], outs[0][1], q     # rows 0..N-1: the nominal grid
        R._grid_run = one_by_one
    try:
        yield
    finally:
        tracking._compiled_or_numpy, R._grid_run = saved


def _timed(label: str, numpy_steps: bool, separate: bool) -> tuple[float, float, dict]:
    memo.clear()
    d = load_design(DESIGN)
    with _patched(numpy_steps, separate):
        w0, c0 = time.perf_counter(), time.process_time()
        ev = evaluate_design(d)
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    q = {k: (v, "") for k, v in R.study_quantities(ev.result).items()}
    q.update({c.claim.id: (c.got, str(c.verdict)) for c in ev.claims})
    if ev.refinement is not None:
        q.update({"refined " + r.claim_id: (repr(r.values), r.outcome)
                  for r in ev.refinement.rows})
    print(f"  {label:<12} {wall:7.1f} s wall {cpu:7.1f} s CPU   claims ok: {ev.ok}", flush=True)
    return wall, cpu, q


def _same(a: dict, b: dict) -> bool:
    eq = lambda x, y: x == y or (isinstance(x, float) and isinstance(y, float)
                                 and math.isnan(x) and math.isnan(y))
    return a.keys() == b.keys() and all(eq(a[k][0], b[k][0]) and a[k][1] == b[k][1] for k in a)


CONFIGS = {"before": (True, True), "fused-numpy": (True, False), "after": (False, False)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=sorted(CONFIGS), action="append",
                    help="time only these configurations (repeatable)")
    ap.add_argument("--warm", action="store_true",
                    help="load (or compile) the kernel before timing")
    args = ap.parse_args()
    if args.warm:
        from workbench.sim.tracking_jit import substeps   # noqa: F401  (import compiles lazily)
        _timed("warm-up", False, False)
    print(f"{DESIGN}: whole verification (study at dt, dt/2, dt/4; claims)")
    rows = {k: _timed(k, *v) for k, v in CONFIGS.items() if not args.only or k in args.only}
    if "before" in rows and "after" in rows:
        (wb, cb, qb), (wa, ca, qa) = rows["before"], rows["after"]
        print(f"  CPU before / after: {cb / ca:.1f}x; wall {wb / wa:.1f}x; "
              f"same quantities, claim values, verdicts and refinement rows: {'yes' if _same(qb, qa) else 'NO'}")


if __name__ == "__main__":
    main()
