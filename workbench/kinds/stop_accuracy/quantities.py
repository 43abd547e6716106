"""Claimable quantities of a ``stop-accuracy`` design, declared once
(:mod:`workbench.features.quantities`).

Per speed ``v<s>`` (km/h, e.g. ``v50``) and controller ``c``::

    v<s>.distance_m                       the stopping point D (m)
    v<s>.<c>.nominal_m                    stop error on the nominal plant (m, + = overshoot)
    v<s>.<c>.fault[<f>].error_m           ... under fault f
    v<s>.<c>.fault[<f>].change_m          |fault error - nominal error| (m)
    v<s>.<c>.grid.max_abs_m               with [grid]: largest |error| over the corners (m)
    v<s>.<c>.grid.failing_corners         ... corners outside the tolerance (a run without
                                          a stop counts)
    v<s>.<c>.mc.<stat>                    with [montecarlo]: p_within, within_lo, within_hi
                                          (Wilson 95 %), p95_abs_m, mean_m, overshoot_share
    v<s>.<c>.convergence.estimate_m       with [convergence]: Richardson error estimate of
                                          the nominal stop error at dt/4 (m)
"""
from __future__ import annotations

import math

from ...features.montecarlo import MC_QUANTITIES
from ...features.quantities import Declared
from .run import speed_key

__all__ = ["TABLE"]

_MC_UNITS = {"p_within": "1", "within_lo": "1", "within_hi": "1", "p95_abs_m": "m",
             "mean_m": "m", "overshoot_share": "1"}


def _speeds(spec):
    return [{"s": speed_key(s), "speed": s} for s in spec.speeds_kmh]


def _cases(spec):
    return [{"s": speed_key(s), "speed": s, "c": c.name} for s in spec.speeds_kmh
            for c in spec.controllers]


def _faults(spec):
    return [x | {"f": f.name} for x in _cases(spec) for f in spec.faults]


def _mc(spec):
    if spec.montecarlo is None:
        return []
    return [x | {"k": k, "u": _MC_UNITS[k]} for x in _cases(spec) for k in MC_QUANTITIES]


def _grid(spec):
    return _cases(spec) if spec.grid else []


def _grid_max(r, s, speed, c):
    e = [abs(x) for x in r.grid[speed, c]]
    return max(e) if all(math.isfinite(x) for x in e) else None


def _conv(spec):
    return _cases(spec) if spec.convergence else []


def _finite(x):
    return x if x is not None and math.isfinite(x) else None


def _estimate(r, s, speed, c):
    chk = r.checks.get(f"{s}.{c}.nominal_m")
    return None if chk is None or chk.estimate is None else _finite(chk.estimate)


TABLE = (
    Declared("{s}.distance_m", "m", lambda r, s, speed: r.distance[speed], over=_speeds),
    Declared("{s}.{c}.nominal_m", "m", lambda r, s, speed, c: _finite(r.nominal[speed, c]),
             over=_cases),
    Declared("{s}.{c}.fault[{f}].error_m", "m",
             lambda r, s, speed, c, f: _finite(r.faults[speed, c, f]), over=_faults),
    Declared("{s}.{c}.fault[{f}].change_m", "m",
             lambda r, s, speed, c, f: _finite(abs(r.faults[speed, c, f] - r.nominal[speed, c])),
             over=_faults),
    Declared("{s}.{c}.mc.{k}", "{u}", lambda r, s, speed, c, k, u: getattr(
        r.mc[speed, c], MC_QUANTITIES[k]), over=_mc),
    Declared("{s}.{c}.grid.max_abs_m", "m", _grid_max, over=_grid),
    Declared("{s}.{c}.grid.failing_corners", "1", lambda r, s, speed, c: float(sum(
        not abs(x) <= r.spec.tolerance for x in r.grid[speed, c])), over=_grid),
    Declared("{s}.{c}.convergence.estimate_m", "m", _estimate, over=_conv),
)
