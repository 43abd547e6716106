"""Study ``station-stopping``: PID, SMC and SMARC station stops of paper 000,
as in the paper and with known-delay compensation.

The design tables and controller variants are in
:mod:`~workbench.papers.p000.station_stopping_spec`, the simulation in
:mod:`~workbench.papers.p000.station_stopping_run`; this module is the study object
(quantities for the claims).
"""
from __future__ import annotations

import numpy as np

from ...features.montecarlo import MC_QUANTITIES
from ...reader import Reader
from .station_stopping_run import StopResult, run_station_stops
from .station_stopping_spec import (COMPENSATED, CONTROLLERS, DAMPING, MC_CONTROLLERS,
                                    PAPER_CONTROLLERS, UNCOMPENSATED, VARIANTS, StopSpec,
                                    load_stop_spec)

__all__ = ["STUDY", "StationStopping"]



class StationStopping:
    kind = "station-stopping"
    uses_solver = False    # no convex solver runs: the report says so
    #: numerical step refined (dt/2, dt/4) for the findings (workbench.refinement)
    refine_field, refine_unit = "dt", "s"

    def load(self, root: Reader) -> StopSpec:
        return load_stop_spec(root)

    def quantity_names(self, spec: StopSpec) -> set[str]:
        names = {"order", "best", "mc.compensation_margin", "mc.compensated_max_abs_mean_m",
                 "mc.uncompensated_min_overshoot_share", "mc.compensated_spread",
                 "nominal.compensated_max_abs_m"}
        for c in CONTROLLERS:
            names |= {f"{c}.mean_abs_cm", f"{c}.worst_section_mean_abs_cm",
                      f"{c}.worst_section_var_cm2",
                      f"{c}.best_section_mean_abs_cm", f"{c}.jerk_mean"}
            for i in range(len(spec.sections)):
                names |= {f"{c}.sections[{i + 1}].mean_abs_cm", f"{c}.sections[{i + 1}].var_cm2"}
        for c in MC_CONTROLLERS:
            names |= {f"{c}.nominal_m"} | {f"{c}.mc.{k}" for k in MC_QUANTITIES}
        for c in DAMPING:
            names |= {f"{c}.damping_zeta", f"{c}.damping_period_s", f"{c}.speed_sign_changes"}
        names |= {f"{c}.nominal_m" for c in VARIANTS if "+" in c}
        return names

    def run(self, design) -> StopResult:
        return run_station_stops(design.spec)

    def quantities(self, res: StopResult) -> dict:
        q = {}
        ns = len(res.sections)
        for c in CONTROLLERS:
            per = [res.stats[c, i].mean_abs for i in range(ns)]
            q[f"{c}.mean_abs_cm"] = res.overall(c)
            q[f"{c}.worst_section_mean_abs_cm"] = max(per)
            q[f"{c}.worst_section_var_cm2"] = max(res.stats[c, i].var for i in range(ns))
            q[f"{c}.best_section_mean_abs_cm"] = min(per)
            q[f"{c}.jerk_mean"] = float(np.mean([res.stats[c, i].jerk_mean for i in range(ns)]))
            for i in range(ns):
                q[f"{c}.sections[{i + 1}].mean_abs_cm"] = res.stats[c, i].mean_abs
                q[f"{c}.sections[{i + 1}].var_cm2"] = res.stats[c, i].var
        order = sorted(PAPER_CONTROLLERS, key=res.overall)
        q["order"] = "<".join(order)
        q["best"] = order[0]
        for c, run in res.nominal.items():
            q[f"{c}.nominal_m"] = run.error
        for c, st in res.mc.items():
            q |= {f"{c}.mc.{k}": getattr(st, a) for k, a in MC_QUANTITIES.items()}
        for c, d in res.damping.items():
            q[f"{c}.damping_zeta"] = d.zeta
            q[f"{c}.damping_period_s"] = d.period
            q[f"{c}.speed_sign_changes"] = float(res.nominal[c].sign_changes)
        comp, unc = [res.mc[c] for c in COMPENSATED], [res.mc[c] for c in UNCOMPENSATED]
        q["mc.compensation_margin"] = min(s.lo for s in comp) - max(s.hi for s in unc)
        q["mc.compensated_max_abs_mean_m"] = max(abs(s.mean) for s in comp)
        q["mc.uncompensated_min_overshoot_share"] = min(s.overshoot for s in unc)
        q["mc.compensated_spread"] = max(s.p for s in comp) - min(s.p for s in comp)
        q["nominal.compensated_max_abs_m"] = max(abs(res.nominal[c].error) for c in COMPENSATED)
        return q


STUDY = StationStopping()
