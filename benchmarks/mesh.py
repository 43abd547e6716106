"""Refined mesh of the antiskid runs: accuracy and cost against the fixed step.

Prints, for the dry-rail design (``designs/antiskid-run-dry.toml``):

1. the compensated run (predictor) on the fixed step dt and dt/2 against
   the same run on the refined mesh (rollout on the mesh too), with the
   wall time of each: the fixed step is what the report uses, the mesh is
   the cross-check of its braking metrics (the low-speed end is stiff);
2. the mass -5 % run without the predictor, whose start is near-neutral:
   the max creep ratio in traction on the fixed step for dt = 10 ms down to
   0.625 ms (first order) and on the mesh at dt and dt/2.

Usage: .venv/bin/python benchmarks/mesh.py [--skip-compensated]
"""
from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from workbench.design import load_design
from workbench.papers.p003 import antiskid_run_spec as S
from workbench.papers.p003.antiskid_scenario import Mesh, simulate_antiskid
from workbench.sim.progress import progress

ROOT = Path(__file__).resolve().parents[1]


def _timed(rs, dt, mesh=None):
    t0 = time.perf_counter()
    _, m = simulate_antiskid(rs, dt, record_dt=None, mesh=mesh)
    return m, time.perf_counter() - t0


def _settings(path: Path, case_name: str, t_end: float | None = None):
    spec = load_design(path).spec
    K, _, _ = S.gain_for(spec)
    case = next(c for c in spec.cases if c.name == case_name)
    cs = S.controller_settings(spec, K, case)
    rs = S.run_settings(spec, cs)
    return spec, cs, (rs if t_end is None else dataclasses.replace(rs, t_end=t_end))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--skip-compensated", action="store_true",
                    help="skip part 1 (the mesh run with the predictor takes ~1 min)")
    args = ap.parse_args()
    if not args.skip_compensated:
        spec, cs, rs = _settings(ROOT / "designs/antiskid-run-dry.toml", "compensated")
        t_b = spec.scenario["t_brake"]
        runs = (("fixed dt", spec.dt, None), ("fixed dt/2", spec.dt / 2, None),
                ("mesh dt", spec.dt, Mesh(spec.dt, spec.mesh_courant, spec.mesh_levels)))
        rows = [(name, *_timed(rs, dt, mesh)) for name, dt, mesh in
                progress(runs, desc="dry, compensated", unit="run")]
        base = rows[0][2]
        print(f"dry, compensated (dt = {spec.dt:g} s; mesh courant {spec.mesh_courant:g}, "
              f"{spec.mesh_levels} levels)")
        for name, m, wall in rows:
            mm = S.case_metrics(m, cs, t_b)
            print(f"  {name:11s} time to cruise {mm['t_cruise']:.4f} s, braking "
                  f"{mm['braking_duration']:.3f} s, to omega <= 3 rad/s "
                  f"{mm['omega3_after_brake']:.3f} s, max |e_vs| {mm['evs_max_tracking']:.2e} "
                  f"m/s; wall {wall:.1f} s ({wall / base:.1f}x fixed dt)")
    spec, cs, rs = _settings(ROOT / "designs/antiskid-run-dry-mass-minus5.toml",
                             "uncompensated", 6.0)
    print("dry, mass -5 %, without the predictor, max creep ratio over the first 6 s:")
    for dt in progress((0.01, 0.005, 0.0025, 0.00125, 0.000625), desc="fixed-step runs",
                       unit="run"):
        m, wall = _timed(rs, dt)
        print(f"  fixed dt = {dt * 1e3:6.3f} ms: {m.lam_max_traction:.5f}  (wall {wall:.2f} s)")
    mesh = Mesh(spec.dt, spec.mesh_courant, spec.mesh_levels)
    for dt in progress((spec.dt, spec.dt / 2), desc="mesh runs", unit="run"):
        m, wall = _timed(rs, dt, mesh)
        print(f"  mesh  dt = {dt * 1e3:6.3f} ms: {m.lam_max_traction:.5f}  (wall {wall:.2f} s)")


if __name__ == "__main__":
    main()
