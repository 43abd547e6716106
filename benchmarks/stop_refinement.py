"""Three-level refinement of the antiskid stop (issue 33, item 4).

Prints, for the compensated case of ``designs/antiskid-run-dry.toml`` (or
the design named), the braking time to v <= v_stop, the time to omega <= 3
rad/s and the largest creep ratio in traction over lambda_opt at dt, dt/2 and dt/4, with the observed
order and Richardson's error estimate of the dt/4 value
(:func:`workbench.sim.convergence.refinement_check`) against a tolerance
(:data:`TOLERANCES`). A measurement, not a claim: the report refines the metrics of its
findings itself (workbench/papers/p003/antiskid_refine.py, the "Refinement of the
findings" table); this script also shows metrics that enter no finding.

Usage: .venv/bin/python benchmarks/stop_refinement.py [design.toml] [--case NAME]
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from workbench.design import load_design
from workbench.papers.p003 import antiskid_run_spec as S
from workbench.papers.p003.antiskid_scenario import simulate_antiskid
from workbench.report.markdown import fmt
from workbench.sim.convergence import refinement_check

ROOT = Path(__file__).resolve().parents[1]
#: metric -> (tolerance, unit) of the three-level check: the stop-duration
#: claim's 0.5 s for the times; for the largest creep ratio in traction over
#: lambda_opt the requirement's margin 1e-3
TOLERANCES = {"braking_duration": (0.5, "s"), "omega3_after_brake": (0.5, "s"),
              "lam_max_over_opt": (1e-3, "1")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design", nargs="?", default=str(ROOT / "designs/antiskid-run-dry.toml"))
    ap.add_argument("--case", default="compensated")
    a = ap.parse_args()
    spec = load_design(a.design).spec
    K = S.gain_for(spec)[0]
    case = next(c for c in spec.cases if c.name == a.case)
    cs = S.controller_settings(spec, K, case)
    rs = S.run_settings(spec, cs)
    mesh = S.case_mesh(spec, case)
    levels = []
    for k in range(3):
        t0 = time.perf_counter()
        _, m = simulate_antiskid(rs, spec.dt / 2 ** k, record_dt=0.05, mesh=mesh)
        levels.append(S.case_metrics(m, cs, spec.scenario["t_brake"]))
        print(f"dt/{2 ** k}: {time.perf_counter() - t0:.1f} s wall", flush=True)
    print(f"{Path(a.design).name} / {a.case}: dt = {fmt(spec.dt)} s")
    for name, (tol, unit) in TOLERANCES.items():
        q = [lv[name] for lv in levels]
        r = refinement_check(*q, tolerance=tol)
        print(f"{name} ({unit}): {', '.join(fmt(x, 6) for x in q)} at dt, dt/2, dt/4; "
              f"order {fmt(r.order, 3)}, Richardson error {fmt(r.estimate, 3)} "
              f"(tolerance {fmt(tol)}): {r.outcome}")


if __name__ == "__main__":
    main()
