"""The decay certificate of a requirement design, before and after, in one run (issue 36, item 4).

:func:`workbench.lmi.requirements_decay.certified_decay` certifies the decay
rate of the rounded gain by Bessel-Legendre cells. The old path
(``WORKBENCH_DECAY_UNSHARED=1``) builds and compiles a fresh cvxpy problem for
every cell; the current one loads each cell's numbers into one problem
compiled per size (``CellFamily``). For each design this script runs the
design's own synthesis up to its decay search (``workbench verify`` until
``certified_decay`` is called, then stops), and runs that search on both
paths in this process, alternately, ``--repeat`` times each. It prints the
best wall and CPU seconds of each path, their ratio, the cells solved, the
certified rate of each path, whether the bisections took the same steps with
the same outcomes, and whether the two brackets are identical to the last bit
("bits"; the shared problem's data is the cell's up to the rounding of
products formed in another order, so a rate may move in its last digits, as
it does between BLAS kernels) or only to the 4 significant digits, rounded
down, that the reports print ("printed"). Nothing here asserts a time.

Usage::

    python benchmarks/decay_cells.py [designs/X.toml ...] [--repeat N]
"""
from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEFAULT = ("designs/train-brake-lag-delay-feedback.toml", "designs/antiskid-robust.toml")


class _Captured(BaseException):
    """Raised to stop the design's run once its decay search's input is known."""


def capture(path: str):
    """(points, keyword arguments) of the design's decay search."""
    import workbench.lmi.requirements_synthesis as rs
    from workbench.cli import main
    real, seen = rs.certified_decay, []

    def hook(points, **kw):
        seen.append(([(a.copy(), b.copy()) for a, b in points], kw))
        raise _Captured()
    rs.certified_decay = hook
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            main(["verify", path])
    except _Captured:
        pass
    finally:
        rs.certified_decay = real
    if not seen:
        sys.exit(f"{path}: no decay search (no [requirements] decay with constant delays)")
    return seen[0]


def _cpu() -> float:
    t = os.times()
    return t.user + t.system


def timed(points, kw, unshared: bool):
    """(bracket, wall s, CPU s, cells solved) of one decay search on one path."""
    from workbench.lmi import requirements_decay as rd
    count = [0]
    solve = rd.CellLMI.solve_at

    def counted(self, h):
        count[0] += 1
        return solve(self, h)
    rd.CellLMI.solve_at = counted
    if unshared:
        os.environ["WORKBENCH_DECAY_UNSHARED"] = "1"
    else:
        os.environ.pop("WORKBENCH_DECAY_UNSHARED", None)
    try:
        c0, w0 = _cpu(), time.perf_counter()
        br = rd.certified_decay(points, **kw)
        return br, time.perf_counter() - w0, _cpu() - c0, count[0]
    finally:
        rd.CellLMI.solve_at = solve
        os.environ.pop("WORKBENCH_DECAY_UNSHARED", None)


def _same(a, b) -> str:
    """"bits", "printed" or "NO" (module docstring)."""
    from workbench.printed_grid import directed
    if (a.h_certified, a.h_refuted, [(s.h, s.outcome) for s in a.steps]) == (
            b.h_certified, b.h_refuted, [(s.h, s.outcome) for s in b.steps]):
        return "bits"
    if ([s.outcome for s in a.steps] == [s.outcome for s in b.steps]
            and directed(a.h_certified, up=False) == directed(b.h_certified, up=False)):
        return "printed"
    return "NO"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("designs", nargs="*", default=list(DEFAULT))
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args(argv)
    os.chdir(ROOT)
    print("| design | cells | old wall s | old CPU s | new wall s | new CPU s | "
          "ratio (CPU) | old decay 1/s | new decay 1/s | identical |")
    print("| :--- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | :--- |")
    for path in args.designs:
        points, kw = capture(path)
        best = {True: [None, float("inf"), float("inf"), 0],
                False: [None, float("inf"), float("inf"), 0]}
        for _ in range(max(1, args.repeat)):
            for unshared in (True, False):
                br, wall, cpu, cells = timed(points, kw, unshared)
                b = best[unshared]
                b[0] = b[0] or br
                b[1], b[2], b[3] = min(b[1], wall), min(b[2], cpu), cells
        old, new = best[True], best[False]
        cells = str(new[3]) if new[3] == old[3] else f"{old[3]} / {new[3]}"
        print(f"| {Path(path).stem} | {cells} | {old[1]:.1f} | {old[2]:.1f} | {new[1]:.1f} | "
              f"{new[2]:.1f} | {old[2] / new[2]:.1f}x | {old[0].h_certified!r} | "
              f"{new[0].h_certified!r} | {_same(old[0], new[0])} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
