"""The closed-loop run of paper 003's antiskid scenario (section 4) and its metrics.

:func:`simulate_antiskid` puts the controller of
:mod:`workbench.controllers.antiskid003` on the delayed wheel-slip plant
(:mod:`workbench.sim.wheel_slip`, stepped by
:func:`workbench.sim.delay.simulate_closed_loop`), single runs or a batch of
parameter samples, optionally on a refined mesh (:class:`Mesh`, the general
:class:`workbench.sim.rate_mesh.RateMesh` with S / v the fastest creep-ratio
rate, :func:`~workbench.sim.wheel_slip.creep_rate_coefficient`, ~3800/v 1/s
on dry rail).
:class:`MetricsRecorder` accumulates the run's metrics (:class:`RunMetrics`)
sample by sample; the controller's own phase events (handover, divergence)
are merged in at the end.

Why this stays paper code: every metric here is a definition of paper 003's
study (time to v_d, creep ratio in traction and braking against lambda_opt,
the creep-speed error of Theorem 3 against the profile of eq (76), the lock
onset). The runs without the predictor need the refined mesh: at low speed
that loop is close to neutral (near a creep ratio with slope J,
lambda' ~ J lambda - (J + k) lambda(t - h), roots decaying at only
(1/h) ln(|J| / |J + k|)), so fast features of width ~1/|J| set at the start
persist for seconds; the exponential step keeps them stable but only a step
below 1/|J| resolves them. The batch form is mirrored bit for bit by the
compiled kernel (:mod:`workbench.papers.p003.antiskid_kernel`), so its
operations stay as they are. Its tables and figures are rendered by the general
:mod:`workbench.report.case_tables` and :mod:`workbench.report.case_figures`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...controllers.antiskid003 import Antiskid003, PhaseEvents
from ...controllers.antiskid003_settings import BRAKE, BRAKE_IN, STOPPED, ControllerSettings
from ...sim.delay import SimResult, simulate_closed_loop
from ...sim.history import BatchDelayLine
from ...sim.perturb import Perturbations, VaryingDelayLine, grade_at, noisy_measure
from ...sim.rate_mesh import RateMesh as Mesh
from ...sim.wheel_slip import (PARAM_ORDER, ArrayOps, ScalarOps, creep_rate_coefficient,
                               creep_speed, model_functions, plant_step, wheel_speed)


@dataclass
class RunMetrics(PhaseEvents):
    """Online metrics of a run (floats, or arrays for a batch); NaN = not
    reached. The controller's phase events (:class:`PhaseEvents`: handover,
    divergence) plus what :class:`MetricsRecorder` accumulates."""

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
    t_past_peak: object = math.nan    # braking: first lambda < -lambda_opt (lock onset)
    evs_last: object = math.nan
    evs_max_tracking: object = math.nan   # NaN: the tracking window was never entered


class MetricsRecorder:
    """Online metrics of a run, updated once per sample by the controller.

    Parameters
    ----------
    s : ControllerSettings
    x0 : tuple
        Initial (v, lambda).
    batch : int or None
        None: floats; else the number of runs stepped together.
    plant_r : float or array
        Wheel radius of the plant (for the measured wheel speed).
    evs_settle : float
        The creep-speed error is tracked from t_brake + evs_settle (s) while
        omega > omega_switch (``evs_max_tracking``); ``evs_last`` is its
        value at the last braking sample.
    """

    def __init__(self, s: ControllerSettings, x0, batch, plant_r, evs_settle: float = 5.0):
        self.s, self.r_p, self.evs_settle = s, plant_r, evs_settle
        self.xp = ScalarOps if batch is None else ArrayOps
        self._v_prev = x0[0] + (0.0 if batch is None else np.zeros(batch))
        self._track_prev = None    # (omega, e_vs left of the switch) of the last tracked sample
        self.m = RunMetrics()
        if batch is not None:
            for k, v in vars(self.m).items():
                setattr(self.m, k, np.full(batch, v, float))

    def __call__(self, t, v, lam, ph, to_cruise, to_brake, to_stop, dt_prev):
        """Update the metrics with one sample (see the class docstring)."""
        if not self.xp.batch:
            return self._scalar(t, v, lam, ph, to_cruise, to_brake, to_stop, dt_prev)
        s, xp, m = self.s, self.xp, self.m
        w = xp.where
        # crossing time of v = v_d, interpolated between the last two samples
        frac = (v - s.v_d) / xp.maximum(v - self._v_prev, 1e-12)
        m.t_cruise = w(to_cruise, t - dt_prev * xp.minimum(frac, 1.0), m.t_cruise)
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
        m.t_omega3 = w(cross_w, t - dt_prev * (1.0 - f_w), m.t_omega3)
        m.t_past_peak = w(cross_l, t - dt_prev * (1.0 - f_l), m.t_past_peak)
        settled = brk & in_window & (t >= s.profile.t_brake + self.evs_settle)
        inside = settled & no(cross_w) & no(cross_l)
        fmax = lambda a, b: w(a != a, b, xp.maximum(a, b))   # NaN = no value yet
        m.evs_max_tracking = w(inside, fmax(m.evs_max_tracking, e), m.evs_max_tracking)
        f_end = xp.minimum(w(cross_w, f_w, 1.0), w(cross_l, f_l, 1.0))
        e_end = e_prev + f_end * (e_on - e_prev)
        end = settled & (cross_w | cross_l)
        m.evs_max_tracking = w(end, fmax(m.evs_max_tracking, e_end), m.evs_max_tracking)
        self._track_prev = (omega, e_on, lam)

    def _scalar(self, t, v, lam, ph, to_cruise, to_brake, to_stop, dt_prev):
        """:meth:`__call__` of a single run: the same operations on floats, in
        the same order, each done only where its result is kept (a single
        run's case runs call this once a step: ``tests/test_antiskid_run.py``
        compares it with the batch form bit for bit)."""
        s, m = self.s, self.m
        if to_cruise:
            frac = (v - s.v_d) / max(v - self._v_prev, 1e-12)
            m.t_cruise = t - dt_prev * min(frac, 1.0)
            m.v_at_cruise = v
            m.lam_at_cruise = lam
        self._v_prev = v
        if ph < BRAKE_IN:
            m.lam_max_traction = max(m.lam_max_traction, lam)
            m.v_max = max(m.v_max, v)
        if to_brake:
            m.lam_at_brake = lam
            m.v_err_at_brake = v - s.v_d
            m.lam_err_at_brake = lam - s.lambda_d
        if to_stop:
            m.t_stop = t
        if ph not in (BRAKE_IN, BRAKE):
            return
        if lam < 0 and math.isnan(m.t_lam_negative):
            m.t_lam_negative = t
        m.lam_min_brake = min(m.lam_min_brake, lam)
        omega = wheel_speed(max(v, s.v_floor), lam, self.r_p, ScalarOps)
        ws = s.profile.omega_switch
        vs_on, _ = s.profile(t, v, 0.0 * v, math.inf + 0.0 * v, ScalarOps)
        vs_star = vs_on if omega > ws else 0.0
        vs = creep_speed(v, lam, ScalarOps)
        e, e_on = abs(vs - vs_star), abs(vs - vs_on)
        m.evs_last = e
        in_window = m.t_omega3 != m.t_omega3 and m.t_past_peak != m.t_past_peak
        cross_w = omega <= ws and m.t_omega3 != m.t_omega3
        cross_l = lam < -s.lambda_opt and m.t_past_peak != m.t_past_peak
        prev = self._track_prev
        if prev is None:
            f_w = f_l = 1.0 + 0.0 * v
            e_prev = e_on
        else:
            w_prev, e_prev, l_prev = prev
            if cross_w:
                f_w = min(max((w_prev - ws) / max(w_prev - omega, 1e-300), 0.0), 1.0)
            if cross_l:
                f_l = min(max((l_prev + s.lambda_opt) / max(l_prev - lam, 1e-300), 0.0), 1.0)
        if cross_w:
            m.t_omega3 = t - dt_prev * (1.0 - f_w)
        if cross_l:
            m.t_past_peak = t - dt_prev * (1.0 - f_l)
        if in_window and t >= s.profile.t_brake + self.evs_settle:
            if not cross_w and not cross_l:
                a = m.evs_max_tracking
                m.evs_max_tracking = e if a != a else max(a, e)
            elif cross_w or cross_l:
                f_end = min(f_w if cross_w else 1.0, f_l if cross_l else 1.0)
                e_end = e_prev + f_end * (e_on - e_prev)
                a = m.evs_max_tracking
                m.evs_max_tracking = e_end if a != a else max(a, e_end)
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
    perturb: Perturbations | None = None    # batches only: noise, gradient, varying delay


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
    xp = ScalarOps if batch is None else ArrayOps
    fns = model_functions("math" if batch is None else "numpy")
    p = run.plant_params
    rec = MetricsRecorder(run.controller, run.x0, batch, p[PARAM_ORDER.index("r")])
    ctrl = Antiskid003(run.controller, run.x0, run.u_init, dt, batch, recorder=rec,
                       k_max=None if mesh is None else mesh.k_max)
    zero = 0.0 if batch is None else np.zeros(batch)
    pt = run.perturb
    if pt is not None and (batch is None or mesh is not None):
        raise ValueError("perturbations are for batches on the fixed step")
    if pt is not None and pt.noisy:
        i_r = PARAM_ORDER.index("r")
        ctrl.measure = noisy_measure(pt, p[i_r], run.controller.params[i_r],
                                     run.controller.v_floor)
    pos, plant_fns = [zero], fns
    if pt is not None and pt.grade is not None:
        plant_fns = model_functions("numpy", graded=True)

    def plant_params():
        """The plant's parameters this step (a slope appended on a gradient)."""
        if pt is None or pt.grade is None:
            return p
        g = grade_at(pos[0], np.asarray(pt.keys["grade"], np.uint64), *pt.grade, pt.segment)
        return (*p, g)

    def step(x, u, t, dt_):
        if batch is None:
            *nx, ctrl.unresolved = plant_step(x, u, p, dt_, fns, xp, with_flag=True)
            return tuple(nx)
        stop = ctrl.phase >= STOPPED
        pp = plant_params()
        pos[0] = pos[0] + dt_ * x[0]
        *nx, unres = plant_step(x, u, pp, dt_, plant_fns, xp, mask=~stop, with_flag=True)
        ctrl.unresolved = unres & ~stop
        return (np.where(stop, x[0], nx[0]), np.where(stop, x[1], nx[1]))

    def done(t, x, ph):
        return bool((ph >= STOPPED).all()) if batch is not None else ph >= STOPPED

    every = 10**12 if record_dt is None else max(int(round(record_dt / dt)), 1)
    x0 = (run.x0[0] + zero, run.x0[1] + zero)
    line = None if batch is None else BatchDelayLine(np.broadcast_to(run.h, (batch,)), dt,
                                                      run.u_init)
    if pt is not None and pt.delay is not None:
        line = VaryingDelayLine(*pt.delay, pt.period, pt.phase, dt, run.u_init)
    level = None
    if mesh is not None:
        S = creep_rate_coefficient()(*p)
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
    for k, v in vars(ctrl.events).items():      # the phase logic's events
        setattr(rec.m, k, v)
    return res, rec.m
