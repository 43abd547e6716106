"""Benchmark: paper 002's MFAC/PID line study and paper 001's 4-train platoon.

Prints, in the same process:

1. the wall time of the whole paper-002 ``tracking`` study (two plant readings,
   tuning grids and Pareto fronts, synthetic line) — target under 60 s — and, as a baseline, the
   same N MFAC grid runs stepped one at a time instead of as one batch;
2. the wall time of one 4-train, 300 s platoon run at T = 0.01 s under the
   NTSM law (trains stepped as arrays) — target under 5 s — against a naive
   loop over trains at every step (same functions, scalar calls), with the
   largest difference between the two trajectories.
"""
from __future__ import annotations

import time

import numpy as np

from workbench.controllers.mfac import MFAC, MFACGains
from workbench.design import load_design
from workbench.kinds.platoon import run as platoon001
from workbench.kinds import tracking as tracking002
from workbench.kinds.tracking.spec import MFAC_KEYS
from workbench.plants.platoon001 import TrainParams
from workbench.profiles import build_profile
from workbench.sim.tracking import simulate_tracking

N_GRID = 40


def bench_line() -> None:
    d = load_design("designs/ato-mfac-pid-002.toml")
    spec = d.spec
    t0 = time.perf_counter()
    tracking002.STUDY.run(d)
    whole = time.perf_counter() - t0

    reading = spec.readings[0]
    prof = build_profile(spec.profile_spec(spec.main), dt=spec.Ts)
    rng = np.random.default_rng(0)
    gains = {k: rng.choice(reading.mfac_grid[k], N_GRID) for k in MFAC_KEYS}

    def run(g):
        ctl = MFAC(MFACGains(**g, epsilon=reading.epsilon), len(g["lam"]),
                   u_min=reading.train.u_min, u_max=reading.train.u_max)
        return simulate_tracking(reading.train, spec.main.route, prof.speed_at,
                                 lambda k, y, yn: ctl.step(y, yn), len(g["lam"]), Ts=spec.Ts,
                                 dt=spec.dt, horizon=spec.main.run_time + 60.0,
                                 brake_start=float(prof.t[np.argmax(prof.a < 0)]))

    t0 = time.perf_counter()
    batch = run(gains)
    batched = time.perf_counter() - t0
    t0 = time.perf_counter()
    single = [run({k: v[i:i + 1] for k, v in gains.items()}) for i in range(N_GRID)]
    one_by_one = time.perf_counter() - t0
    diff = max(np.nanmax(np.abs(s.v[0] - batch.v[i, :s.v.shape[1]]))
               for i, s in enumerate(single))
    print("paper 002 tracking study (2 plant readings, Macun-Nanhu + 6 synthetic sections)")
    print(f"  whole study (tuning grids, fronts, line):      {whole:7.2f} s   (target < 60 s)")
    print(f"  {N_GRID} MFAC runs as one batch:                {batched:7.2f} s")
    print(f"  the same {N_GRID} runs one at a time (baseline):  {one_by_one:7.2f} s   "
          f"ratio {one_by_one / batched:5.1f}x, max |dv| {diff:.1e} m/s")


def _naive_platoon(nominal, true, law1, ref, *, n, spacing, T, horizon, w, leader_gain,
                   route):
    """Baseline: the same model stepped train by train with scalar calls."""
    K = int(round(horizon / T))
    trains = [TrainParams(true.m[i], true.c0[i], true.c1[i], true.c2[i], true.g)
              for i in range(n)]
    x = [-i * spacing for i in range(n)]
    v = [0.0] * n
    a_prev = [0.0] * n
    xs = np.zeros((K, n))
    for k in range(K):
        v_ref, a_ref = (float(r) for r in ref(k * T))
        u, i_g = [0.0] * n, [0.0] * n
        for i in range(n):
            i_g[i] = route.grade[sum(x[i] >= g0 for g0 in route.grade_from[1:])]
            u1 = float(nominal.resistance(v[i]) + nominal.grade_force(i_g[i]))
            if i == 0:
                u[i] = nominal.m * (a_ref + leader_gain * (v_ref - v[0])) + u1
            else:
                u[i] = law1(x[i - 1] - x[i] - spacing, v[i - 1] - v[i], u1, a_prev[i - 1])
        xs[k] = x
        for i, tr in enumerate(trains):
            acc = (u[i] - tr.resistance(v[i]) - tr.grade_force(i_g[i]) + w[k, i]) / tr.m
            v_new = max(v[i] + T * acc, 0.0)
            a_prev[i] = (v_new - v[i]) / T
            x[i] += 0.5 * T * (v[i] + v_new)
            v[i] = v_new
    return xs


def bench_platoon() -> None:
    d = load_design("designs/platoon-ntsm-001.toml")
    spec = d.spec
    sc = platoon001.scenario(spec)
    law = sc.law("ntsm")
    K = len(sc.w)
    t0 = time.perf_counter()
    run = sc.simulate("ntsm")
    fast = time.perf_counter() - t0
    law1 = lambda e, de, u1, ap: float(law(np.array([e]), np.array([de]), u1, ap)[0][0])
    t0 = time.perf_counter()
    xs = _naive_platoon(sc.nominal, sc.true, law1, sc.leader_ref, **sc.common())
    naive = time.perf_counter() - t0
    print(f"paper 001 platoon: {spec.n} trains, {fmt_s(spec.horizon)} s at T = {spec.T} s "
          f"({K} steps)")
    print(f"  trains stepped as arrays:        {fast:7.2f} s   (target < 5 s)")
    print(f"  naive loop over trains (baseline): {naive:5.2f} s   ratio {naive / fast:5.1f}x, "
          f"max |dx| {np.abs(xs - run.x).max():.1e} m")


def fmt_s(x: float) -> str:
    return f"{x:g}"


def main() -> None:
    bench_line()
    bench_platoon()


if __name__ == "__main__":
    main()
