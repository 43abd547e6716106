"""Predictor-based antiskid controllers of paper 003.

Everything numeric here is ``sympy.lambdify`` of
:func:`workbench.plants.adhesion.adhesion_model` through
:mod:`workbench.sim.wheel_slip` (plant *and* controller models); one compiled
function serves a single run (floats) and a batch of parameter samples
(arrays) alike.

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

Integration: the predictor steps the model with the plant's own kernel
(:mod:`workbench.sim.wheel_slip`: explicit Euler in v, exponential Euler in
the stiff creep ratio, adaptive halving); on a refined mesh (the run's
``Mesh``) the controller is told each step's length by :meth:`Antiskid003.set_step`.

Divergence: a run ends as diverged when |lambda| >= lam_diverged, when a
law commands a torque beyond ``u_range``, or when a plant step cannot be
resolved (:class:`ControllerSettings`); :class:`PhaseEvents` records when,
in which phase and why (:data:`DIVERGED_HOW`). Every other run metric is
the caller's: the controller calls ``recorder(t, v, lambda, phase,
to_cruise, to_brake, to_stop, dt_prev)`` once per sample (the antiskid-run
study's recorder, :mod:`workbench.papers.p003.antiskid_scenario`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..sim.history import DelayLine, TimedDelayLine
from ..sim.wheel_slip import (PARAM_ORDER, ArrayOps, ScalarOps,
                              exp_euler, model_functions, phi1, plant_forms, plant_step,
                              stiff_step, wheel_speed)
from .antiskid003_scalar import ScalarSample, _scalar_stiff_step
from .antiskid003_settings import (ACCEL, BRAKE, BRAKE_IN, CRUISE, DIVERGED, DIVERGED_HOW,
                                   HANDOVER, STOPPED, ControllerSettings)


@dataclass
class PhaseEvents:
    """What the controller's phase logic decided (floats, or arrays for a
    batch); NaN = did not happen."""

    t_handover_done: object = math.nan
    v_at_handover: object = math.nan
    lam_at_handover: object = math.nan
    t_diverged: object = math.nan
    phase_diverged: object = math.nan
    diverged_how: object = math.nan   # index into DIVERGED_HOW


class Antiskid003(ScalarSample):
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
    recorder : callable, optional
        Called once per sample with ``(t, v, lambda, phase, to_cruise,
        to_brake, to_stop, dt_prev)`` (the run's metrics; see the module
        docstring).
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
                 recorder=None, k_max: int | None = None):
        self.s, self.dt, self._dt_prev = s, dt, dt
        self._ticks = self._base = None if k_max is None else 2 ** k_max
        self.xp = ScalarOps if batch is None else ArrayOps
        self.fns = model_functions("math" if batch is None else "numpy")
        self.r_c = s.params[PARAM_ORDER.index("r")]
        self.recorder = recorder
        zero = 0.0 if batch is None else np.zeros(batch)
        self.phase = ACCEL if batch is None else np.full(batch, ACCEL)
        self.events = PhaseEvents()
        if batch is not None:
            for k, v in vars(self.events).items():
                setattr(self.events, k, np.full(batch, v, float))
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
        #: None, or ``measure(v, lambda) -> (v_m, lambda_m)``: what the
        #: controller sees of the true state at each sample (measurement
        #: noise, :func:`workbench.sim.perturb.measured_state`); the
        #: divergence test and the recorder keep the true state
        self.measure = None

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
        if not xp.batch:     # a single run: the same operations as below, less Python
            if ph != CRUISE:
                return _scalar_stiff_step(v, lam, u, dt, self.fns["braking" if ph == BRAKE else
                                                                  "traction"], s.v_floor, p, 0)
            ve, le = v - s.v_d, lam - s.lambda_d
            den = c["d4"] * ve + c["d5"] * le + c["d6"]
            f2 = c["d1"] * ve + c["d2"] * le + c["d3"] + den * u
            z = (c["d2"] + c["d5"] * u) * dt
            return v + dt * (c["a1"] * ve + c["a2"] * le), lam + dt * (
                math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z) * f2
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
            nv, nl = exp_euler(v, lam, c["a1"] * ve + c["a2"] * le, f2,
                                (c["d2"] + c["d5"] * u) * dt, dt, xp)
            out_v, out_l = (nv, nl) if every else (xp.where(sel, nv, out_v),
                                                   xp.where(sel, nl, out_l))
        return out_v, out_l

    def _rollout(self, v, lam, ph):
        """X(t + h) of eq (2) by running the phase's model from x(t) through
        the inputs of the last h seconds (exact ZOH weights of the window; on
        a refined mesh, in pieces of the current step with the exact average
        input over each)."""
        line = self.uline
        pieces = line.pieces() if self._base is None else line.pieces(self._ticks)
        if not self.xp.batch:
            return self._rollout_scalar(v, lam, ph, pieces)
        return self._rollout_generic(v, lam, ph, pieces)

    def _rollout_generic(self, v, lam, ph, pieces):
        """:meth:`_rollout` for a batch (arrays) or a single run (floats), one
        :meth:`_model_step` per piece."""
        masks = self._model_masks(ph) if self.xp.batch else None
        for u, d in pieces:
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
        if not self.xp.batch:
            return self._observe_scalar(v, lam, ph)
        self._observe_generic(v, lam, ph)

    def _observe_generic(self, v, lam, ph):
        """:meth:`_observe` for a batch (arrays) or a single run (floats)."""
        s, xp, dt = self.s, self.xp, self._dt_prev
        braking = ph >= BRAKE_IN
        if xp.batch and braking.all() or not xp.batch and braking:
            self.delta = 0.0 * v
        elif self._prev is not None and s.sampling == "stiff" and s.observer_tau > 0:
            pv, pl, pph = self._prev
            ua = self.uline.delayed()
            _, f20, f2u, j0, ju = plant_forms(xp.maximum(pv, s.v_floor), pl, s.params, self.fns, xp)
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
        if not self.xp.batch:
            return self._call_scalar(t, x)
        return self._call_generic(t, x)

    def _call_generic(self, t, x):
        """One sample, for a batch (arrays) or a single run (floats)."""
        s, xp = self.s, self.xp
        v_true, lam_true = x
        v, lam = x if self.measure is None else self.measure(v_true, lam_true)
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
        bad = (~(xp.abs(lam_true) < s.lam_diverged) | unres) & (ph < STOPPED) if B else (
            (not abs(lam_true) < s.lam_diverged or unres) and ph < STOPPED)
        self.events.t_diverged = xp.where(bad, t, self.events.t_diverged)
        self.events.phase_diverged = xp.where(bad, ph, self.events.phase_diverged)
        self.events.diverged_how = xp.where(bad, xp.where(unres, 1.0, 0.0), self.events.diverged_how)
        self.events.t_handover_done = xp.where(handed, t, self.events.t_handover_done)
        self.events.v_at_handover = xp.where(handed, v, self.events.v_at_handover)
        self.events.lam_at_handover = xp.where(handed, lam, self.events.lam_at_handover)
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
            self.events.t_diverged, self.events.phase_diverged = t, ph
            self.phase = ph = DIVERGED
            u = fv = fl = 0.0
        wild = ~(xp.abs(u) <= s.u_range) & (ph < STOPPED) if B else (
            not abs(u) <= s.u_range and ph < STOPPED)
        if xp.any(wild):    # the law has left any physical range: the run has diverged
            self.events.t_diverged = xp.where(wild, t, self.events.t_diverged)
            self.events.phase_diverged = xp.where(wild, ph, self.events.phase_diverged)
            self.events.diverged_how = xp.where(wild, 2.0, self.events.diverged_how)
            self.phase = ph = xp.where(wild, DIVERGED, ph)
            u, fv, fl = (xp.where(wild, 0.0, a) for a in (u, fv, fl))
        self.fv.push(fv, self._ticks)
        self.fl.push(fl, self._ticks)
        self.uline.push(u, self._ticks)
        if self.recorder is not None:
            self.recorder(t, v_true, lam_true, ph, to_cruise, to_brake, to_stop, self._dt_prev)
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
        if not xp.batch:     # a single run: its one law (as the loop below, without masks)
            if ph == ACCEL:
                return self._accel(Pv, Pl, s.lambda_opt)
            if ph == HANDOVER:
                return self._accel(Pv, Pl, s.lambda_d)
            if ph == CRUISE:
                return self._cruise(v, lam, Pv, Pl)
            if ph == BRAKE_IN:
                return self._accel(Pv, Pl, -s.handover_band)
            if ph == BRAKE:
                return self._brake(t, Pv, Pl)
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

