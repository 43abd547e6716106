"""Paper 000's station stops (PID, SMC, SMARC; designs/stopping-line5.toml):
the ``[analysis]`` module of a ``stop-accuracy`` design.

The design is a configuration of the general kind
(:mod:`workbench.kinds.stop_accuracy`: the laws are its expressions and named
modules, the runs its simulation, :mod:`.station_stopping_run`). What stays
here is paper 000's: the names of the quantities its claims use (the paper's
rows: ``smarc.mean_abs_cm``, ``pid-damped.damping_zeta``, ...), the damping
analysis of the PID gains, the printed Tables 3-4 and the report's wording
(:mod:`.station_stopping_render`).
"""
from __future__ import annotations

import numpy as np

from ...features.montecarlo import MC_QUANTITIES
from .station_stopping_spec import (COMPENSATED, CONTROLLERS, DAMPING, MC_CONTROLLERS,
                                    PAPER_CONTROLLERS, UNCOMPENSATED, VARIANTS, load)

__all__ = ["ANALYSIS", "StationStopping"]


class StationStopping:
    """The analysis of ``[analysis] module = "p000.station_stopping"``."""

    def load(self, root, spec):
        return load(root, spec)

    def quantity_names(self, spec) -> set[str]:
        names = {"order", "best", "mc.compensation_margin", "mc.compensated_max_abs_mean_m",
                 "mc.uncompensated_min_overshoot_share", "mc.compensated_spread",
                 "nominal.compensated_max_abs_m"}
        for c in CONTROLLERS:
            names |= {f"{c}.mean_abs_cm", f"{c}.worst_section_mean_abs_cm",
                      f"{c}.worst_section_var_cm2",
                      f"{c}.best_section_mean_abs_cm", f"{c}.jerk_mean"}
            for i in range(len(spec.sections.sections)):
                names |= {f"{c}.sections[{i + 1}].mean_abs_cm", f"{c}.sections[{i + 1}].var_cm2"}
        for c in MC_CONTROLLERS:
            names |= {f"{c}.nominal_m"} | {f"{c}.mc.{k}" for k in MC_QUANTITIES}
        for c in DAMPING:
            names |= {f"{c}.damping_zeta", f"{c}.damping_period_s", f"{c}.speed_sign_changes"}
        names |= {f"{c}.nominal_m" for c in VARIANTS if "+" in c}
        return names

    def run(self, spec):
        from .station_stopping_run import run_station_stops
        return run_station_stops(spec)

    def quantities(self, res) -> dict:
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

    def render(self, design, res):
        from .station_stopping_render import render
        return render(design, res)


ANALYSIS = StationStopping()
