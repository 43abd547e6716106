"""Cost of the exact delay margin against the state dimension n (issue 21, item 7).

For n = 5..60, one seeded system x' = A x + A_d x(t - h) (a chain of cars with
delayed velocity feedback, :func:`system`) and the seconds of

* :func:`~workbench.margins.delay_margin_sweep` (phase sweep following every
  eigenvalue branch, O(n^3) per grid point): every n;
* :func:`~workbench.margins.delay_margin_eig` (Chen-Gu-Nett, a 2 n^2 pencil,
  O(n^6)): n <= ``KRON_MAX`` (at n = 30 it takes ~20 s, at n = 40 ~170 s);

with the relative difference of the two where both ran. Target: n = 40 under
2 s on 2 cores. OpenBLAS threads matter on a loaded machine: compare
``OPENBLAS_NUM_THREADS=1 .venv/bin/python benchmarks/margins_scale.py``.

Run: ``.venv/bin/python benchmarks/margins_scale.py [--kron-max N]``
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np

from workbench.margins import delay_margin_eig, delay_margin_sweep, relative_difference
from workbench.report.markdown import fmt, md_table

SIZES = (5, 10, 15, 20, 25, 30, 40, 50, 60)
KRON_MAX = 20


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


def _timed(f, *args):
    t0 = time.perf_counter()
    out = f(*args)
    return out, time.perf_counter() - t0


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--kron-max", type=int, default=KRON_MAX,
                   help="largest n for the Kronecker method (default %(default)s)")
    args = p.parse_args(argv)
    rows = []
    for n in SIZES:
        A, Ad = system(n)
        sw, t_sw = _timed(delay_margin_sweep, A, Ad)
        if n <= args.kron_max:
            kr, t_kr = _timed(delay_margin_eig, A, Ad)
            kr_txt, diff = f"{t_kr:.2f}", fmt(relative_difference(sw.h, kr.h), 2)
        else:
            kr_txt, diff = "—", "—"
        rows.append([n, fmt(sw.h, 7), len(sw.crossings), f"{t_sw:.2f}", kr_txt, diff])
    print(f"OPENBLAS_NUM_THREADS = {os.environ.get('OPENBLAS_NUM_THREADS', 'unset')}, "
          f"{os.cpu_count()} cores visible\n")
    print(md_table(["n", "h* (s)", "crossings", "sweep (s)", "Kronecker (s)", "rel. diff"],
                   rows, "rrrrrr"))


if __name__ == "__main__":
    main()
