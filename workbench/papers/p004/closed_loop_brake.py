"""Study ``closed-loop-brake``: paper 004's deceleration feedback against the
open-loop brake, over an error grid, on the paper-000 brake plant.

Worked numbers of section 1.3 (stopping distances, gradient shares) are
computed from sympy expressions written here once. The simulations brake a
train from each initial speed to a stopping point D (the nominal open-loop
stopping distance of the single command ``a_target``) in three modes:

``open``
    one brake command a_target, held (the "large open loop" of section 1);
``ato-open``
    the ATO re-commands a_req = v^2 / (2 d_go) every cycle, the brake
    executes it open loop (today's practice, and the fallback of section 2.7);
``closed``
    the ATO's a_req is the *target deceleration* of the command generator,
    which measures the deceleration from the axle speeds (train speed = max
    of 4 axles) and closes the loop: incremental fuzzy control when
    |error| > e_switch, PID (shared :class:`~workbench.controllers.pid.PID`)
    otherwise (section 2.5); all four axles failed or sliding -> fallback
    to ``ato-open``.

Each mode runs over force error x gradient x friction scatter, with an
analogue (PWM / network) or a 3-bit (levels 0-7) command channel, plus
sensor-fault and electric-brake-loss cases at the nominal corner.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ...controllers.fuzzy import FuzzyIncrement
from ...features.montecarlo import MC_QUANTITIES, MonteCarloSpec, load_montecarlo
from ...kinds.stop_accuracy.pipeline import open_loop_distance, read_brake_plant
from ...reader import Quantity, Reader
from ...tuning.pid import Damping, damping, deceleration_loop
from .closed_loop_brake_run import (CHANNELS, CONTROLLERS, FAULTS, FULL, MC_FACTORS, MC_MODES,
                                    run_horizon_sweep, run_montecarlo, simulate_brake)

__all__ = ["STUDY", "Result004", "Run", "Spec004", "compute_worked", "decel_damping", "run_grid",
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
class Spec004:
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
    high_ratio: float = 1.1                   # a sensor reading high reads this x the speed
    montecarlo: MonteCarloSpec | None = None
    t_predict_sweep: tuple = ()               # ATO horizons (s) of the retuning sweep


def _load(root: Reader) -> Spec004:
    params = read_brake_plant(root)
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
                    params["g"].value)
    w.finish()
    sc = root.table("scenario")
    speeds = sc.numbers("speeds_kmh", positive=True)
    a_t = sc.number("a_target", positive=True, hi=2.0)
    c_full = sc.number("c_full", positive=True, hi=2.0)
    fe = sc.numbers("force_error")
    gr = sc.numbers("gradient")
    fr = sc.numbers("friction", positive=True)
    if any(abs(x) >= 0.9 for x in fe):
        raise sc.fail("force_error", list(fe), "fractions in (-0.9, 0.9)")
    tol = sc.number("tolerance", positive=True)
    sc.finish()
    ct = root.table("control")
    fz = ct.table("fuzzy")
    fuzzy = FuzzyIncrement(fz.number("e_scale", positive=True), fz.number("de_scale", positive=True),
                           fz.number("du_scale", positive=True))
    fz.finish()
    p = ct.table("pid")
    pid = {k: p.number(k, nonneg=True) for k in ("kp", "ki", "kd")}
    p.finish()
    spec = Spec004(params, worked, speeds, a_t, c_full, fe, gr, fr, tol, fuzzy,
                   e_switch=ct.number("e_switch", positive=True), pid=pid,
                   tau_filter=ct.number("tau_filter", nonneg=True),
                   slide=ct.number("slide_ratio", positive=True, hi=1.0),
                   d_min=ct.number("d_min", positive=True),
                   t_predict=ct.number("t_predict", nonneg=True, hi=5.0), dt=0.0, dt_ctrl=0.0,
                   high_ratio=ct.number("high_ratio", lo=1.0, hi=2.0,
                                        what="ratio >= 1 (a sensor reading high)"),
                   t_predict_sweep=ct.numbers("t_predict_sweep", what="horizons (s)"))
    if not all(0 <= x <= 5.0 for x in spec.t_predict_sweep):
        raise ct.fail("t_predict_sweep", list(spec.t_predict_sweep), "horizons in [0, 5] s")
    ct.finish()
    mc = load_montecarlo(root, {k: f.positive for k, f in MC_FACTORS.items()})
    sim = root.table("sim")
    spec = Spec004(**{**spec.__dict__, "dt": sim.number("dt", positive=True, hi=0.05),
                      "dt_ctrl": sim.number("dt_ctrl", positive=True, hi=1.0), "montecarlo": mc})
    sim.finish()
    return spec


@dataclass(frozen=True)
class Run:
    """One simulated case."""

    speed_kmh: float
    mode: str
    channel: str
    force_error: float
    gradient: float
    friction: float
    fault: str
    electric: bool


@dataclass(frozen=True)
class Result004:
    worked: dict
    distance: dict          # speed -> stopping point D (m)
    runs: tuple             # Run
    errors: tuple           # stop error (m) per run (nan: no stop)
    tolerance: float        # m, platform-door tolerance
    feasible: tuple         # per run: full service can hold a_target on that corner
    curves: tuple = ()      # (Run, position - D (m), speed (m/s)) of the curve corners
    mc: dict | None = None  # (speed km/h, mode) -> StopStatistics of the Monte Carlo
    damping: Damping | None = None   # of the linearised deceleration PID loop
    sweep: tuple = ()       # (ATO horizon s, speed km/h, nominal closed-loop stop error m)

    def failing(self, **kw) -> list[tuple[Run, float]]:
        """Runs (with errors) outside the tolerance among those selected."""
        return [(r, e) for r, e in self.select(**kw) if not abs(e) <= self.tolerance]

    def select(self, **kw) -> list[tuple[Run, float]]:
        return [(r, e) for r, e in zip(self.runs, self.errors)
                if all(getattr(r, k) == v for k, v in kw.items())]

    def max_abs(self, **kw) -> float:
        errs = [abs(e) for _, e in self.select(**kw)]
        return float(max(errs)) if errs and all(np.isfinite(errs)) else float("nan")


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


def _cases(spec: Spec004) -> list[Run]:
    runs = []
    for s in spec.speeds_kmh:
        for fe, gr, fr in itertools.product(spec.force_error, spec.gradient, spec.friction):
            runs.append(Run(s, "open", "analogue", fe, gr, fr, "healthy", True))
            runs.append(Run(s, FULL, "analogue", fe, gr, fr, "healthy", True))
            runs.append(Run(s, "ato-open", "analogue", fe, gr, fr, "healthy", True))
            for ch in CHANNELS:
                runs.append(Run(s, "closed", ch, fe, gr, fr, "healthy", True))
        for f in FAULTS:
            if f != "healthy":
                runs.append(Run(s, "closed", "analogue", 0.0, 0.0, 1.0, f, True))
        for mode in ("ato-open", "closed"):
            runs.append(Run(s, mode, "analogue", 0.0, 0.0, 1.0, "healthy", False))
    return runs


def stopping_point(spec: Spec004, v0: float) -> float:
    """Nominal open-loop stopping distance of the single command (m)."""
    return open_loop_distance({k: q.value for k, q in spec.params.items()}, spec.a_target, v0,
                              dt=spec.dt, dt_ctrl=spec.dt_ctrl)


def run_grid(spec: Spec004, *, montecarlo: bool = True) -> Result004:
    """The error grid, the sensor faults, the electric-brake loss; with
    ``montecarlo`` also the Monte Carlo and the horizon sweep."""
    runs = _cases(spec)
    n = len(runs)
    D = {s: stopping_point(spec, s / 3.6) for s in spec.speeds_kmh}
    arr = lambda f: np.array([f(r) for r in runs], float)
    base = {k: q.value for k, q in spec.params.items()}
    dist = arr(lambda r: D[r.speed_kmh])
    tr = simulate_brake(
        spec, v0=arr(lambda r: r.speed_kmh / 3.6), dist=dist,
        controller=np.array([list(CONTROLLERS).index((r.mode, r.channel)) for r in runs]),
        states=np.array([list(FAULTS[r.fault]) for r in runs]),
        overrides={"K1": base["K1"] * arr(lambda r: r.friction),
                   "v_ho": np.where(arr(lambda r: r.electric) > 0, base["v_ho"], 1e3)},
        theta=arr(lambda r: r.gradient), kappa=1 + arr(lambda r: r.force_error))
    err = tr.x_stop - dist
    full = {(r.speed_kmh, r.force_error, r.gradient, r.friction): e
            for r, e in zip(runs, err) if r.mode == FULL}
    feasible = [bool(full.get((r.speed_kmh, r.force_error, r.gradient, r.friction), -1.0)
                     <= -spec.tolerance) for r in runs]
    keep = [k for k, r in enumerate(runs) if r.mode != FULL]
    corners = {(0.0, 0.0, 1.0), (min(spec.force_error), 0.0, 1.0)}
    curves = tuple((r, tr.x[:, k] - dist[k], tr.v[:, k]) for k, r in enumerate(runs)
                   if r.speed_kmh == spec.speeds_kmh[0] and r.fault == "healthy" and r.electric
                   and (r.force_error, r.gradient, r.friction) in corners and r.mode != FULL)
    return Result004(compute_worked(spec.worked), D, tuple(runs[k] for k in keep),
                     tuple(float(err[k]) for k in keep), spec.tolerance,
                     tuple(feasible[k] for k in keep), curves,
                     run_montecarlo(spec, D) if montecarlo else None, decel_damping(spec),
                     run_horizon_sweep(spec, D) if montecarlo else ())


def decel_damping(spec: Spec004) -> Damping:
    """Damping of the linearised deceleration PID loop (electric stage, dead
    time T1 plus one control period: sample and hold, and the backward
    difference of the measured speed)."""
    p = {k: q.value for k, q in spec.params.items()}
    return damping(*deceleration_loop(spec.pid["kp"], spec.pid["ki"], P1=p["P1"], T2=p["T2"],
                                      tau=spec.tau_filter), p["T1"] + spec.dt_ctrl)


def _key(x: float) -> str:
    return f"{x:g}"


class ClosedLoopBrake:
    kind = "closed-loop-brake"
    #: numerical step refined (dt/2, dt/4) for the findings (workbench.refinement)
    refine_field, refine_unit = "dt", "s"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader) -> Spec004:
        return _load(root)

    def quantity_names(self, spec: Spec004) -> set[str]:
        names = {f"worked.{k}" for k in compute_worked(spec.worked)}
        for s in spec.speeds_kmh:
            b = f"v{_key(s)}"
            names |= {f"{b}.open.max_abs_m", f"{b}.ato-open.max_abs_m",
                      f"{b}.closed.analogue.max_abs_m", f"{b}.closed.3bit.max_abs_m",
                      f"{b}.closed.analogue.failing_corners", f"{b}.closed.3bit.failing_corners",
                      f"{b}.closed.analogue.failing_feasible_corners",
                      f"{b}.closed.3bit.failing_feasible_corners",
                      f"{b}.closed.analogue.feasible_max_abs_m",
                      f"{b}.closed.3bit.feasible_max_abs_m",
                      f"{b}.electric_loss.closed.abs_m", f"{b}.electric_loss.ato-open.abs_m"}
            names |= {f"{b}.fault[{f}].{k}" for f in FAULTS if f != "healthy"
                      for k in ("abs_m", "error_m", "change_vs_healthy_m")}
            names |= {f"{b}.closed.3bit_minus_analogue_m", f"{b}.nominal.closed.analogue.abs_m",
                      f"{b}.nominal.closed.3bit.abs_m", f"{b}.nominal.ato-open.abs_m"}
            names |= {f"{b}.mc.{m}.{k}" for m in MC_MODES for k in MC_QUANTITIES}
            names.add(f"{b}.mc.closed_minus_ato-open_p")
        return names | {"pid.damping_zeta"}

    def run(self, design) -> Result004:
        return run_grid(design.spec)

    def quantities(self, res: Result004) -> dict:
        q = {f"worked.{k}": v for k, v in res.worked.items()}
        for s in res.distance:
            b = f"v{_key(s)}"
            grid = dict(speed_kmh=s, fault="healthy", electric=True)
            q[f"{b}.open.max_abs_m"] = res.max_abs(mode="open", **grid)
            q[f"{b}.ato-open.max_abs_m"] = res.max_abs(mode="ato-open", **grid)
            for ch in CHANNELS:
                sel = res.select(mode="closed", channel=ch, **grid)
                q[f"{b}.closed.{ch}.max_abs_m"] = res.max_abs(mode="closed", channel=ch, **grid)
                q[f"{b}.closed.{ch}.failing_corners"] = float(len(res.failing(
                    mode="closed", channel=ch, **grid)))
                q[f"{b}.closed.{ch}.failing_feasible_corners"] = float(sum(
                    res.feasible[res.runs.index(r)] for r, _ in res.failing(
                        mode="closed", channel=ch, **grid)))
                feas = [abs(e) for r, e in sel if res.feasible[res.runs.index(r)]]
                q[f"{b}.closed.{ch}.feasible_max_abs_m"] = max(feas) if feas else None
            q[f"{b}.closed.3bit_minus_analogue_m"] = (q[f"{b}.closed.3bit.feasible_max_abs_m"]
                                                      - q[f"{b}.closed.analogue.feasible_max_abs_m"])
            nominal = dict(speed_kmh=s, mode="closed", channel="analogue", force_error=0.0,
                           gradient=0.0, friction=1.0, electric=True)
            healthy = res.select(fault="healthy", **nominal)[0][1]
            for f in FAULTS:
                if f != "healthy":
                    q[f"{b}.fault[{f}].abs_m"] = res.max_abs(speed_kmh=s, fault=f)
                    q[f"{b}.fault[{f}].error_m"] = res.select(fault=f, **nominal)[0][1]
                    q[f"{b}.fault[{f}].change_vs_healthy_m"] = abs(
                        res.select(fault=f, **nominal)[0][1] - healthy)
            q[f"{b}.nominal.closed.analogue.abs_m"] = abs(healthy)
            q[f"{b}.nominal.closed.3bit.abs_m"] = abs(res.select(
                fault="healthy", **{**nominal, "channel": "3bit"})[0][1])
            q[f"{b}.nominal.ato-open.abs_m"] = abs(res.select(
                fault="healthy", **{**nominal, "mode": "ato-open"})[0][1])
            for mode in ("closed", "ato-open"):
                q[f"{b}.electric_loss.{mode}.abs_m"] = res.max_abs(speed_kmh=s, mode=mode,
                                                                   electric=False)
            for m in MC_MODES:
                st = res.mc[s, m]
                q |= {f"{b}.mc.{m}.{k}": getattr(st, a) for k, a in MC_QUANTITIES.items()}
            q[f"{b}.mc.closed_minus_ato-open_p"] = res.mc[s, "closed"].p - res.mc[s, "ato-open"].p
        q["pid.damping_zeta"] = res.damping.zeta
        return q


STUDY = ClosedLoopBrake()
