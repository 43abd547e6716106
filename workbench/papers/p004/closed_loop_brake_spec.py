"""Paper 004's own tables of designs/closed-loop-brake-004.toml and its check of the design.

``[worked]`` (the inputs of section 1.3's worked numbers, computed from
sympy expressions written here once) and ``[retuning] t_predict_sweep`` are
paper 004's; :func:`load` checks that the design has the controllers,
grid, faults and constants the report's runs name.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ...kinds.stop_accuracy.needs import require
from ...reader import Quantity, Reader
from .closed_loop_brake_run import ELECTRIC_LOSS, FACTORS, FAULT_NAMES

__all__ = ["NEEDS", "Paper004", "Worked", "compute_worked", "load", "worked_formulas"]


@lru_cache(maxsize=1)
def worked_formulas():
    """Sympy expressions of paper 004 section 1.3: (symbols, distance, degraded
    deceleration, gradient share)."""
    v, a, err, i, g, a_brake = sp.symbols("v a epsilon i g a_b", real=True)
    distance = v**2 / (2 * a)                                 # constant-deceleration stop
    grade = g * sp.sin(sp.atan(i / 1000))                     # along-track gravity, i in permille
    degraded = a * (1 - err) - grade                          # force error + down-grade
    share = grade / a_brake
    return (v, a, err, i, g, a_brake), distance, degraded, share


@dataclass(frozen=True)
class Worked:
    v_kmh: float
    v_printed: Quantity
    a_full: Quantity
    force_error: float
    gradient_permille: float
    shares: tuple  # (gradient permille, fraction of full brake)
    g: float


@dataclass(frozen=True)
class Paper004:
    """What the analysis reads besides the kind's tables: ``[worked]`` and
    ``[retuning] t_predict_sweep`` (ATO horizons, s)."""

    worked: Worked
    t_predict_sweep: tuple


#: The controllers the analysis runs by name.
NEEDS = ("open", "ato_open", "closed", "closed_3bit", "full_service")


def load(root: Reader, spec) -> Paper004:
    """Check that ``spec`` has what the report's runs need and read ``[worked]``
    and ``[retuning]``."""
    require(root, spec, "p004.closed_loop_brake", controllers=NEEDS,
            loops=("closed", "closed_3bit"), grid=FACTORS,
            feasible_with="full_service", faults=(*FAULT_NAMES, ELECTRIC_LOSS),
            constants=("t_p", "d_min"), tables=("command", "montecarlo"))
    w = root.table("worked")
    shares = []
    for s in w.tables("shares"):
        shares.append((s.number("gradient_permille", positive=True),
                       s.number("brake_fraction", positive=True, hi=1.0)))
        s.finish()
    worked = Worked(w.number("v_kmh", positive=True), w.quantity("v_printed", "m/s", positive=True),
                    w.quantity("a_full", "m/s^2", positive=True),
                    w.number("force_error", lo=0.0, hi=0.9),
                    w.number("gradient_permille", lo=0.0, hi=100.0), tuple(shares),
                    spec.params["g"].value)
    w.finish()
    rt = root.table("retuning")
    sweep = rt.numbers("t_predict_sweep", what="horizons (s)")
    if not all(0 <= x <= 5.0 for x in sweep):
        raise rt.fail("t_predict_sweep", list(sweep), "horizons in [0, 5] s")
    rt.finish()
    return Paper004(worked, tuple(sweep))


def compute_worked(w: Worked) -> dict:
    (v, a, err, i, g, a_b), distance, degraded, share = worked_formulas()
    v_exact = w.v_kmh / 3.6
    a2 = float(degraded.subs({a: w.a_full.value, err: w.force_error, i: w.gradient_permille,
                              g: w.g}))
    d = lambda vv, aa: float(distance.subs({v: vv, a: aa}))
    out = {"d1": d(w.v_printed.value, w.a_full.value), "d1_exact_speed": d(v_exact, w.a_full.value),
           "a2": a2, "a2_printed": round(a2, 3)}
    out["d2"] = d(w.v_printed.value, a2)
    out["delta"] = out["d2"] - out["d1"]
    out["delta_exact_speed"] = d(v_exact, a2) - out["d1_exact_speed"]
    out["delta_rounded_inputs"] = d(w.v_printed.value, out["a2_printed"]) - out["d1"]
    for gp, frac in w.shares:
        out[f"share[{gp:g}permille,{frac:g}]"] = 100 * float(
            share.subs({g: w.g, i: gp, a_b: frac * w.a_full.value}))
    return out
