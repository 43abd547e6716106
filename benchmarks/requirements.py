"""Design to requirements (issue 31): certified decay against the best exact decay.

For x'' = x + u(t - h) (pendulum type) and x'' = u(t - h) (double
integrator) with delay = [0, 0.3] s and objective "decay", prints

* the certified decay rate of the returned (rounded) gain over [0, 0.3] s,
* the exact worst decay of that gain (rightmost root on the delay grid),
* the best exact worst-case decay found by a direct grid search over K
  (coarse grid, then a finer grid around its best point; the worst case
  over 7 delays of [0, 0.3] s, so an upper estimate of the grid point's
  true worst case),
* the ratio certified / best,

and the synthesis time of several requirement sets. Figures, not assertions.

Run: ``.venv/bin/python benchmarks/requirements.py``.
"""
from __future__ import annotations

import time

import numpy as np

import workbench
from workbench.margins import spectral_abscissa

PLANTS = {
    "pendulum x'' = x + u(t-h)": np.array([[0.0, 1.0], [1.0, 0.0]]),
    "double integrator x'' = u(t-h)": np.array([[0.0, 1.0], [0.0, 0.0]]),
}
B = np.array([[0.0], [1.0]])
H = 0.3


def worst(A, K, hs):
    return -max(spectral_abscissa(A, B @ K, float(h)) for h in hs)


def grid_best(A, hs):
    """Best worst-case exact decay over a K grid (coarse, then fine)."""
    best = (-np.inf, None)
    for k1 in np.linspace(-8.0, -0.25, 32):
        for k2 in np.linspace(-6.0, 0.0, 25):
            K = np.array([[k1, k2]])
            w = worst(A, K, hs)
            if w > best[0]:
                best = (w, K)
    c1, c2 = best[1][0]
    for k1 in np.linspace(c1 - 0.25, c1 + 0.25, 11):
        for k2 in np.linspace(c2 - 0.25, c2 + 0.25, 11):
            K = np.array([[k1, k2]])
            w = worst(A, K, hs)
            if w > best[0]:
                best = (w, K)
    return best


def main() -> None:
    hs = np.linspace(0.0, H, 7)
    for name, A in PLANTS.items():
        t0 = time.perf_counter()
        r = workbench.design_gain((A), B, delay=(0.0, H), objective="decay")
        dt = time.perf_counter() - t0
        row = r.row("decay")
        g, Kg = grid_best(A, hs)
        print(f"{name}, delay [0, {H}] s, objective decay")
        print(f"  K = {r.K.tolist()}  synthesis + certification {dt:.1f} s")
        print(f"  certified decay {row.certified:.4f} 1/s, exact worst decay of that K "
              f"{row.exact:.4f} 1/s ({row.verdict})")
        print(f"  best exact worst-case decay of the K grid {g:.4f} 1/s at K = "
              f"{np.round(Kg, 3).tolist()}")
        print(f"  ratio certified / best grid = {row.certified / g:.3f}")
    A = PLANTS["pendulum x'' = x + u(t-h)"]
    sets = {
        "delay only (objective delay)": dict(objective="delay"),
        "decay >= 0.5 (objective delay)": dict(decay_rate=0.5, objective="delay"),
        "l2 from w = u-channel to x1 (objective l2_gain)": dict(
            objective="l2_gain", Bw=B, Cz=[[1.0, 0.0]]),
        "decay + input limit 5 from box 0.5 (objective decay)": dict(
            objective="decay", input_limit=5.0, box=(0.5, 0.5)),
    }
    print("pendulum, delay [0, 0.3] s: time per requirement set")
    for name, kw in sets.items():
        t0 = time.perf_counter()
        r = workbench.design_gain(A, B, delay=(0.0, H), **kw)
        dt = time.perf_counter() - t0
        rows = "; ".join(f"{x.name}: cert {x.certified if x.certified is None else round(x.certified, 4)}"
                         f" exact {x.exact if x.exact is None else round(x.exact, 4)} {x.verdict}"
                         for x in r.rows)
        print(f"  {name}: {dt:.1f} s, K = {None if r.K is None else r.K.tolist()}; {rows}")


if __name__ == "__main__":
    main()
