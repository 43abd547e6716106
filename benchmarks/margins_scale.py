"""Cost of the exact delay margin and stability windows against the state dimension n
(issue 21, item 7; issue 32, item 8: n = 80 in <= 10 s on one core).

For each n (default 20, 40, 60, 80) one seeded system x' = A x + A_d x(t - h),
a chain of m = n // 2 cars (:func:`system`: seeded coupler stiffnesses, light
direct damping, delayed velocity feedback; crossings exist, so h* is finite),
and the seconds of what a design report asks for:

* :func:`~workbench.margins.exact_margin` (the phase sweep following every
  eigenvalue branch of A + A_d e^{-j theta}, O(n^3) per phase point; the
  Chen-Gu-Nett 2 n^2 pencil, O(n^6), only where it is cheap: n <= 14 under
  ``cross_check="auto"``) and
* :func:`~workbench.margins.stability_windows` up to 4 h* (the same sweep's
  crossings, reused, then root counting);

as CPU seconds of this process (``time.process_time``: with
``OPENBLAS_NUM_THREADS=1`` the one-core cost, little changed by other load)
and wall seconds. ``--kron-max N`` also times the Chen-Gu-Nett pencil for
n <= N and prints its relative difference from the sweep.

Run: ``OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/margins_scale.py
[--sizes 20 40 60 80] [--kron-max N]``
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from workbench.margins import (delay_margin_eig, exact_margin, relative_difference,
                               stability_windows)
from workbench.report.markdown import fmt, md_table

SIZES = (20, 40, 60, 80)
KRON_MAX = 0


def system(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A train of m = n // 2 cars: positions x and velocities v, couplers of
    seeded stiffness between neighbours and to the track, a little direct
    damping, and delayed velocity feedback v'(t) = ... - D v(t - h); for odd n one
    more state, a first-order filter of the delayed first position. Crossings
    exist (delayed damping of an oscillator), so h* is finite."""
    rng = np.random.default_rng(np.random.SeedSequence([21, n]))
    m = n // 2
    k = rng.uniform(0.5, 2.0, m + 1)
    K = np.diag(k[:-1] + k[1:]) - np.diag(k[1:-1], 1) - np.diag(k[1:-1], -1)
    A, Ad = np.zeros((n, n)), np.zeros((n, n))
    A[:m, m:2 * m] = np.eye(m)
    A[m:2 * m, :m] = -K
    A[m:2 * m, m:2 * m] = -0.05 * np.eye(m)
    Ad[m:2 * m, m:2 * m] = -np.diag(rng.uniform(0.2, 0.6, m))
    if n % 2:
        A[-1, -1], Ad[-1, 0] = -1.0, 1.0
    return A, Ad


def _timed(f, *args, **kw):
    c0, w0 = time.process_time(), time.perf_counter()
    out = f(*args, **kw)
    return out, time.process_time() - c0, time.perf_counter() - w0


def _both(A, Ad):
    ex = exact_margin(A, Ad)
    return ex, stability_windows(A, Ad, 4 * ex.h if np.isfinite(ex.h) and ex.h > 0 else 10.0)


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--sizes", type=int, nargs="+", default=list(SIZES))
    p.add_argument("--kron-max", type=int, default=KRON_MAX,
                   help="largest n for timing the Chen-Gu-Nett pencil (default %(default)s)")
    args = p.parse_args(argv)
    rows = []
    for n in args.sizes:
        A, Ad = system(n)
        (ex, win), cpu, wall = _timed(_both, A, Ad)
        kr_txt = diff = "—"
        if n <= args.kron_max:
            kr, t_kr, _ = _timed(delay_margin_eig, A, Ad)
            kr_txt, diff = f"{t_kr:.2f}", fmt(relative_difference(ex.h, kr.h), 2)
        method = "sweep" + (" + Chen-Gu-Nett" if ex.kronecker is not None else "")
        rows.append([n, fmt(ex.h, 7), len(ex.sweep.crossings), len(win), method,
                     f"{cpu:.2f}", f"{wall:.2f}", kr_txt, diff])
    print(f"OPENBLAS_NUM_THREADS = {os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}, "
          f"{os.cpu_count()} cores visible, load average {os.getloadavg()[0]:.1f}\n")
    print(md_table(["n", "h* (s)", "crossings", "windows", "method", "CPU (s)", "wall (s)",
                    "Chen-Gu-Nett (s)", "rel. diff"], rows, "rrrrlrrrr"))


if __name__ == "__main__":
    main()
