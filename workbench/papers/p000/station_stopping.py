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

from ...features.quantities import Declared
from ...kinds.stop_accuracy.analysis import Analysis
from ...kinds.stop_accuracy.quantities import mc_family, over
from .station_stopping_spec import (ABLATION, COMPENSATED, CONTROLLERS, DAMPING, MC_CONTROLLERS,
                                    PAPER_CONTROLLERS, UNCOMPENSATED, load)
from .station_stopping_render import render
from .station_stopping_run import run_station_stops

__all__ = ["ANALYSIS", "StationStopping", "TABLE"]


def _per(r, c: str, attr: str) -> list:
    """``attr`` of the section statistics of controller ``c``, per section."""
    return [getattr(r.stats[c, i], attr) for i in range(len(r.sections))]


def _order(r) -> list:
    """The paper's controllers by mean |stop error| over the sections, best first."""
    return sorted(PAPER_CONTROLLERS, key=r.overall)


def _cells(spec) -> list:
    return [{"c": c, "k": i + 1, "i": i} for c in CONTROLLERS
            for i in range(len(spec.sections.sections))]


def _mc(r, group) -> list:
    return [r.mc[c] for c in group]


#: The quantities paper 000's claims name (the paper's rows), declared once.
TABLE = (
    Declared("{c}.mean_abs_cm", "cm", lambda r, c: r.overall(c), over=over(CONTROLLERS)),
    Declared("{c}.worst_section_mean_abs_cm", "cm", lambda r, c: max(_per(r, c, "mean_abs")),
             over=over(CONTROLLERS)),
    Declared("{c}.worst_section_var_cm2", "cm^2", lambda r, c: max(_per(r, c, "var")),
             over=over(CONTROLLERS)),
    Declared("{c}.best_section_mean_abs_cm", "cm", lambda r, c: min(_per(r, c, "mean_abs")),
             over=over(CONTROLLERS)),
    Declared("{c}.jerk_mean", "m/s^3", lambda r, c: float(np.mean(_per(r, c, "jerk_mean"))),
             over=over(CONTROLLERS)),
    Declared("{c}.sections[{k}].mean_abs_cm", "cm", lambda r, c, k, i: r.stats[c, i].mean_abs,
             over=_cells),
    Declared("{c}.sections[{k}].var_cm2", "cm^2", lambda r, c, k, i: r.stats[c, i].var,
             over=_cells),
    Declared("order", "", lambda r: "<".join(_order(r))),
    Declared("best", "", lambda r: _order(r)[0]),
    Declared("{c}.nominal_m", "m", lambda r, c: r.nominal[c].error,
             over=over(MC_CONTROLLERS + ABLATION)),
    mc_family("{c}.mc", over(MC_CONTROLLERS), lambda r, c: r.mc[c]),
    Declared("{c}.damping_zeta", "1", lambda r, c: r.damping[c].zeta, over=over(DAMPING)),
    Declared("{c}.damping_period_s", "s", lambda r, c: r.damping[c].period, over=over(DAMPING)),
    Declared("{c}.speed_sign_changes", "1", lambda r, c: float(r.nominal[c].sign_changes),
             over=over(DAMPING)),
    Declared("mc.compensation_margin", "1", lambda r: min(s.lo for s in _mc(r, COMPENSATED))
             - max(s.hi for s in _mc(r, UNCOMPENSATED))),
    Declared("mc.compensated_max_abs_mean_m", "m",
             lambda r: max(abs(s.mean) for s in _mc(r, COMPENSATED))),
    Declared("mc.uncompensated_min_overshoot_share", "1",
             lambda r: min(s.overshoot for s in _mc(r, UNCOMPENSATED))),
    Declared("mc.compensated_spread", "1", lambda r: max(s.p for s in _mc(r, COMPENSATED))
             - min(s.p for s in _mc(r, COMPENSATED))),
    Declared("nominal.compensated_max_abs_m", "m",
             lambda r: max(abs(r.nominal[c].error) for c in COMPENSATED)),
)


#: the analysis of ``[analysis] module = "p000.station_stopping"``
ANALYSIS = Analysis(TABLE, load, run_station_stops, render)
