"""Paper 004's own tables and its view of designs/closed-loop-brake-004.toml.

``[worked]`` (the inputs of section 1.3's worked numbers, computed from
sympy expressions written here once) and ``[retuning] t_predict_sweep`` are
paper 004's; :func:`view` gives the design's ``stop-accuracy`` spec in the
names of the report (a_target, the grid's force error, gradient and
friction, the command generator's gains).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ...controllers.fuzzy import FuzzyIncrement
from ...reader import Quantity, Reader

__all__ = ["NEEDS", "Paper004", "Spec004", "Worked", "compute_worked", "load", "view",
           "worked_formulas"]


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


@dataclass(frozen=True)
class Spec004:
    """The paper's view of the design: its ``stop-accuracy`` spec (``kind``)
    in the names of the report (:func:`view`)."""

    params: dict
    worked: Worked
    speeds_kmh: tuple
    a_target: float
    c_full: float
    force_error: tuple
    gradient: tuple
    friction: tuple
    tolerance: float
    fuzzy: FuzzyIncrement
    e_switch: float
    pid: dict
    tau_filter: float
    slide: float
    d_min: float
    t_predict: float
    dt: float
    dt_ctrl: float
    high_ratio: float
    montecarlo: object                        # MonteCarloSpec
    t_predict_sweep: tuple                    # ATO horizons (s) of the retuning sweep
    kind: object                              # the StopAccuracySpec


#: The controllers, grid factors and constants the analysis reads from the design.
NEEDS = ("open", "ato_open", "closed", "closed_3bit", "full_service")


def load(root: Reader, spec) -> Paper004:
    """Check that ``spec`` has what the report's runs need and read ``[worked]``
    and ``[retuning]``."""
    names = [c.name for c in spec.controllers]
    grid = dict(spec.grid)
    if (names[:len(NEEDS)] != list(NEEDS) or any(spec.controllers[names.index(k)].loop is None
                                                for k in ("closed", "closed_3bit"))
            or set(grid) != {"force_error", "gradient", "friction"} or spec.command is None
            or spec.montecarlo is None or "t_p" not in spec.constants
            or "d_min" not in spec.constants):
        raise root.fail("analysis.module", "p004.closed_loop_brake", "a design with the "
                        "controllers " + ", ".join(NEEDS) + " (closed and closed_3bit with a "
                        "deceleration_loop), a [grid] of force_error, gradient and friction, a "
                        "[target] command, [montecarlo] and the constants t_p and d_min")
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


def view(spec) -> Spec004:
    """The paper's view of the ``stop-accuracy`` spec ``spec`` (its values, at
    its step ``dt``: a refined spec gives a refined view)."""
    loop = spec.controllers[NEEDS.index("closed")].loop.values(spec.constants)
    grid, const = dict(spec.grid), spec.constants
    return Spec004(spec.params, spec.paper.worked, spec.speeds_kmh, spec.command, spec.c_max,
                   grid["force_error"], grid["gradient"], grid["friction"], spec.tolerance,
                   FuzzyIncrement(loop["e_scale"], loop["de_scale"], loop["du_scale"]),
                   loop["e_switch"], {k: loop[k] for k in ("kp", "ki", "kd")},
                   loop["tau_filter"], loop["slide_ratio"], const["d_min"].value,
                   const["t_p"].value, spec.dt, spec.dt_ctrl, loop["high_ratio"],
                   spec.montecarlo, spec.paper.t_predict_sweep, spec)


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
