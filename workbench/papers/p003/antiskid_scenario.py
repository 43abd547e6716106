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
sample by sample with :func:`metric_updates`, the one compiled definition of
the metrics that the compiled batch (:mod:`workbench.papers.p003.antiskid_kernel`)
inlines too; the controller's own phase events (handover, divergence) are
merged in at the end.

Why this stays paper code: every metric here is a definition of paper 003's
study (time to v_d, creep ratio in traction and braking against lambda_opt,
the creep-speed error of Theorem 3 against the profile of eq (76), the lock
onset). The runs without the predictor need the refined mesh: at low speed
that loop is close to neutral (near a creep ratio with slope J,
lambda' ~ J lambda - (J + k) lambda(t - h), roots decaying at only
(1/h) ln(|J| / |J + k|)), so fast features of width ~1/|J| set at the start
persist for seconds; the exponential step keeps them stable but only a step
below 1/|J| resolves them. The numpy batch form (controller and plant step)
is the reference the compiled kernel is compared with run by run, so its
operations stay as they are. Its tables and figures are rendered by the general
:mod:`workbench.report.case_tables` and :mod:`workbench.report.case_figures`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import lru_cache

import numpy as np

from ...controllers.antiskid003 import Antiskid003, PhaseEvents
from ...controllers.antiskid003_settings import BRAKE, BRAKE_IN, STOPPED, ControllerSettings
from ...sim.delay import SimResult, simulate_closed_loop
from ...sim.metric_rows import field_names, from_rows, initial_rows
from ...sim.perturb import Perturbations, PlantOnPath, batch_delay_line, noisy_measure
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


#: Field order of the metrics array (RunMetrics; PhaseEvents first).
METRIC_FIELDS = field_names(RunMetrics)
#: The creep-speed error is tracked from t_brake + EVS_SETTLE (s) while omega >
#: omega_switch (``evs_max_tracking``), in every run of the study.
EVS_SETTLE = 5.0


@lru_cache(maxsize=None)
def metric_updates():
    """The metric update of one sample, compiled (numba): ``(record,
    record_rows)``, the one definition of the run's metrics (:class:`RunMetrics`)
    that every closed loop of the study calls, the compiled batch
    (:mod:`workbench.papers.p003.antiskid_kernel`, ``record`` inlined into
    its loop) and :class:`MetricsRecorder` (a single run or a numpy batch).

    ``record(t, v, lam, ph, to_cruise, to_brake, to_stop, dt_prev, M, RS, j,
    cfg, r_p, settle)`` updates run ``j``: its metrics ``M[j]``
    (:data:`METRIC_FIELDS` order) and its state ``RS[j]`` = (v_prev,
    has_track, omega_prev, e_prev, lam_prev); ``cfg`` the controller's settings
    (:func:`~workbench.controllers.antiskid003_jit.settings_array`), ``r_p`` the
    plant's wheel radius, ``settle`` (:data:`EVS_SETTLE`). ``record_rows`` does every row of ``M``, with ``v``,
    ``lam``, ``ph``, the flags and ``r_p`` arrays (one value per run)."""
    from ...sim.jit_cache import cached, require_numba
    require_numba("an antiskid run's metrics")
    import numba

    from ...controllers import antiskid003_jit as C
    from ...sim.wheel_slip_jit import creep_speed, fmax, fmin, wheel_speed

    jit = numba.njit(nogil=True, error_model="numpy")
    M_ = {k: i for i, k in enumerate(METRIC_FIELDS)}
    T_CRUISE, V_CRUISE, L_CRUISE = M_["t_cruise"], M_["v_at_cruise"], M_["lam_at_cruise"]
    L_MAX, V_MAX, L_BRAKE = M_["lam_max_traction"], M_["v_max"], M_["lam_at_brake"]
    VE_BRAKE, LE_BRAKE, T_NEG = M_["v_err_at_brake"], M_["lam_err_at_brake"], M_["t_lam_negative"]
    L_MIN, T_OM3, T_STOP, T_PEAK = (M_["lam_min_brake"], M_["t_omega3"], M_["t_stop"],
                                    M_["t_past_peak"])
    E_LAST, E_MAX = M_["evs_last"], M_["evs_max_tracking"]
    V_D, L_D, L_OPT, V_FLOOR = C.V_D, C.LAMBDA_D, C.LAMBDA_OPT, C.V_FLOOR
    WS, TB, profile = C.OMEGA_SWITCH, C.T_BRAKE, C.profile

    @jit
    def clip(x):
        return fmin(fmax(x, 0.0), 1.0)

    @jit
    def fmax_nan(a, b):      # NaN = no value yet
        return b if a != a else fmax(a, b)

    @numba.njit(nogil=True, error_model="numpy", inline="always")
    def record(t, v, lam, ph, to_cruise, to_brake, to_stop, dt, M, RS, j, cfg, r_p, settle):
        """One sample of run ``j`` (:func:`metric_updates`)."""
        # crossing time of v = v_d, interpolated between the last two samples
        frac = (v - cfg[V_D]) / fmax(v - RS[j, 0], 1e-12)
        if to_cruise:
            M[j, T_CRUISE] = t - dt * fmin(frac, 1.0)
            M[j, V_CRUISE], M[j, L_CRUISE] = v, lam
        RS[j, 0] = v
        if ph < BRAKE_IN:
            M[j, L_MAX], M[j, V_MAX] = fmax(M[j, L_MAX], lam), fmax(M[j, V_MAX], v)
        if to_brake:
            M[j, L_BRAKE], M[j, VE_BRAKE], M[j, LE_BRAKE] = lam, v - cfg[V_D], lam - cfg[L_D]
        if to_stop:
            M[j, T_STOP] = t
        if not (ph == BRAKE_IN or ph == BRAKE):
            return
        if lam < 0 and M[j, T_NEG] != M[j, T_NEG]:
            M[j, T_NEG] = t
        M[j, L_MIN] = fmin(M[j, L_MIN], lam)
        omega = wheel_speed(fmax(v, cfg[V_FLOOR]), lam, r_p)
        ws = cfg[WS]
        # creep-speed error of Theorem 3, e_vs = v_s - v_s*(t) (measured), and
        # its left limit at omega = omega_switch (v_s* still on the profile)
        vs_on, _ = profile(t, v, 0.0 * v, math.inf + 0.0 * v, cfg)
        vs_star = vs_on if omega > ws else 0.0          # eq (76)
        vs = creep_speed(v, lam)
        e, e_on = abs(vs - vs_star), abs(vs - vs_on)
        M[j, E_LAST] = e
        # The tracking window runs from t_brake + settle to the first of
        # omega <= omega_switch (v_s* drops to 0, eq 76) and the lock onset,
        # lambda < -lambda_opt (the wheel passes the braking adhesion peak; the
        # divergence metrics report what follows). Both crossings are
        # interpolated linearly between the samples around them: the error
        # may be steep there, and the first sample past a crossing alone would
        # make the metric depend on where the grid falls.
        in_window = M[j, T_OM3] != M[j, T_OM3] and M[j, T_PEAK] != M[j, T_PEAK]
        cross_w = omega <= ws and M[j, T_OM3] != M[j, T_OM3]
        cross_l = lam < -cfg[L_OPT] and M[j, T_PEAK] != M[j, T_PEAK]
        if RS[j, 1] == 0.0:
            f_w = f_l = 1.0 + 0.0 * v
            e_prev = e_on
        else:
            w_prev, e_prev, l_prev = RS[j, 2], RS[j, 3], RS[j, 4]
            f_w = clip((w_prev - ws) / fmax(w_prev - omega, 1e-300))
            f_l = clip((l_prev + cfg[L_OPT]) / fmax(l_prev - lam, 1e-300))
        if cross_w:
            M[j, T_OM3] = t - dt * (1.0 - f_w)
        if cross_l:
            M[j, T_PEAK] = t - dt * (1.0 - f_l)
        settled = in_window and t >= cfg[TB] + settle
        if settled and not cross_w and not cross_l:
            M[j, E_MAX] = fmax_nan(M[j, E_MAX], e)
        f_end = fmin(f_w if cross_w else 1.0, f_l if cross_l else 1.0)
        e_end = e_prev + f_end * (e_on - e_prev)
        if settled and (cross_w or cross_l):
            M[j, E_MAX] = fmax_nan(M[j, E_MAX], e_end)
        RS[j, 1], RS[j, 2], RS[j, 3], RS[j, 4] = 1.0, omega, e_on, lam

    @jit
    def record_rows(t, v, lam, ph, to_cruise, to_brake, to_stop, dt, M, RS, cfg, r_p, settle):
        for j in range(M.shape[0]):
            record(t, v[j], lam[j], ph[j], to_cruise[j], to_brake[j], to_stop[j], dt, M, RS, j,
                   cfg, r_p[j], settle)

    return (cached(record, "antiskid_scenario.record"),
            cached(record_rows, "antiskid_scenario.record_rows"))


class MetricsRecorder:
    """Online metrics of a run, updated once per sample by the controller
    with the compiled update of :func:`metric_updates` (needs numba).

    Parameters
    ----------
    s : ControllerSettings
    x0 : tuple
        Initial (v, lambda).
    batch : int or None
        None: floats; else the number of runs stepped together.
    plant_r : float or array
        Wheel radius of the plant (for the measured wheel speed).
    dt : float
        The run's step (s).
    """

    def __init__(self, s: ControllerSettings, x0, batch, plant_r, dt: float):
        from ...controllers.antiskid003_jit import settings_array
        n, self.batch = (1 if batch is None else batch), batch
        self._record, self._rows = metric_updates()
        # the metrics read the settings, not the predictor: any predictor's
        # settings are laid out as the compiled controller's
        self.cfg = settings_array(replace(s, predictor="rollout"), dt)
        self.M = initial_rows(RunMetrics, n)
        self.RS = np.zeros((n, 5))
        self.RS[:, 0] = x0[0]
        self.r_p = np.broadcast_to(np.asarray(plant_r, float), (n,)).copy()

    def __call__(self, t, v, lam, ph, to_cruise, to_brake, to_stop, dt_prev):
        """Update the metrics with one sample."""
        if self.batch is None:
            self._record(float(t), float(v), float(lam), int(ph), bool(to_cruise),
                         bool(to_brake), bool(to_stop), float(dt_prev), self.M, self.RS, 0,
                         self.cfg, self.r_p[0], EVS_SETTLE)
        else:
            self._rows(float(t), v, lam, np.asarray(ph, np.int64), to_cruise, to_brake, to_stop,
                       float(dt_prev), self.M, self.RS, self.cfg, self.r_p, EVS_SETTLE)

    @property
    def m(self) -> RunMetrics:
        """The metrics so far: floats for a single run, arrays for a batch."""
        return from_rows(RunMetrics, self.M, self.batch is None)


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
    rec = MetricsRecorder(run.controller, run.x0, batch, p[PARAM_ORDER.index("r")], dt)
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
    path = None if batch is None else PlantOnPath(pt, p)

    def step(x, u, t, dt_):
        if batch is None:
            *nx, ctrl.unresolved = plant_step(x, u, p, dt_, fns, xp, with_flag=True)
            return tuple(nx)
        stop = ctrl.phase >= STOPPED
        pp = path.params(x[0], dt_)
        *nx, unres = plant_step(x, u, pp, dt_, path.fns, xp, mask=~stop, with_flag=True)
        ctrl.unresolved = unres & ~stop
        return (np.where(stop, x[0], nx[0]), np.where(stop, x[1], nx[1]))

    every = 10**12 if record_dt is None else max(int(round(record_dt / dt)), 1)
    x0 = (run.x0[0] + zero, run.x0[1] + zero)
    line = batch_delay_line(pt, run.h, batch, dt, run.u_init)
    level = None if mesh is None else mesh.of_state(creep_rate_coefficient()(*p))
    with np.errstate(all="ignore"):
        res = simulate_closed_loop(step, ctrl, x0, h=float(np.max(run.h)), dt=dt,
                                   t_end=run.t_end, u_init=run.u_init + zero,
                                   record_every=every, line=line, level=level,
                                   done=lambda t, x, ph: bool(np.all(ph >= STOPPED)),
                                   k_max=0 if mesh is None else mesh.k_max)
    res = None if record_dt is None else SimResult(res.t, res.x, res.u, res.u_applied,
                                                   res.phase, ("v", "lambda"), ("u",), dt)
    m = rec.m
    for k, v in vars(ctrl.events).items():      # the phase logic's events
        setattr(m, k, v)
    return res, m
