"""Predictor-based antiskid controllers of paper 003 and their closed-loop run.

Everything numeric here is ``sympy.lambdify`` of
:func:`workbench.plants.adhesion.adhesion_model` (plant *and* controller
models); the parameters are lambdify arguments, so one compiled function
serves a single run (``math`` backend, floats) and a batch of parameter
samples (``numpy`` backend, arrays) alike.

Controllers (paper 003, section 3):

* acceleration, eq (64): u_ac = (-y2(P) - k_ac (P_lambda - lambda_opt)) / y3(P);
* cruise, eq (61): u_cr = (-d3 + K E(t)) / (d4 v_e(t+h) + d5 lambda_e(t+h) + d6)
  (the numerator uses the *current* error, so the linear loop is
  E' = A E + B K E(t - h), the system the LMI of Theorem 1 certifies);
* braking, eq (69): tracks the desired creep speed v_s* of eqs (76)-(78);
* phases, eq (75): acceleration until the measured speed reaches v_d, cruise
  until t_brake, braking until v <= v_stop (end of the run).

P = X(t + h) is the predictor of Lemma 1, eq (2), computed numerically:
P_n = x_n + (integral over the last h seconds of f(P(s), u(s)) ds), the
integrand stored per step in a :class:`~workbench.sim.history.DelayLine`
(model f of the active phase: eq 65 traction form, eq 62 linear error model,
eq 70 braking form). The initial window follows eq (66): the model is run
from x(0) over [0, h] with the initial input u(theta) = u_init.

Guards (as in the paper): below omega = omega_switch (3 rad/s, eq 76) the
desired creep speed is 0 (creep speed, not creep ratio, is tracked in
braking); the speed in denominators is floored at ``v_floor``; the run ends
at v <= v_stop, where the model (creep ratio divided by v) stops being
meaningful.

Integration: v by explicit Euler; the creep ratio, whose dynamics are stiff
at low speed (d lambda'/d lambda ~ -m g r^2 mu'(lambda) / (J v), a time
constant of about v / 4000 s on dry rail), by the exponential Euler step
lambda+ = lambda + dt phi1(dt J) lambda', J = d lambda'/d lambda from the
sympy Jacobian, phi1(z) = (e^z - 1)/z: exact for the linear part, stable for
any dt J < 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Literal

import numpy as np
import sympy as sp

from ..plants.adhesion import PARAMETER_UNITS, adhesion_model
from ..sim.delay import SimResult, simulate_closed_loop
from ..sim.history import DelayLine

ACCEL, HANDOVER, CRUISE, BRAKE, STOPPED, DIVERGED = 0, 1, 2, 3, 4, 5
PHASE_NAMES = ("acceleration", "handover", "cruise", "braking", "stopped", "diverged")
PARAM_ORDER = tuple(PARAMETER_UNITS)


@lru_cache(maxsize=4)
def model_functions(backend: Literal["math", "numpy"]) -> dict:
    """Lambdified (y1, y2, y3, dy2/dlambda, dy3/dlambda) of eq (13) and the
    (z...) of eq (16), each as one function of (v, lambda, *params) with
    params in :data:`PARAM_ORDER`."""
    mdl = adhesion_model()
    args = (mdl.v, mdl.lam, *[mdl.params[k] for k in PARAM_ORDER])
    out = {}
    for name, (f1, f2, f3) in (("traction", mdl.traction), ("braking", mdl.braking)):
        exprs = (f1, f2, f3, sp.diff(f2, mdl.lam), sp.diff(f3, mdl.lam))
        out[name] = sp.lambdify(args, exprs, modules=backend, cse=True)
    return out


class _Scalar:
    """The few array functions the loop needs, for floats."""
    where = staticmethod(lambda c, a, b: a if c else b)
    maximum, minimum, abs = staticmethod(max), staticmethod(min), staticmethod(abs)
    expm1, sqrt = staticmethod(math.expm1), staticmethod(math.sqrt)
    any = staticmethod(bool)
    batch = False


class _Array:
    where, maximum, minimum, abs = np.where, np.maximum, np.minimum, np.abs
    expm1, sqrt, any = np.expm1, np.sqrt, np.any
    batch = True


@dataclass(frozen=True)
class CreepSpeedProfile:
    """Desired creep speed in braking, eqs (76)-(78) (m/s).

    v_s*(t) = max(vs_min, (c0 - c1 (t - t_brake)) lambda_allow sqrt(v^2 + 1))
    while omega > omega_switch, else 0.
    """

    t_brake: float
    c0: float = 0.06
    c1: float = 0.08
    lambda_allow: float = 0.07
    vs_min: float = -0.15
    omega_switch: float = 3.0

    def __call__(self, t, v, vdot, omega, xp):
        """(v_s*, d v_s*/dt) at time t, speed v, acceleration vdot, wheel speed omega."""
        root = xp.sqrt(v * v + 1.0)
        slope = self.c0 - self.c1 * (t - self.t_brake)
        raw = slope * self.lambda_allow * root
        draw = self.lambda_allow * (-self.c1 * root + slope * v * vdot / root)
        on = omega > self.omega_switch
        free = raw > self.vs_min
        vs = xp.where(on, xp.where(free, raw, self.vs_min), 0.0)
        dvs = xp.where(on & free if xp.batch else (on and free), draw, 0.0)
        return vs, dvs


@dataclass(frozen=True)
class ControllerSettings:
    """Data of controller (75).

    Attributes
    ----------
    params : tuple[float, ...]
        Model constants the controller uses (nominal), in :data:`PARAM_ORDER`.
    v_d, lambda_d, lambda_opt : float
        Cruise speed (m/s), cruise creep ratio, peak-adhesion creep ratio.
    K : tuple[float, float]
        Cruise gain of eq (61).
    lin : dict[str, float]
        a1, a2, d1..d6 of the cruise linearisation (eqs 18, 23).
    k_ac, k_de : float
        Gains of eqs (64), (69) (1/s).
    h_model : float
        Delay the predictor compensates (s).
    profile : CreepSpeedProfile
    compensate : bool
        False: the same laws fed the current state (no predictor).
    handover : {"speed", "creep"}
        "speed" (eq 75 as printed): cruise law from the moment v >= v_d.
        "creep" (workbench variant): at v >= v_d, first eq (64) with target
        lambda_d instead of lambda_opt; the cruise law takes over once
        |lambda - lambda_d| <= ``handover_band``.
    v_stop, v_floor : float
        End of run and speed floor in denominators (m/s).
    lam_diverged : float
        |lambda| at which the run is declared diverged and ended (the
        creep ratio of eq 4 lies in (-1, 1); near +-1 the wheel spins or locks).
    """

    params: tuple
    v_d: float
    lambda_d: float
    lambda_opt: float
    K: tuple
    lin: dict
    k_ac: float
    k_de: float
    h_model: float
    profile: CreepSpeedProfile
    compensate: bool = True
    handover: str = "speed"
    handover_band: float = 0.002
    v_stop: float = 0.05
    v_floor: float = 0.01
    lam_diverged: float = 0.9


def _forms(v, lam, p, fns, xp):
    """(v', lambda'_0, lambda'_u, J_0, J_u) of the form that applies (eq 12 for
    lambda >= 0, eq 15 otherwise): lambda' = lambda'_0 + lambda'_u u."""
    if not xp.batch:
        return fns["traction" if lam >= 0 else "braking"](v, lam, *p)
    tr = fns["traction"](v, lam, *p)
    br = fns["braking"](v, lam, *p)
    pos = lam >= 0
    return tuple(np.where(pos, a, b) for a, b in zip(tr, br))


def wheel_speed(v, lam, r, xp):
    """omega (rad/s) from v and lambda, eqs (4)-(5)."""
    return xp.where(lam >= 0, v / (1.0 - xp.minimum(lam, 0.999)), v * (1.0 + lam)) / r


def creep_speed(v, lam, xp):
    """v_s = v_w - v (m/s)."""
    return xp.where(lam >= 0, lam * v / (1.0 - xp.minimum(lam, 0.999)), lam * v)


def plant_step(x, u, p, dt, fns, xp, v_floor=1e-3):
    """One step of the adhesion plant: explicit Euler in v, exponential Euler
    in the stiff creep ratio (module docstring)."""
    v, lam = x
    vg = xp.maximum(v, v_floor)
    f1, f20, f2u, j0, ju = _forms(vg, lam, p, fns, xp)
    f2 = f20 + f2u * u
    z = (j0 + ju * u) * dt
    big = xp.abs(z) > 1e-8
    zs = xp.where(big, z, 1.0)
    phi = xp.where(big, xp.expm1(zs) / zs, 1.0 + 0.5 * z)
    return (v + dt * f1, lam + dt * phi * f2)


@dataclass
class RunMetrics:
    """Online metrics of a run (floats, or arrays for a batch); NaN = not reached."""

    t_cruise: object = math.nan
    v_at_cruise: object = math.nan
    lam_at_cruise: object = math.nan
    lam_max_traction: object = -math.inf
    v_max: object = -math.inf
    lam_at_brake: object = math.nan
    v_err_at_brake: object = math.nan
    lam_err_at_brake: object = math.nan
    t_lam_negative: object = math.nan
    lam_min_brake: object = math.inf
    t_omega3: object = math.nan
    t_stop: object = math.nan
    t_handover_done: object = math.nan
    t_diverged: object = math.nan
    phase_diverged: object = math.nan
    evs_ema: object = 0.0
    evs_max_late: object = 0.0


class Antiskid003:
    """Controller (75) with the predictor of Lemma 1, as a sampled callable
    ``(t, x, inputs) -> (u, phase)`` for :func:`simulate_closed_loop`.

    Parameters
    ----------
    s : ControllerSettings
    x0 : tuple
        Initial (v, lambda) (for the initial predictor window, eq 66).
    u_init : float
        Input on [-h, 0) (N m).
    dt : float
        Step = sampling period (s).
    batch : int or None
        None: floats; else the number of runs stepped together.
    plant_r : float or array
        Wheel radius of the plant (for the measured wheel speed).
    evs_window : float
        Averaging time of the creep-speed-error metric (s).
    """

    def __init__(self, s: ControllerSettings, x0, u_init: float, dt: float, batch=None,
                 plant_r=None, evs_window: float = 1.0):
        self.s, self.dt = s, dt
        self.xp = _Scalar if batch is None else _Array
        self.fns = model_functions("math" if batch is None else "numpy")
        self.r_c = s.params[PARAM_ORDER.index("r")]
        self.r_p = self.r_c if plant_r is None else plant_r
        self.evs_window = evs_window
        zero = 0.0 if batch is None else np.zeros(batch)
        self.phase = ACCEL if batch is None else np.full(batch, ACCEL)
        self.m = RunMetrics()
        if batch is not None:
            for k, v in vars(self.m).items():
                setattr(self.m, k, np.full(batch, v, float))
        # eq (66): run the traction model from x0 over [0, h] with u_init
        hist_v, hist_l = [], []
        v, lam = (x0[0] + zero, x0[1] + zero)
        line = DelayLine(s.h_model, dt, 0.0)
        p = s.params
        for _ in range(line.N + 1):
            nv, nl = plant_step((v, lam), u_init, p, dt, self.fns, self.xp)
            hist_v.append((nv - v) / dt)
            hist_l.append((nl - lam) / dt)
            v, lam = nv, nl
        self.fv = DelayLine(s.h_model, dt, zero, history=hist_v)
        self.fl = DelayLine(s.h_model, dt, zero, history=hist_l)

    # -- the three laws -------------------------------------------------------------
    def _accel(self, Pv, Pl, target):
        s, p = self.s, self.s.params
        y1, y2, y3, *_ = self.fns["traction"](self.xp.maximum(Pv, s.v_floor), Pl, *p)
        u = (-y2 - s.k_ac * (Pl - target)) / y3
        return u, y1, y2 + y3 * u

    def _cruise(self, v, lam, Pv, Pl):
        s, c = self.s, self.s.lin
        ve, le = Pv - s.v_d, Pl - s.lambda_d
        den = c["d4"] * ve + c["d5"] * le + c["d6"]
        u = (-c["d3"] + s.K[0] * (v - s.v_d) + s.K[1] * (lam - s.lambda_d)) / den
        return u, c["a1"] * ve + c["a2"] * le, c["d1"] * ve + c["d2"] * le + c["d3"] + den * u

    def _brake(self, t, Pv, Pl):
        s, p, xp = self.s, self.s.params, self.xp
        vg = xp.maximum(Pv, s.v_floor)
        z1, z2, z3, *_ = self.fns["braking"](vg, Pl, *p)
        omega = wheel_speed(vg, Pl, self.r_c, xp)
        vs, dvs = s.profile(t + s.h_model, vg, z1, omega, xp)
        u = ((-s.k_de * (vg * Pl - vs) + z1 + dvs) / vg - (1.0 + Pl) / vg * z1 - z2) / z3
        return u, z1, z2 + z3 * u

    # -- one sample -----------------------------------------------------------------
    def __call__(self, t, x, inputs):
        s, xp, m = self.s, self.xp, self.m
        v, lam = x
        if s.compensate:
            Pv, Pl = v + self.fv.window_integral(), lam + self.fl.window_integral()
        else:
            Pv, Pl = v, lam
        ph, B = self.phase, xp.batch
        after = HANDOVER if s.handover == "creep" else CRUISE
        to_cruise = (ph == ACCEL) & (v >= s.v_d) if B else (ph == ACCEL and v >= s.v_d)
        ph = xp.where(to_cruise, after, ph)
        near = xp.abs(lam - s.lambda_d) <= s.handover_band
        handed = (ph == HANDOVER) & near if B else (ph == HANDOVER and near)
        ph = xp.where(handed, CRUISE, ph)
        to_brake = (ph < BRAKE) & (t >= s.profile.t_brake) if B else (
            ph < BRAKE and t >= s.profile.t_brake)
        ph = xp.where(to_brake, BRAKE, ph)
        to_stop = (ph == BRAKE) & (v <= s.v_stop) if B else (ph == BRAKE and v <= s.v_stop)
        ph = xp.where(to_stop, STOPPED, ph)
        bad = ~(xp.abs(lam) < s.lam_diverged) & (ph < STOPPED) if B else (
            not abs(lam) < s.lam_diverged and ph < STOPPED)
        self.m.t_diverged = xp.where(bad, t, self.m.t_diverged)
        self.m.phase_diverged = xp.where(bad, ph, self.m.phase_diverged)
        self.m.t_handover_done = xp.where(handed, t, self.m.t_handover_done)
        ph = xp.where(bad, DIVERGED, ph)
        self.phase = ph
        u = fv = fl = 0.0 * v
        for code, law in ((ACCEL, lambda: self._accel(Pv, Pl, s.lambda_opt)),
                          (HANDOVER, lambda: self._accel(Pv, Pl, s.lambda_d)),
                          (CRUISE, lambda: self._cruise(v, lam, Pv, Pl)),
                          (BRAKE, lambda: self._brake(t, Pv, Pl))):
            sel = ph == code
            if xp.any(sel):
                uc, fvc, flc = law()
                u, fv, fl = xp.where(sel, uc, u), xp.where(sel, fvc, fv), xp.where(sel, flc, fl)
        self.fv.push(fv)
        self.fl.push(fl)
        self._metrics(t, v, lam, ph, to_cruise, to_brake, to_stop)
        return u, ph

    def _metrics(self, t, v, lam, ph, to_cruise, to_brake, to_stop):
        s, xp, m = self.s, self.xp, self.m
        w = xp.where
        m.t_cruise = w(to_cruise, t, m.t_cruise)
        m.v_at_cruise = w(to_cruise, v, m.v_at_cruise)
        m.lam_at_cruise = w(to_cruise, lam, m.lam_at_cruise)
        trac = ph < BRAKE
        m.lam_max_traction = w(trac, xp.maximum(m.lam_max_traction, lam), m.lam_max_traction)
        m.v_max = w(trac, xp.maximum(m.v_max, v), m.v_max)
        m.lam_at_brake = w(to_brake, lam, m.lam_at_brake)
        m.v_err_at_brake = w(to_brake, v - s.v_d, m.v_err_at_brake)
        m.lam_err_at_brake = w(to_brake, lam - s.lambda_d, m.lam_err_at_brake)
        m.t_stop = w(to_stop, t, m.t_stop)
        brk = ph == BRAKE
        if not xp.any(brk):
            return
        first_neg = brk & (lam < 0) & (m.t_lam_negative != m.t_lam_negative) if xp.batch else (
            lam < 0 and math.isnan(m.t_lam_negative))
        m.t_lam_negative = w(first_neg, t, m.t_lam_negative)
        m.lam_min_brake = w(brk, xp.minimum(m.lam_min_brake, lam), m.lam_min_brake)
        omega = wheel_speed(xp.maximum(v, s.v_floor), lam, self.r_p, xp)
        low = brk & (omega <= s.profile.omega_switch) & (m.t_omega3 != m.t_omega3) if xp.batch \
            else (omega <= s.profile.omega_switch and math.isnan(m.t_omega3))
        m.t_omega3 = w(low, t, m.t_omega3)
        # creep-speed error of Theorem 3, e_vs = v_s - v_s*(t) (measured)
        vs_star, _ = s.profile(t, v, 0.0 * v, omega, xp)
        e = xp.abs(creep_speed(v, lam, xp) - vs_star)
        a = self.dt / self.evs_window
        m.evs_ema = w(brk, m.evs_ema + a * (e - m.evs_ema), m.evs_ema)
        late = brk & (t >= s.profile.t_brake + 5.0) if xp.batch else (
            brk and t >= s.profile.t_brake + 5.0)
        m.evs_max_late = w(late, xp.maximum(m.evs_max_late, e), m.evs_max_late)


@dataclass(frozen=True)
class RunSettings:
    """A run of section 4: initial state, initial input, delay, horizon.

    ``plant_params`` is the true plant (may differ from the controller's)."""

    plant_params: tuple
    controller: ControllerSettings
    h: float
    x0: tuple = (3.0, 0.001)
    u_init: float = 100.0
    t_end: float = 400.0


def simulate_antiskid(run: RunSettings, dt: float, *, record_dt: float | None = 0.05,
                      batch: int | None = None) -> tuple[SimResult | None, RunMetrics]:
    """Simulate controller (75) on the delayed plant.

    Parameters
    ----------
    run : RunSettings
        For a batch, ``plant_params`` entries and ``h`` may be arrays... ``h``
        must be one float (a batch shares the delay grid).
    dt : float
        Step and sampling period (s).
    record_dt : float or None
        Recording interval (s); None records nothing (batch Monte Carlo).
    batch : int or None

    Returns
    -------
    (SimResult or None, RunMetrics)
    """
    xp = _Scalar if batch is None else _Array
    fns = model_functions("math" if batch is None else "numpy")
    p = run.plant_params
    ctrl = Antiskid003(run.controller, run.x0, run.u_init, dt, batch,
                       plant_r=p[PARAM_ORDER.index("r")])
    zero = 0.0 if batch is None else np.zeros(batch)

    def step(x, u, t, dt_):
        nx = plant_step(x, u, p, dt_, fns, xp)
        if batch is None:
            return nx
        stop = ctrl.phase >= STOPPED
        return (np.where(stop, x[0], nx[0]), np.where(stop, x[1], nx[1]))

    def done(t, x, ph):
        return bool(np.all(ph >= STOPPED))

    every = 10**12 if record_dt is None else max(int(round(record_dt / dt)), 1)
    x0 = (run.x0[0] + zero, run.x0[1] + zero)
    with np.errstate(all="ignore"):
        res = simulate_closed_loop(step, ctrl, x0, h=run.h, dt=dt, t_end=run.t_end,
                                   u_init=run.u_init + zero, record_every=every, done=done)
    if record_dt is None:
        res = None
    else:
        res = SimResult(res.t, res.x, res.u, res.u_applied, res.phase, ("v", "lambda"),
                        ("u",), dt)
    return res, ctrl.m
