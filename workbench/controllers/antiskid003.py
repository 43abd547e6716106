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

P = X(t + h) is the predictor of Lemma 1, eq (2), computed numerically with
the model of the active phase (eq 65 traction form, eq 62 linear error
model, eq 70 braking form). Default ("rollout"): the model is run from x(t)
through the controller's own inputs of the last h seconds (u on [-h, 0) =
u_init), with the plant's stiff step. Literal form ("recursive"):
P_n = x_n + (integral over the last h seconds of f(P(s), u(s)) ds), the
integrand of past predictions stored per step in a
:class:`~workbench.sim.history.DelayLine`, its initial window from eq (66);
its error obeys a neutral-type equation and fails where the creep dynamics
are stiff (see the antiskid-run-dry report).

Sampling: laws run every step; ``sampling = "stiff"`` holds the torque that
moves the exponential-Euler creep ratio by dt times the rate the continuous
law asks for, including an estimate of the plant-model mismatch so that the
sampled loop's fixed points are the continuous loop's (see
:class:`ControllerSettings`, ``sampling`` and ``observer_tau``).

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
any dt J < 0; a step that would move lambda by more than MAX_DLAMBDA is
halved (adaptive sub-stepping, :func:`stiff_step`, per run in a batch). A
single run may also run on a refined mesh (:class:`Mesh`: steps dt / 2**k
where dt S / v is large), which the runs without the predictor need.

Divergence: a run ends as diverged when |lambda| >= lam_diverged, when a
law commands a torque beyond ``u_range``, or when a plant step cannot be
resolved (:class:`ControllerSettings`); ``RunMetrics.diverged_how`` says
which (:data:`DIVERGED_HOW`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Literal

import numpy as np
import sympy as sp

from ..plants.adhesion import PARAMETER_UNITS, adhesion_model
from ..sim.delay import SimResult, simulate_closed_loop
from ..sim.history import BatchDelayLine, DelayLine, TimedDelayLine

ACCEL, HANDOVER, CRUISE, BRAKE_IN, BRAKE, STOPPED, DIVERGED = range(7)
PHASE_NAMES = ("acceleration", "handover to cruise", "cruise", "handover to braking",
               "braking", "stopped", "diverged")
PARAM_ORDER = tuple(PARAMETER_UNITS)
#: Why a run was declared diverged (``RunMetrics.diverged_how``).
DIVERGED_HOW = ("|lambda| at its limit: spin or lock", "step not resolved", "torque out of range")


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
    any, logical_not = staticmethod(bool), staticmethod(lambda x: not x)
    batch = False


def _any_of(x) -> bool:
    """``np.any`` of a mask, by the array's own method when it is one (the
    loop asks this several times a step; the function form's dispatch costs
    more than the test)."""
    return x.any() if isinstance(x, np.ndarray) else bool(np.any(x))


class _Array:
    where, maximum, minimum, abs = np.where, np.maximum, np.minimum, np.abs
    expm1, sqrt, logical_not = np.expm1, np.sqrt, np.logical_not
    any = staticmethod(_any_of)
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
    sampling : {"stiff", "zoh"}
        How a continuous law is held over a sample. "zoh": the printed value.
        "stiff": the creep ratio reacts to a held torque within a fraction of
        a sample at low speed (time constant ~ v/4000 s), so the printed
        value held for dt realises the continuous law's rate only when
        dt |J| << 1; "stiff" holds u with f20 + f2u u = g / phi1(dt J),
        g = f20 + f2u u_printed, which moves the creep ratio of the
        exponential step by dt g (the continuous law's rate) for any dt J.
    predictor : {"rollout", "recursive"}
        How eq (2) is evaluated: "rollout" runs the phase's model from x(t)
        through the inputs of the last h seconds; "recursive" sums the stored
        f(P(s), u(s)) of past predictions (the literal form of eq 2).
        The recursive form's error obeys e(t) = int_{t-h}^t J e(s) ds, a
        neutral-type equation, and is not robust when J (the creep-ratio
        Jacobian) is stiff, i.e. at low speed.
    cruise_entry : {"speed", "creep"}
        "speed" (eq 75 as printed): cruise law from the moment v >= v_d.
        "creep" (workbench variant): at v >= v_d, first eq (64) with target
        lambda_d instead of lambda_opt; the cruise law takes over once
        |lambda - lambda_d| <= ``handover_band``.
    brake_entry : {"time", "creep"}
        "time" (as printed): braking law (69) from t_brake. "creep"
        (variant): eq (64) with target -``handover_band`` until lambda <= 0,
        where the braking form (eq 15) that eq (69) is built on applies.
    v_stop, v_floor : float
        End of run and speed floor in denominators (m/s).
    lam_diverged : float
        |lambda| at which the run is declared diverged and ended (the
        creep ratio of eq 4 lies in (-1, 1); near +-1 the wheel spins or locks).
        A run is also declared diverged when a law commands |u| > ``u_range``
        or a plant step cannot be resolved
        (a sub-step of dt / 2**MAX_HALVINGS still moves lambda by more than
        MAX_DLAMBDA): the applied torque has left any physical range (e.g.
        law (69) evaluated on the traction side, where its e^{b lambda} terms
        blow up) and the state after that step is not a trajectory of the
        model at any step size; no metric uses it.
    u_range : float
        |u| (N m) above which a commanded torque is out of any physical range
        and the run is declared diverged (inf: never); the designs set it to
        a multiple of the peak adhesion torque mu(lambda_opt) m g r.
    observer_tau : float
        Time constant (s) of the estimate of the model mismatch delta =
        lambda'_plant - lambda'_model that ``sampling = "stiff"`` needs (0:
        none). The stiff hold scales the model's rate g by 1/phi1(dt J); the
        plant's rate is g + delta, and scaling only g leaves delta scaled by
        phi1(dt J) = 1 + dt J / 2 + ..., which moves the loop's fixed points
        by O(dt) when the plant differs from the model (the mass +-5 %
        designs: the slow cruise transient, v - v_d at t_brake, converged only
        at first order). With the estimate the hold realises g + delta, whose
        zeros are the continuous loop's. Estimated in traction and cruise
        only; in braking (speed, hence delta, changing on the time scale of
        the estimate) the plain stiff hold is kept.
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
    sampling: str = "stiff"
    predictor: str = "rollout"
    cruise_entry: str = "speed"
    brake_entry: str = "time"
    handover_band: float = 0.002
    v_stop: float = 0.05
    v_floor: float = 0.01
    lam_diverged: float = 0.9
    u_range: float = math.inf
    observer_tau: float = 0.2


def _forms(v, lam, p, fns, xp):
    """(v', lambda'_0, lambda'_u, J_0, J_u) of the form that applies (eq 12 for
    lambda >= 0, eq 15 otherwise): lambda' = lambda'_0 + lambda'_u u."""
    if not xp.batch:
        return fns["traction" if lam >= 0 else "braking"](v, lam, *p)
    pos = lam >= 0
    if pos.all() or not pos.any():     # one form for the whole batch (NaN: "braking")
        return fns["traction" if pos.all() else "braking"](v, lam, *p)
    tr = fns["traction"](v, lam, *p)
    br = fns["braking"](v, lam, *p)
    return tuple(np.where(pos, a, b) for a, b in zip(tr, br))


def wheel_speed(v, lam, r, xp):
    """omega (rad/s) from v and lambda, eqs (4)-(5)."""
    return xp.where(lam >= 0, v / (1.0 - xp.minimum(lam, 0.999)), v * (1.0 + lam)) / r


def creep_speed(v, lam, xp):
    """v_s = v_w - v (m/s)."""
    return xp.where(lam >= 0, lam * v / (1.0 - xp.minimum(lam, 0.999)), lam * v)


def phi1(z, xp):
    """phi1(z) = (e^z - 1) / z (1 + z/2 near 0)."""
    if not xp.batch:
        return math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z
    big = xp.abs(z) > 1e-8
    if big.all():          # the usual case: the same values, fewer array passes
        return np.expm1(z) / z
    zs = xp.where(big, z, 1.0)
    return xp.where(big, xp.expm1(zs) / zs, 1.0 + 0.5 * z)


def _exp_euler(v, lam, f1, f2, z, dt, xp):
    """(v + dt f1, lambda + dt phi1(z) f2), z = dt d lambda'/d lambda."""
    return v + dt * f1, lam + dt * phi1(z, xp) * f2


#: Largest creep-ratio change of one exponential-Euler step; larger steps are
#: halved (the adhesion curve is far from linear over such a change).
MAX_DLAMBDA = 0.02


#: Halvings :func:`stiff_step` may make (smallest sub-step dt / 2**MAX_HALVINGS).
MAX_HALVINGS = 8


def stiff_step(v, lam, u, dt, evalf, xp, mask=True, depth=0):
    """Explicit Euler in v, exponential Euler in the stiff creep ratio, with
    ``evalf(v, lam) -> (v', lambda'_0, lambda'_u, J_0, J_u)``; halved
    recursively (up to MAX_HALVINGS times) while the creep ratio would move by
    more than MAX_DLAMBDA; in a batch, per run (runs where ``mask`` is false
    are never halved), so each run follows its single-run trajectory."""
    return _stiff_step(v, lam, u, dt, evalf, xp, mask, depth)[:2]


def _stiff_step(v, lam, u, dt, evalf, xp, mask, depth):
    """:func:`stiff_step` plus ``unresolved``: true (per run) when a sub-step
    of dt / 2**MAX_HALVINGS still moved the creep ratio by more than
    MAX_DLAMBDA, i.e. the step could not be resolved."""
    f1, f20, f2u, j0, ju = evalf(v, lam)
    out = _exp_euler(v, lam, f1, f20 + f2u * u, (j0 + ju * u) * dt, dt, xp)
    big = ~(xp.abs(out[1] - lam) <= MAX_DLAMBDA) & mask if xp.batch else \
        not abs(out[1] - lam) <= MAX_DLAMBDA
    if depth < MAX_HALVINGS and xp.any(big):
        sub = mask & big if xp.batch else mask
        hv, hl, bad1 = _stiff_step(v, lam, u, dt / 2, evalf, xp, sub, depth + 1)
        nv, nl, bad2 = _stiff_step(hv, hl, u, dt / 2, evalf, xp, sub, depth + 1)
        if not xp.batch:
            return nv, nl, bad1 or bad2
        # per run: only the runs that need it take the half steps, so a run
        # of a batch follows exactly its single-run trajectory
        return np.where(big, nv, out[0]), np.where(big, nl, out[1]), big & (bad1 | bad2)
    return out[0], out[1], big


def plant_step(x, u, p, dt, fns, xp, v_floor=1e-3, mask=True, with_flag=False):
    """One step of the adhesion plant (module docstring), the form (eq 12 or
    15) chosen by the sign of lambda; ``with_flag``: also return the
    ``unresolved`` flag of :func:`_stiff_step`."""
    out = _stiff_step(x[0], x[1], u, dt,
                      lambda v, lam: _forms(xp.maximum(v, v_floor), lam, p, fns, xp), xp, mask, 0)
    return out if with_flag else out[:2]


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
    v_at_handover: object = math.nan
    lam_at_handover: object = math.nan
    t_diverged: object = math.nan
    phase_diverged: object = math.nan
    diverged_how: object = math.nan   # index into DIVERGED_HOW
    t_past_peak: object = math.nan    # braking: first lambda < -lambda_opt (lock onset)
    evs_last: object = math.nan
    evs_max_tracking: object = math.nan   # NaN: the tracking window was never entered


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
    evs_settle : float
        The creep-speed error is tracked from t_brake + evs_settle (s) while
        omega > omega_switch (``evs_max_tracking``); ``evs_last`` is its
        value at the last braking sample.
    k_max : int or None
        None: every step is ``dt``. Else the loop runs on a refined mesh
        (:func:`~workbench.sim.delay.simulate_closed_loop` with a level, steps
        dt / 2**k, k <= k_max, announced by :meth:`set_step`); the histories
        are then :class:`~workbench.sim.history.TimedDelayLine` and the
        predictor's rollout integrates eq (2) in pieces of the current step,
        the plant's discretisation (a coarser rollout than the plant is
        inconsistent: see ``benchmarks/mesh.py``).
    """

    def __init__(self, s: ControllerSettings, x0, u_init: float, dt: float, batch=None,
                 plant_r=None, evs_settle: float = 5.0, k_max: int | None = None):
        self.s, self.dt, self._dt_prev = s, dt, dt
        self._ticks = self._base = None if k_max is None else 2 ** k_max
        self.xp = _Scalar if batch is None else _Array
        self.fns = model_functions("math" if batch is None else "numpy")
        self.r_c = s.params[PARAM_ORDER.index("r")]
        self.r_p = self.r_c if plant_r is None else plant_r
        self.evs_settle = evs_settle
        self._v_prev = x0[0] + (0.0 if batch is None else np.zeros(batch))
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
        if k_max is None:
            self.fv = DelayLine(s.h_model, dt, zero, history=hist_v)
            self.fl = DelayLine(s.h_model, dt, zero, history=hist_l)
            self.uline = DelayLine(s.h_model, dt, u_init + zero)
        else:
            tick, H = dt / self._base, s.h_model * self._base / dt
            self.fv, self.fl = (TimedDelayLine(H, tick, zero, history=hist,
                                               history_ticks=self._base)
                                for hist in (hist_v, hist_l))
            self.uline = TimedDelayLine(H, tick, u_init + zero)
        self._prev = None          # (v, lambda) of the previous sample
        self.delta = zero          # filtered estimate of the model-mismatch rate of lambda
        #: set by the plant step: the last step could not be resolved (see
        #: ControllerSettings.lam_diverged)
        self.unresolved = False if batch is None else np.zeros(batch, bool)
        self._track_prev = None    # (omega, e_vs left of the switch) of the last tracked sample

    def set_step(self, ticks: int, tick: float) -> None:
        """The step about to start lasts ``ticks`` ticks of ``tick`` s (refined mesh)."""
        self._ticks, self.dt = ticks, ticks * tick

    # -- predictors ----------------------------------------------------------------
    def _model_masks(self, ph):
        """Which runs use which prediction model, for the phases ``ph``:
        (traction, braking, cruise), each None (no run) or (mask, every run)."""
        xp = self.xp
        if not xp.batch:
            return tuple((True, True) if on else None
                         for on in (ph not in (CRUISE, BRAKE), ph == BRAKE, ph == CRUISE))
        out = []
        for sel in ((ph != CRUISE) & (ph < BRAKE), ph == BRAKE, ph == CRUISE):
            out.append((sel, bool(sel.all())) if sel.any() else None)
        return tuple(out)

    def _model_step(self, v, lam, u, dt, ph, masks=None):
        """One step of the phase's prediction model: traction form (eq 65) in
        acceleration and handovers, linear error model (eq 62) in cruise,
        braking form (eq 70) in braking; exponential Euler in lambda.
        ``masks``: :meth:`_model_masks` of ``ph`` (computed when None)."""
        s, xp, p, c = self.s, self.xp, self.s.params, self.s.lin
        m_tr, m_br, m_cr = self._model_masks(ph) if masks is None else masks
        out_v, out_l = v, lam
        for forms, m in (("traction", m_tr), ("braking", m_br)):
            if m is not None:
                sel, every = m
                fn = self.fns[forms]
                nv, nl = stiff_step(v, lam, u, dt, lambda vv, ll: fn(
                    xp.maximum(vv, s.v_floor), ll, *p), xp, sel)
                out_v, out_l = (nv, nl) if every else (xp.where(sel, nv, out_v),
                                                       xp.where(sel, nl, out_l))
        if m_cr is not None:
            sel, every = m_cr
            ve, le = v - s.v_d, lam - s.lambda_d
            den = c["d4"] * ve + c["d5"] * le + c["d6"]
            f2 = c["d1"] * ve + c["d2"] * le + c["d3"] + den * u
            nv, nl = _exp_euler(v, lam, c["a1"] * ve + c["a2"] * le, f2,
                                (c["d2"] + c["d5"] * u) * dt, dt, xp)
            out_v, out_l = (nv, nl) if every else (xp.where(sel, nv, out_v),
                                                   xp.where(sel, nl, out_l))
        return out_v, out_l

    def _rollout(self, v, lam, ph):
        """X(t + h) of eq (2) by running the phase's model from x(t) through
        the inputs of the last h seconds (exact ZOH weights of the window; on
        a refined mesh, in pieces of the current step with the exact average
        input over each)."""
        line, masks = self.uline, self._model_masks(ph)
        for u, d in (line.pieces() if self._base is None else line.pieces(self._ticks)):
            v, lam = self._model_step(v, lam, u, d, ph, masks)
        return v, lam

    # -- the three laws -------------------------------------------------------------
    def _sampled(self, u, f20, f2u, j0, ju):
        """The input to hold over one sample so that the stiff creep ratio
        moves by dt times the rate the continuous law asks for (see
        ``ControllerSettings.sampling``); the printed law when dt J -> 0."""
        if self.s.sampling == "zoh":
            return u
        xp = self.xp
        phi = phi1((j0 + ju * u) * self.dt, xp)
        # the plant's rate at t + h is the model's g = f20 + f2u u plus delta;
        # P came from the model, which lacks delta: the plant at t + h is off
        # by about delta (e^{hJ} - 1) / J, so its rate is g + delta e^{hJ}
        d = self.delta
        if self.s.compensate:
            hj = xp.minimum(xp.maximum((j0 + ju * u) * self.s.h_model, -700.0), 20.0)
            d = d * (1.0 + xp.expm1(hj))
        return ((f20 + f2u * u) / phi + d * (1.0 / phi - 1.0) - f20) / f2u

    def _observe(self, v, lam, ph):
        """Update the filtered estimate ``delta`` of the mismatch rate
        lambda'_plant - lambda'_model from the last step (see
        ``ControllerSettings.observer_tau``): the model says the step from
        the previous sample under the input the controller believes applied,
        u(t - h_model), moves lambda by dt phi1(dt J) (f_model + delta)."""
        s, xp, dt = self.s, self.xp, self._dt_prev
        braking = ph >= BRAKE_IN
        if xp.batch and braking.all() or not xp.batch and braking:
            self.delta = 0.0 * v
        elif self._prev is not None and s.sampling == "stiff" and s.observer_tau > 0:
            pv, pl, pph = self._prev
            ua = self.uline.delayed()
            _, f20, f2u, j0, ju = _forms(xp.maximum(pv, s.v_floor), pl, s.params, self.fns, xp)
            cr = pph == CRUISE      # the cruise law's model is eq (62)
            if xp.any(cr):
                c, ve, le = s.lin, pv - s.v_d, pl - s.lambda_d
                den = c["d4"] * ve + c["d5"] * le + c["d6"]
                f20 = xp.where(cr, c["d1"] * ve + c["d2"] * le + c["d3"], f20)
                f2u, j0 = xp.where(cr, den, f2u), xp.where(cr, c["d2"], j0)
                ju = xp.where(cr, c["d5"], ju)
            d = (lam - pl) / (dt * phi1((j0 + ju * ua) * dt, xp)) - (f20 + f2u * ua)
            new = self.delta + -math.expm1(-dt / s.observer_tau) * (d - self.delta)
            # not in braking (see observer_tau); a non-finite estimate is dropped
            keep = ~(xp.abs(new) < 1e6) | (ph >= BRAKE_IN) if xp.batch else (
                not abs(new) < 1e6 or ph >= BRAKE_IN)
            self.delta = xp.where(keep, 0.0 * v, new)
        self._prev = (v, lam, ph)

    def _accel(self, Pv, Pl, target):
        s, p = self.s, self.s.params
        y1, y2, y3, dy2, dy3 = self.fns["traction"](self.xp.maximum(Pv, s.v_floor), Pl, *p)
        u = self._sampled((-y2 - s.k_ac * (Pl - target)) / y3, y2, y3, dy2, dy3)
        return u, y1, y2 + y3 * u

    def _cruise(self, v, lam, Pv, Pl):
        s, c = self.s, self.s.lin
        ve, le = Pv - s.v_d, Pl - s.lambda_d
        den = c["d4"] * ve + c["d5"] * le + c["d6"]
        u = (-c["d3"] + s.K[0] * (v - s.v_d) + s.K[1] * (lam - s.lambda_d)) / den
        u = self._sampled(u, c["d1"] * ve + c["d2"] * le + c["d3"], den, c["d2"], c["d5"])
        return u, c["a1"] * ve + c["a2"] * le, c["d1"] * ve + c["d2"] * le + c["d3"] + den * u

    def _brake(self, t, Pv, Pl):
        s, p, xp = self.s, self.s.params, self.xp
        vg = xp.maximum(Pv, s.v_floor)
        z1, z2, z3, dz2, dz3 = self.fns["braking"](vg, Pl, *p)
        omega = wheel_speed(vg, Pl, self.r_c, xp)
        vs, dvs = s.profile(t + s.h_model, vg, z1, omega, xp)
        u = ((-s.k_de * (vg * Pl - vs) + z1 + dvs) / vg - (1.0 + Pl) / vg * z1 - z2) / z3
        u = self._sampled(u, z2, z3, dz2, dz3)
        return u, z1, z2 + z3 * u

    # -- one sample -----------------------------------------------------------------
    def __call__(self, t, x, inputs):
        s, xp, m = self.s, self.xp, self.m
        v, lam = x
        ph, B = self.phase, xp.batch
        after = HANDOVER if s.cruise_entry == "creep" else CRUISE
        to_cruise = (ph == ACCEL) & (v >= s.v_d) if B else (ph == ACCEL and v >= s.v_d)
        ph = xp.where(to_cruise, after, ph)
        near = xp.abs(lam - s.lambda_d) <= s.handover_band
        handed = (ph == HANDOVER) & near if B else (ph == HANDOVER and near)
        ph = xp.where(handed, CRUISE, ph)
        to_brake = (ph < BRAKE_IN) & (t >= s.profile.t_brake) if B else (
            ph < BRAKE_IN and t >= s.profile.t_brake)
        ph = xp.where(to_brake, BRAKE_IN if s.brake_entry == "creep" else BRAKE, ph)
        braked = (ph == BRAKE_IN) & (lam <= 0) if B else (ph == BRAKE_IN and lam <= 0)
        ph = xp.where(braked, BRAKE, ph)
        in_brake = (ph == BRAKE_IN) | (ph == BRAKE) if B else ph in (BRAKE_IN, BRAKE)
        to_stop = in_brake & (v <= s.v_stop) if B else (in_brake and v <= s.v_stop)
        ph = xp.where(to_stop, STOPPED, ph)
        unres = self.unresolved
        bad = (~(xp.abs(lam) < s.lam_diverged) | unres) & (ph < STOPPED) if B else (
            (not abs(lam) < s.lam_diverged or unres) and ph < STOPPED)
        self.m.t_diverged = xp.where(bad, t, self.m.t_diverged)
        self.m.phase_diverged = xp.where(bad, ph, self.m.phase_diverged)
        self.m.diverged_how = xp.where(bad, xp.where(unres, 1.0, 0.0), self.m.diverged_how)
        self.m.t_handover_done = xp.where(handed, t, self.m.t_handover_done)
        self.m.v_at_handover = xp.where(handed, v, self.m.v_at_handover)
        self.m.lam_at_handover = xp.where(handed, lam, self.m.lam_at_handover)
        ph = xp.where(bad, DIVERGED, ph)
        self.phase = ph
        try:
            self._observe(v, lam, ph)
            u, fv, fl = self._laws(t, v, lam, ph)
        except (OverflowError, ZeroDivisionError, ValueError):
            if xp.batch:   # numpy gives inf/nan instead; never reached
                raise
            # floats: a model evaluation overflowed (e.g. a predicted creep ratio
            # far outside (-1, 1)): the run has diverged
            self.m.t_diverged, self.m.phase_diverged = t, ph
            self.phase = ph = DIVERGED
            u = fv = fl = 0.0
        wild = ~(xp.abs(u) <= s.u_range) & (ph < STOPPED) if B else (
            not abs(u) <= s.u_range and ph < STOPPED)
        if xp.any(wild):    # the law has left any physical range: the run has diverged
            self.m.t_diverged = xp.where(wild, t, self.m.t_diverged)
            self.m.phase_diverged = xp.where(wild, ph, self.m.phase_diverged)
            self.m.diverged_how = xp.where(wild, 2.0, self.m.diverged_how)
            self.phase = ph = xp.where(wild, DIVERGED, ph)
            u, fv, fl = (xp.where(wild, 0.0, a) for a in (u, fv, fl))
        self.fv.push(fv, self._ticks)
        self.fl.push(fl, self._ticks)
        self.uline.push(u, self._ticks)
        self._metrics(t, v, lam, ph, to_cruise, to_brake, to_stop)
        self._dt_prev = self.dt
        return u, ph

    def _laws(self, t, v, lam, ph):
        """(u, predicted v', predicted lambda') of the active laws."""
        s, xp = self.s, self.xp
        if not s.compensate:
            Pv, Pl = v, lam
        elif s.predictor == "rollout":
            Pv, Pl = self._rollout(v, lam, ph)
        else:
            Pv, Pl = v + self.fv.window_integral(), lam + self.fl.window_integral()
        u = fv = fl = 0.0 * v
        for code, law in ((ACCEL, lambda: self._accel(Pv, Pl, s.lambda_opt)),
                          (HANDOVER, lambda: self._accel(Pv, Pl, s.lambda_d)),
                          (CRUISE, lambda: self._cruise(v, lam, Pv, Pl)),
                          (BRAKE_IN, lambda: self._accel(Pv, Pl, -s.handover_band)),
                          (BRAKE, lambda: self._brake(t, Pv, Pl))):
            sel = ph == code
            if xp.any(sel):
                uc, fvc, flc = law()
                u, fv, fl = xp.where(sel, uc, u), xp.where(sel, fvc, fv), xp.where(sel, flc, fl)
        return u, fv, fl

    def _metrics(self, t, v, lam, ph, to_cruise, to_brake, to_stop):
        s, xp, m = self.s, self.xp, self.m
        w = xp.where
        # crossing time of v = v_d, interpolated between the last two samples
        frac = (v - s.v_d) / xp.maximum(v - self._v_prev, 1e-12)
        m.t_cruise = w(to_cruise, t - self._dt_prev * xp.minimum(frac, 1.0), m.t_cruise)
        self._v_prev = v
        m.v_at_cruise = w(to_cruise, v, m.v_at_cruise)
        m.lam_at_cruise = w(to_cruise, lam, m.lam_at_cruise)
        trac = ph < BRAKE_IN
        m.lam_max_traction = w(trac, xp.maximum(m.lam_max_traction, lam), m.lam_max_traction)
        m.v_max = w(trac, xp.maximum(m.v_max, v), m.v_max)
        m.lam_at_brake = w(to_brake, lam, m.lam_at_brake)
        m.v_err_at_brake = w(to_brake, v - s.v_d, m.v_err_at_brake)
        m.lam_err_at_brake = w(to_brake, lam - s.lambda_d, m.lam_err_at_brake)
        m.t_stop = w(to_stop, t, m.t_stop)
        brk = (ph == BRAKE_IN) | (ph == BRAKE) if xp.batch else ph in (BRAKE_IN, BRAKE)
        if not xp.any(brk):
            return
        first_neg = brk & (lam < 0) & (m.t_lam_negative != m.t_lam_negative) if xp.batch else (
            lam < 0 and math.isnan(m.t_lam_negative))
        m.t_lam_negative = w(first_neg, t, m.t_lam_negative)
        m.lam_min_brake = w(brk, xp.minimum(m.lam_min_brake, lam), m.lam_min_brake)
        omega = wheel_speed(xp.maximum(v, s.v_floor), lam, self.r_p, xp)
        ws, no = s.profile.omega_switch, xp.logical_not
        # creep-speed error of Theorem 3, e_vs = v_s - v_s*(t) (measured), and
        # its left limit at omega = omega_switch (v_s* still on the profile)
        vs_on, _ = s.profile(t, v, 0.0 * v, math.inf + 0.0 * v, xp)
        vs_star = xp.where(omega > ws, vs_on, 0.0)          # eq (76)
        vs = creep_speed(v, lam, xp)
        e, e_on = xp.abs(vs - vs_star), xp.abs(vs - vs_on)
        m.evs_last = w(brk, e, m.evs_last)
        # The tracking window runs from t_brake + evs_settle to the first of
        # omega <= omega_switch (v_s* drops to 0, eq 76) and the lock onset,
        # lambda < -lambda_opt (the wheel passes the braking adhesion peak; the
        # divergence metrics report what follows). Both crossings are
        # interpolated linearly between the samples around them: the error
        # may be steep there, and the first sample past a crossing alone would
        # make the metric depend on where the grid falls.
        in_window = (m.t_omega3 != m.t_omega3) & (m.t_past_peak != m.t_past_peak)
        cross_w = brk & (omega <= ws) & (m.t_omega3 != m.t_omega3)
        cross_l = brk & (lam < -s.lambda_opt) & (m.t_past_peak != m.t_past_peak)
        if self._track_prev is None:
            f_w = f_l = 1.0 + 0.0 * v
            e_prev = e_on
        else:
            w_prev, e_prev, l_prev = self._track_prev
            clip = lambda x: xp.minimum(xp.maximum(x, 0.0), 1.0)
            f_w = clip((w_prev - ws) / xp.maximum(w_prev - omega, 1e-300))
            f_l = clip((l_prev + s.lambda_opt) / xp.maximum(l_prev - lam, 1e-300))
        m.t_omega3 = w(cross_w, t - self._dt_prev * (1.0 - f_w), m.t_omega3)
        m.t_past_peak = w(cross_l, t - self._dt_prev * (1.0 - f_l), m.t_past_peak)
        settled = brk & in_window & (t >= s.profile.t_brake + self.evs_settle)
        inside = settled & no(cross_w) & no(cross_l)
        fmax = lambda a, b: w(a != a, b, xp.maximum(a, b))   # NaN = no value yet
        m.evs_max_tracking = w(inside, fmax(m.evs_max_tracking, e), m.evs_max_tracking)
        f_end = xp.minimum(w(cross_w, f_w, 1.0), w(cross_l, f_l, 1.0))
        e_end = e_prev + f_end * (e_on - e_prev)
        end = settled & (cross_w | cross_l)
        m.evs_max_tracking = w(end, fmax(m.evs_max_tracking, e_end), m.evs_max_tracking)
        self._track_prev = (omega, e_on, lam)


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


@lru_cache(maxsize=1)
def _creep_rate_coefficient():
    """S(params) with S / v the creep-ratio rate |d lambda'/d lambda| at
    lambda = 0, the steepest point of the adhesion curve: m g r^2 mu'(0) / J
    (eq 13, dominant term; the rest is O(zeta / J))."""
    mdl = adhesion_model()
    p = mdl.params
    S = sp.diff(mdl.mu_traction, mdl.lam).subs(mdl.lam, 0) * p["m"] * p["g"] * p["r"] ** 2 / p["J"]
    return sp.lambdify([p[k] for k in PARAM_ORDER], S, "math")


@dataclass(frozen=True)
class Mesh:
    """Refined mesh of a single run, set by the creep-ratio time constant.

    The step is dt / 2**k with k the smallest level (at most ``k_max``) with
    (dt_ref / 2**k) S / v <= ``courant``, S / v the fastest creep-ratio rate
    (:func:`_creep_rate_coefficient`, ~3800/v 1/s on dry rail). ``dt_ref``
    is the design's step: a run at dt_ref / 2 then takes exactly half of
    every step of the run at dt_ref, so step halving still compares a mesh
    with its refinement.

    Why: without the predictor, the loop at low speed is close to neutral
    (near a creep ratio with slope J, lambda' ~ J lambda - (J + k) lambda(t - h),
    roots decaying at only (1/h) ln(|J| / |J + k|)), so fast features of
    width ~1/|J| set at the start persist for seconds; the exponential step
    keeps them stable but only a step below 1/|J| resolves them.
    """

    dt_ref: float
    courant: float
    k_max: int

    def level(self, v: float, S: float) -> int:
        rate = self.dt_ref * S / (self.courant * max(v, 1e-3))
        return 0 if rate <= 1.0 else min(self.k_max, math.ceil(math.log2(rate)))


def simulate_antiskid(run: RunSettings, dt: float, *, record_dt: float | None = 0.05,
                      batch: int | None = None,
                      mesh: Mesh | None = None) -> tuple[SimResult | None, RunMetrics]:
    """Simulate controller (75) on the delayed plant.

    Parameters
    ----------
    run : RunSettings
        For a batch, ``plant_params`` entries and ``h`` may be (B,) arrays
        (one value per run).
    dt : float
        Step and sampling period (s).
    record_dt : float or None
        Recording interval (s); None records nothing (batch Monte Carlo).
    batch : int or None
    mesh : Mesh, optional
        Single runs only: refine the step where the creep ratio is fast
        (:class:`Mesh`); None: every step is ``dt``.

    Returns
    -------
    (SimResult or None, RunMetrics)
    """
    if mesh is not None and batch is not None:
        raise ValueError("a refined mesh is for single runs (batch=None)")
    xp = _Scalar if batch is None else _Array
    fns = model_functions("math" if batch is None else "numpy")
    p = run.plant_params
    ctrl = Antiskid003(run.controller, run.x0, run.u_init, dt, batch,
                       plant_r=p[PARAM_ORDER.index("r")],
                       k_max=None if mesh is None else mesh.k_max)
    zero = 0.0 if batch is None else np.zeros(batch)

    def step(x, u, t, dt_):
        if batch is None:
            *nx, ctrl.unresolved = plant_step(x, u, p, dt_, fns, xp, with_flag=True)
            return tuple(nx)
        stop = ctrl.phase >= STOPPED
        *nx, unres = plant_step(x, u, p, dt_, fns, xp, mask=~stop, with_flag=True)
        ctrl.unresolved = unres & ~stop
        return (np.where(stop, x[0], nx[0]), np.where(stop, x[1], nx[1]))

    def done(t, x, ph):
        return bool((ph >= STOPPED).all()) if batch is not None else ph >= STOPPED

    every = 10**12 if record_dt is None else max(int(round(record_dt / dt)), 1)
    x0 = (run.x0[0] + zero, run.x0[1] + zero)
    line = None if batch is None else BatchDelayLine(np.broadcast_to(run.h, (batch,)), dt,
                                                      run.u_init)
    level = None
    if mesh is not None:
        S = _creep_rate_coefficient()(*p)
        level = lambda x: mesh.level(x[0], S)
    with np.errstate(all="ignore"):
        res = simulate_closed_loop(step, ctrl, x0, h=float(np.max(run.h)), dt=dt,
                                   t_end=run.t_end, u_init=run.u_init + zero,
                                   record_every=every, done=done, line=line, level=level,
                                   k_max=0 if mesh is None else mesh.k_max)
    if record_dt is None:
        res = None
    else:
        res = SimResult(res.t, res.x, res.u, res.u_applied, res.phase, ("v", "lambda"),
                        ("u",), dt)
    return res, ctrl.m
