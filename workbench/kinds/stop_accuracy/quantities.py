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
    v<s>.<c>.grid.feasible_max_abs_m      with [grid] feasible_with: largest |error| over the
                                          feasible corners (m)
    v<s>.<c>.grid.failing_feasible_corners ... feasible corners outside the tolerance
    v<s>.<c>.mc.<stat>                    with [montecarlo]: p_within, within_lo, within_hi
                                          (Wilson 95 %), p95_abs_m, mean_m, overshoot_share
    v<s>.<c>.convergence.estimate_m       with [convergence]: Richardson error estimate of
                                          the nominal stop error at dt/4 (m)

With ``[[sections]]`` and ``[repeats]``, per section ``k`` (1, 2, ...) and
repeating controller ``c`` (cm, cm^2, m/s^3)::

    sections[<k>].<c>.mean_abs_cm         mean |stop error| over the repeats
    sections[<k>].<c>.mean_cm             signed mean
    sections[<k>].<c>.var_cm2             variance (ddof 1)
    sections[<k>].<c>.max_abs_cm          largest |stop error|
    sections[<k>].<c>.jerk_mean           mean |da/dt| while moving
    sections.<c>.mean_abs_cm              mean over the sections of mean_abs_cm
    sections.<c>.worst_mean_abs_cm        largest section mean_abs_cm
"""
from __future__ import annotations

import math

import numpy as np

from ...features.montecarlo import MC_QUANTITIES
from ...features.quantities import Declared
from .run import speed_key

__all__ = ["MC_UNITS", "TABLE", "feasible", "mc_family", "over"]

#: Unit of each Monte Carlo statistic of :data:`~workbench.features.montecarlo.MC_QUANTITIES`.
MC_UNITS = {"p_within": "1", "within_lo": "1", "within_hi": "1", "p95_abs_m": "m",
            "mean_m": "m", "overshoot_share": "1"}


def over(names, key: str = "c"):
    """An ``over`` of :class:`Declared`: one member per name of ``names``
    (fixed by the study, not read from the spec), as ``{key: name}``."""
    return lambda spec: [{key: n} for n in names]


def mc_family(prefix: str, members, stats) -> Declared:
    """The Monte Carlo statistics ``<prefix>.<stat>`` (``stat`` of
    :data:`~workbench.features.montecarlo.MC_QUANTITIES`) of every member.

    Parameters
    ----------
    prefix : str
        Name template over the members' keys (``"{s}.{c}.mc"``).
    members : callable
        ``members(spec) -> iterable of dict``: the index of each member.
    stats : callable
        ``stats(result, **index) -> StopStatistics`` of one member.
    """
    return Declared(prefix + ".{k}", "{u}", lambda r, k, u, **ix: getattr(
        stats(r, **ix), MC_QUANTITIES[k]), over=lambda spec: [
            x | {"k": k, "u": MC_UNITS[k]} for x in members(spec) for k in MC_QUANTITIES])


def _speeds(spec):
    return [{"s": speed_key(s), "speed": s} for s in spec.speeds_kmh]


def _cases(spec):
    return [{"s": speed_key(s), "speed": s, "c": c.name} for s in spec.speeds_kmh
            for c in spec.controllers]


def _faults(spec):
    return [x | {"f": f.name} for x in _cases(spec) for f in spec.faults]


def _mc(spec):
    return [] if spec.montecarlo is None else _cases(spec)


def _grid(spec):
    return _cases(spec) if spec.grid else []


def _grid_max(r, s, speed, c):
    e = [abs(x) for x in r.grid[speed, c]]
    return max(e) if all(math.isfinite(x) for x in e) else None


def _feasible_grid(spec):
    return _cases(spec) if spec.grid and spec.grid_feasible else []


def feasible(r, speed) -> list:
    """Per corner of the grid: ``feasible_with`` stops at least the tolerance short."""
    return [e <= -r.spec.tolerance for e in r.grid[speed, r.spec.grid_feasible]]


def _feasible_errors(r, speed, c):
    return [x for x, ok in zip(r.grid[speed, c], feasible(r, speed)) if ok]


def _feasible_max(r, s, speed, c):
    e = [abs(x) for x in _feasible_errors(r, speed, c)]
    return max(e) if e and all(math.isfinite(x) for x in e) else None


def _conv(spec):
    return _cases(spec) if spec.convergence else []


def _finite(x):
    return x if x is not None and math.isfinite(x) else None


def _estimate(r, s, speed, c):
    chk = r.checks.get(f"{s}.{c}.nominal_m")
    return None if chk is None or chk.estimate is None else _finite(chk.estimate)


def _sec_cases(spec):
    rp = spec.sections
    if rp is None:
        return []
    return [{"c": c.name} for c in spec.controllers if not rp.controllers
            or c.name in rp.controllers]


def _sec_cells(spec):
    n = 0 if spec.sections is None else len(spec.sections.sections)
    return [x | {"k": i + 1, "i": i} for i in range(n) for x in _sec_cases(spec)]


def _over_sections(r, c, f):
    return f([r.sections[i, c].mean_abs for i in range(len(r.spec.sections.sections))])


_SECTION_STATS = (("mean_abs_cm", "cm", "mean_abs"), ("mean_cm", "cm", "mean"),
                  ("var_cm2", "cm^2", "var"), ("max_abs_cm", "cm", "max_abs"),
                  ("jerk_mean", "m/s^3", "jerk_mean"))


TABLE = (
    Declared("{s}.distance_m", "m", lambda r, s, speed: r.distance[speed], over=_speeds),
    Declared("{s}.{c}.nominal_m", "m", lambda r, s, speed, c: _finite(r.nominal[speed, c]),
             over=_cases),
    Declared("{s}.{c}.fault[{f}].error_m", "m",
             lambda r, s, speed, c, f: _finite(r.faults[speed, c, f]), over=_faults),
    Declared("{s}.{c}.fault[{f}].change_m", "m",
             lambda r, s, speed, c, f: _finite(abs(r.faults[speed, c, f] - r.nominal[speed, c])),
             over=_faults),
    mc_family("{s}.{c}.mc", _mc, lambda r, s, speed, c: r.mc[speed, c]),
    Declared("{s}.{c}.grid.max_abs_m", "m", _grid_max, over=_grid),
    Declared("{s}.{c}.grid.failing_corners", "1", lambda r, s, speed, c: float(sum(
        not abs(x) <= r.spec.tolerance for x in r.grid[speed, c])), over=_grid),
    Declared("{s}.{c}.grid.feasible_max_abs_m", "m", _feasible_max, over=_feasible_grid),
    Declared("{s}.{c}.grid.failing_feasible_corners", "1", lambda r, s, speed, c: float(sum(
        not abs(x) <= r.spec.tolerance for x in _feasible_errors(r, speed, c))),
        over=_feasible_grid),
    Declared("{s}.{c}.convergence.estimate_m", "m", _estimate, over=_conv),
    *(Declared("sections[{k}].{c}." + name, unit,
               lambda r, k, i, c, a=attr: getattr(r.sections[i, c], a), over=_sec_cells)
      for name, unit, attr in _SECTION_STATS),
    Declared("sections.{c}.mean_abs_cm", "cm",
             lambda r, c: _over_sections(r, c, lambda x: float(np.mean(x))), over=_sec_cases),
    Declared("sections.{c}.worst_mean_abs_cm", "cm",
             lambda r, c: _over_sections(r, c, max), over=_sec_cases),
)
