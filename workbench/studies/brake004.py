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

from ..controllers.fuzzy import FuzzyIncrement
from ..controllers.pid import PID
from ..reader import Quantity, Reader
from ..sim.stopping import batch_params, simulate
from .stopping000_spec import load_plant

MODES = ("open", "ato-open", "closed")
#: not a control mode: full service from t = 0, to test each corner's feasibility
FULL = "full-service"
CHANNELS = ("analogue", "3bit")
#: axle-sensor cases at the nominal corner: name -> states of the 4 axles
FAULTS = {"healthy": "oooo", "1 sliding": "sooo", "3 failed": "fffo",
          "2 sliding + 1 failed": "ssfo", "all 4 failed": "ffff", "all 4 sliding": "ssss"}


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


def _load(root: Reader) -> Spec004:
    params = load_plant(root)
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
                   t_predict=ct.number("t_predict", nonneg=True, hi=5.0), dt=0.0, dt_ctrl=0.0)
    ct.finish()
    sim = root.table("sim")
    spec = Spec004(**{**spec.__dict__, "dt": sim.number("dt", positive=True, hi=0.05),
                      "dt_ctrl": sim.number("dt_ctrl", positive=True, hi=1.0)})
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
    p = batch_params({k: q.value for k, q in spec.params.items()}, 1)
    tr = simulate(p, lambda t, o: np.full(1, spec.a_target), n=1, t_end=200.0, dt=spec.dt,
                  dt_ctrl=spec.dt_ctrl, v0=v0)
    return float(tr.x_stop[0])


def run_grid(spec: Spec004, *, debug: dict | None = None) -> Result004:
    runs = _cases(spec)
    n = len(runs)
    D = {s: stopping_point(spec, s / 3.6) for s in spec.speeds_kmh}
    arr = lambda f: np.array([f(r) for r in runs], float)
    base = {k: q.value for k, q in spec.params.items()}
    p = batch_params(base, n, {"K1": base["K1"] * arr(lambda r: r.friction),
                               "v_ho": np.where(arr(lambda r: r.electric) > 0, base["v_ho"], 1e3)})
    dist = arr(lambda r: D[r.speed_kmh])
    mode = np.array([(*MODES, FULL).index(r.mode) for r in runs])
    bits = np.array([r.channel == "3bit" for r in runs])
    states = np.array([list(FAULTS[r.fault]) for r in runs])           # (n, 4)
    fallback = np.all(states != "o", axis=1)
    closed = (mode == 2) & ~fallback
    idx_closed = np.flatnonzero(closed)
    pids = {j: PID(**spec.pid, dt=spec.dt_ctrl) for j in idx_closed}
    st = {"c": np.zeros(n), "a_f": np.zeros(n), "v_prev": None, "e_prev": np.zeros(n),
          "anchor": np.zeros(n), "in_pid": np.zeros(n, bool)}

    def policy(t, o):
        a_now = np.maximum(-o.a, 0.0)
        tp = spec.t_predict       # ATO predicts over the brake's dead time
        v_p = np.maximum(o.v - a_now * tp, 0.0)
        d_go = dist - o.x - 0.5 * (o.v + v_p) * tp
        a_req = np.where(d_go > 0, v_p**2 / (2 * np.maximum(d_go, spec.d_min)), spec.c_full)
        axles = np.where(states == "o", o.v[:, None],
                         np.where(states == "s", o.v[:, None] * (1 - spec.slide), 0.0))
        v_m = axles.max(axis=1)
        if st["v_prev"] is None:
            st["v_prev"] = v_m.copy()
        raw = (st["v_prev"] - v_m) / spec.dt_ctrl
        st["v_prev"] = v_m
        k = spec.dt_ctrl / (spec.tau_filter + spec.dt_ctrl)
        st["a_f"] = st["a_f"] + k * (raw - st["a_f"])
        e = a_req - st["a_f"]
        de = (e - st["e_prev"]) / spec.dt_ctrl
        st["e_prev"] = e
        # closed loop: command = a_req (feed-forward) + correction; the correction is
        # integrated by the fuzzy increments, or set by PID around its value at the switch
        corr = st["c"]
        small = np.abs(e) <= spec.e_switch
        enter = small & ~st["in_pid"]
        st["anchor"] = np.where(enter, corr, st["anchor"])
        for j in idx_closed:
            if enter[j]:
                pids[j].reset()
        fz = corr + spec.fuzzy.increment(e, de)
        pid_out = st["anchor"].copy()
        for j in idx_closed:
            if small[j]:
                pid_out[j] += pids[j].step(float(e[j]))
        corr = np.clip(np.where(small, pid_out, fz), -spec.c_full, spec.c_full)
        st["in_pid"] = small
        st["c"] = np.where(closed, corr, 0.0)
        c_closed = a_req + corr
        c_new = np.where(mode == 0, spec.a_target, np.where(closed, c_closed, a_req))
        c_new = np.where(mode == 3, spec.c_full, c_new)
        if debug is not None:
            debug.setdefault("rows", []).append((t, a_req.copy(), st["a_f"].copy(), c_new.copy(),
                                                 d_go.copy(), o.v.copy()))
        c_new = np.clip(c_new, 0.0, spec.c_full)
        q = np.round(c_new / spec.c_full * 7) / 7 * spec.c_full
        return np.where(bits, q, c_new)

    v0 = arr(lambda r: r.speed_kmh / 3.6)
    tr = simulate(p, policy, n=n, t_end=float(2 * (v0 / spec.a_target).max() + 60), dt=spec.dt,
                  dt_ctrl=spec.dt_ctrl, dt_rec=0.5, v0=v0,
                  theta=arr(lambda r: r.gradient), kappa=1 + arr(lambda r: r.force_error),
                  c_min=0.0, c_max=spec.c_full)
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
                     tuple(feasible[k] for k in keep), curves)


def _key(x: float) -> str:
    return f"{x:g}"


class ClosedLoopBrake:
    kind = "closed-loop-brake"
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
            names |= {f"{b}.fault[{f}].abs_m" for f in FAULTS if f != "healthy"}
            names |= {f"{b}.fault[{f}].change_vs_healthy_m" for f in FAULTS if f != "healthy"}
            names.add(f"{b}.closed.3bit_minus_analogue_m")
        return names

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
                    q[f"{b}.fault[{f}].change_vs_healthy_m"] = abs(
                        res.select(fault=f, **nominal)[0][1] - healthy)
            for mode in ("closed", "ato-open"):
                q[f"{b}.electric_loss.{mode}.abs_m"] = res.max_abs(speed_kmh=s, mode=mode,
                                                                   electric=False)
        return q


STUDY = ClosedLoopBrake()
