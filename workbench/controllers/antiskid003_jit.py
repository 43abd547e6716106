"""Controller (75) of paper 003, compiled (numba), one run at a time.

The sample of :class:`workbench.controllers.antiskid003.Antiskid003`
(``__call__``: phase logic, divergence events, the mismatch estimate of
``observer_tau``, the predictor rollout of eq (2), the laws (61), (64),
(69) and their stiff hold) written over floats with the compiled stepping
kernel of :mod:`workbench.sim.wheel_slip_jit`, operation for operation as
the batched numpy path (which stays the reference: the compiled and numpy
paths are compared run by run in ``tests/test_compiled_kernel.py``).

Supported: ``predictor = "rollout"`` (or ``compensate = False``), either
``sampling``, either entry; on the fixed step (no refined mesh).

State of a run, passed between calls as arrays:

* ``cfg`` -- :func:`settings_array` (settings and step, read-only);
* ``st`` -- :data:`STATE` (phase, previous sample, mismatch estimate, ...);
* ``ubuf`` -- the controller's own input history (ring of N + 2 samples,
  :class:`~workbench.sim.history.DelayLine` of h_model);
* ``ev`` -- the phase events, :class:`~workbench.controllers.antiskid003.PhaseEvents`
  field order (the first entries of the caller's metrics array).
"""
from __future__ import annotations

import math
from dataclasses import fields

import numba
import numpy as np

from ..sim.history import split_delay
from ..sim.wheel_slip import PARAM_ORDER
from ..sim.wheel_slip_jit import (BRAKING, TRACTION, braking, fmax, fmin, forms, phi1, stiff_step,
                                  stiff_step_at, traction, wheel_speed)
from .antiskid003 import PhaseEvents
from .antiskid003_settings import (ACCEL, BRAKE, BRAKE_IN, CRUISE, DIVERGED, HANDOVER, STOPPED,
                                   ControllerSettings)

_JIT = dict(nogil=True, error_model="numpy")
_JITI = dict(_JIT, inline="always")

#: Entries of :func:`settings_array`.
CFG = ("v_d", "lambda_d", "lambda_opt", "K0", "K1", "a1", "a2", "d1", "d2", "d3", "d4", "d5",
       "d6", "k_ac", "k_de", "h_model", "t_brake", "c0", "c1", "lambda_allow", "vs_min",
       "omega_switch", "compensate", "stiff", "cruise_creep", "brake_creep", "band", "v_stop",
       "v_floor", "lam_diverged", "u_range", "observer_on", "alpha", "dt", "N", "f", "r",
       "group")
(V_D, LAMBDA_D, LAMBDA_OPT, K0, K1, A1, A2, D1, D2, D3, D4, D5, D6, K_AC, K_DE, H_MODEL, T_BRAKE,
 C0, C1, LAMBDA_ALLOW, VS_MIN, OMEGA_SWITCH, COMPENSATE, STIFF, CRUISE_CREEP, BRAKE_CREEP, BAND,
 V_STOP, V_FLOOR, LAM_DIVERGED, U_RANGE, OBSERVER_ON, ALPHA, DT, NC, FC, R_C,
 GROUP) = range(len(CFG))

#: Entries of the controller state ``st``. The last five: the traction forms
#: (lambda'_0, lambda'_u, J_0, J_u) that the last predictor rollout of
#: :func:`rollout_lanes` evaluated at the sample's (v, lambda), and whether
#: they are there (1) -- the mismatch estimate of the next sample needs the
#: same forms at the same point (:func:`observe`).
STATE = ("phase", "has_prev", "prev_v", "prev_lam", "prev_phase", "delta", "unresolved",
         "pushed", "kept", "kept_f20", "kept_f2u", "kept_j0", "kept_ju")
PH, HAS_PREV, PV, PL, PPH, DELTA, UNRES, PUSHED, KEPT, KF20, KF2U, KJ0, KJU = range(len(STATE))

_EV = {f.name: i for i, f in enumerate(fields(PhaseEvents))}
E_HANDOVER, E_V_HANDOVER, E_LAM_HANDOVER = (_EV["t_handover_done"], _EV["v_at_handover"],
                                            _EV["lam_at_handover"])
E_T_DIV, E_PH_DIV, E_HOW = _EV["t_diverged"], _EV["phase_diverged"], _EV["diverged_how"]


def settings_array(s: ControllerSettings, dt: float, group: int = 1) -> np.ndarray:
    """The settings of ``s`` at step ``dt`` as the float array ``cfg`` (:data:`CFG`);
    ``group``: the predictor's rollout steps over ``group`` held samples at a
    time, with their exact average (1: every sample, as
    :meth:`Antiskid003._rollout`; a fast sampled controller's choice, see
    :mod:`workbench.papers.p003.antiskid_sampled`)."""
    if not (isinstance(group, int) and group >= 1):
        raise ValueError(f"group = {group!r}; expected an integer >= 1")
    if s.compensate and s.predictor != "rollout":
        raise ValueError(f"predictor = {s.predictor!r}; the compiled controller runs "
                         "predictor = 'rollout' (or compensate = false)")
    N, f = split_delay(s.h_model, dt)
    c, pr = s.lin, s.profile
    observer = s.sampling == "stiff" and s.observer_tau > 0
    vals = dict(v_d=s.v_d, lambda_d=s.lambda_d, lambda_opt=s.lambda_opt, K0=s.K[0], K1=s.K[1],
                **{k: c[k] for k in ("a1", "a2", "d1", "d2", "d3", "d4", "d5", "d6")},
                k_ac=s.k_ac, k_de=s.k_de, h_model=s.h_model, t_brake=pr.t_brake, c0=pr.c0,
                c1=pr.c1, lambda_allow=pr.lambda_allow, vs_min=pr.vs_min,
                omega_switch=pr.omega_switch, compensate=float(s.compensate),
                stiff=float(s.sampling == "stiff"), cruise_creep=float(s.cruise_entry == "creep"),
                brake_creep=float(s.brake_entry == "creep"), band=s.handover_band,
                v_stop=s.v_stop, v_floor=s.v_floor, lam_diverged=s.lam_diverged,
                u_range=s.u_range, observer_on=float(observer),
                alpha=-math.expm1(-dt / s.observer_tau) if observer else 0.0,
                dt=dt, N=float(N), f=f, r=s.params[PARAM_ORDER.index("r")], group=float(group))
    return np.array([float(vals[k]) for k in CFG])


def initial_state(s: ControllerSettings, dt: float, u_init: float) -> tuple[np.ndarray, np.ndarray]:
    """(``st``, ``ubuf``) of a run at t = 0."""
    N, _ = split_delay(s.h_model, dt)
    st = np.zeros(len(STATE))
    st[PH] = ACCEL
    return st, np.full(N + 2, float(u_init))


@numba.njit(**_JITI)
def profile(t, v, vdot, omega, cfg):
    """(v_s*, d v_s*/dt) of eqs (76)-(78) (:class:`CreepSpeedProfile`)."""
    root = math.sqrt(v * v + 1.0)
    slope = cfg[C0] - cfg[C1] * (t - cfg[T_BRAKE])
    raw = slope * cfg[LAMBDA_ALLOW] * root
    draw = cfg[LAMBDA_ALLOW] * (-cfg[C1] * root + slope * v * vdot / root)
    on = omega > cfg[OMEGA_SWITCH]
    free = raw > cfg[VS_MIN]
    vs = (raw if free else cfg[VS_MIN]) if on else 0.0
    dvs = draw if on and free else 0.0
    return vs, dvs


@numba.njit(**_JITI)
def _model_step(v, lam, u, dt, kind, cfg, p):
    """One step of the prediction model ``kind`` (TRACTION, BRAKING, or 0:
    the linear cruise error model, eq 62)."""
    if kind != 0:
        nv, nl, _ = stiff_step(v, lam, u, dt, p, cfg[V_FLOOR], kind)
        return nv, nl
    ve, le = v - cfg[V_D], lam - cfg[LAMBDA_D]
    den = cfg[D4] * ve + cfg[D5] * le + cfg[D6]
    f2 = cfg[D1] * ve + cfg[D2] * le + cfg[D3] + den * u
    z = (cfg[D2] + cfg[D5] * u) * dt
    return v + dt * (cfg[A1] * ve + cfg[A2] * le), lam + dt * phi1(z) * f2


@numba.njit(**_JIT)
def rollout(v, lam, ph, ubuf, n, cfg, p):
    """X(t + h) of eq (2): the phase's model run from x(t) through the inputs
    of the last h seconds (:meth:`Antiskid003._rollout`)."""
    if ph == CRUISE:
        kind = 0
    elif ph < BRAKE:
        kind = TRACTION
    elif ph == BRAKE:
        kind = BRAKING
    else:
        return v, lam
    N, f, dt, L, G = int(cfg[NC]), cfg[FC], cfg[DT], ubuf.shape[0], int(cfg[GROUP])
    if f > 0:
        v, lam = _model_step(v, lam, ubuf[(n - N - 1) % L], f * dt, kind, cfg, p)
    if G == 1:
        j = (n - N) % L      # ring index of sample k = n - N, ..., n - 1 (no division per step)
        for _ in range(N):
            v, lam = _model_step(v, lam, ubuf[j], dt, kind, cfg, p)
            j = j + 1 if j + 1 < L else 0
        return v, lam
    k = n - N
    while k < n:       # pieces of G held samples, each with their average input
        m = min(G, n - k)
        total = 0.0
        for j in range(k, k + m):
            total += ubuf[j % L]
        v, lam = _model_step(v, lam, total / m, m * dt, kind, cfg, p)
        k += m
    return v, lam


@numba.njit(**_JITI)
def delayed(ubuf, j, n, cfg):
    """Average of u(t - h_model) over the step of the last pushed sample (run
    ``j``'s input history ``ubuf[j]``)."""
    N, f, L = int(cfg[NC]), cfg[FC], ubuf.shape[1]
    a = ubuf[j, (n - 1 - N) % L]
    return a if f == 0.0 else (1.0 - f) * a + f * ubuf[j, (n - 2 - N) % L]


@numba.njit(**_JITI)
def sampled(u, f20, f2u, j0, ju, delta, cfg):
    """:meth:`Antiskid003._sampled`: the input held over one sample."""
    if cfg[STIFF] == 0.0:
        return u
    dt = cfg[DT]
    phi = phi1((j0 + ju * u) * dt)
    d = delta
    if cfg[COMPENSATE] != 0.0:
        hj = fmin(fmax((j0 + ju * u) * cfg[H_MODEL], -700.0), 20.0)
        d = d * (1.0 + math.expm1(hj))
    return ((f20 + f2u * u) / phi + d * (1.0 / phi - 1.0) - f20) / f2u


@numba.njit(**_JITI)
def observe(v, lam, ph, st, ubuf, j, cfg, p):
    """:meth:`Antiskid003._observe`: update run ``j``'s mismatch estimate ``st[j, DELTA]``."""
    dt = cfg[DT]
    if ph >= BRAKE_IN:
        st[j, DELTA] = 0.0 * v
    elif st[j, HAS_PREV] != 0.0 and cfg[OBSERVER_ON] != 0.0:
        pv, pl, pph = st[j, PV], st[j, PL], st[j, PPH]
        ua = delayed(ubuf, j, int(st[j, PUSHED]), cfg)
        if pph == CRUISE:       # the linear cruise model (eq 62); the plant's forms otherwise
            ve, le = pv - cfg[V_D], pl - cfg[LAMBDA_D]
            den = cfg[D4] * ve + cfg[D5] * le + cfg[D6]
            f20 = cfg[D1] * ve + cfg[D2] * le + cfg[D3]
            f2u, j0, ju = den, cfg[D2], cfg[D5]
        elif st[j, KEPT] != 0.0 and pl >= 0:    # the forms the rollout kept: eq 13 at (pv, pl)
            f20, f2u, j0, ju = st[j, KF20], st[j, KF2U], st[j, KJ0], st[j, KJU]
        else:
            _, f20, f2u, j0, ju = forms(fmax(pv, cfg[V_FLOOR]), pl, p, 0)
        d = (lam - pl) / (dt * phi1((j0 + ju * ua) * dt)) - (f20 + f2u * ua)
        new = st[j, DELTA] + cfg[ALPHA] * (d - st[j, DELTA])
        st[j, DELTA] = 0.0 * v if not abs(new) < 1e6 else new
    st[j, HAS_PREV], st[j, PV], st[j, PL], st[j, PPH], st[j, KEPT] = 1.0, v, lam, ph, 0.0


@numba.njit(**_JIT)
def law_forms(ph, Pv, Pl, cfg, p):
    """The model forms the law of phase ``ph`` needs at the prediction (Pv,
    Pl): eq (13) for the traction laws, eq (16) for the braking law, at the
    speed floored at v_floor; zeros for the others (:func:`law_with`)."""
    if ph == ACCEL or ph == HANDOVER or ph == BRAKE_IN:
        return traction(fmax(Pv, cfg[V_FLOOR]), Pl, p)
    if ph == BRAKE:
        return braking(fmax(Pv, cfg[V_FLOOR]), Pl, p)
    z = 0.0 * Pv
    return z, z, z, z, z


@numba.njit(**_JIT)
def _accel(Pl, target, delta, cfg, y):
    y1, y2, y3, dy2, dy3 = y
    return sampled((-y2 - cfg[K_AC] * (Pl - target)) / y3, y2, y3, dy2, dy3, delta, cfg)


@numba.njit(**_JIT)
def _cruise(v, lam, Pv, Pl, delta, cfg):
    ve, le = Pv - cfg[V_D], Pl - cfg[LAMBDA_D]
    den = cfg[D4] * ve + cfg[D5] * le + cfg[D6]
    u = (-cfg[D3] + cfg[K0] * (v - cfg[V_D]) + cfg[K1] * (lam - cfg[LAMBDA_D])) / den
    return sampled(u, cfg[D1] * ve + cfg[D2] * le + cfg[D3], den, cfg[D2], cfg[D5], delta, cfg)


@numba.njit(**_JIT)
def _brake(t, Pv, Pl, delta, cfg, z):
    vg = fmax(Pv, cfg[V_FLOOR])
    z1, z2, z3, dz2, dz3 = z
    omega = wheel_speed(vg, Pl, cfg[R_C])
    vs, dvs = profile(t + cfg[H_MODEL], vg, z1, omega, cfg)
    u = ((-cfg[K_DE] * (vg * Pl - vs) + z1 + dvs) / vg - (1.0 + Pl) / vg * z1 - z2) / z3
    return sampled(u, z2, z3, dz2, dz3, delta, cfg)


@numba.njit(**_JITI)
def kind_of(ph, cfg):
    """The rollout's model for phase ``ph`` (:func:`_model_step`'s ``kind``),
    or -1: no rollout (no predictor, or the phase has no law)."""
    if cfg[COMPENSATE] == 0.0 or ph > BRAKE:
        return -1
    if ph == CRUISE:
        return 0
    return TRACTION if ph < BRAKE else BRAKING


@numba.njit(**_JITI)
def law_at(t, v, lam, Pv, Pl, ph, delta, cfg, p):
    """The torque of the active phase's law at the prediction (Pv, Pl), with
    the mismatch estimate ``delta`` (:meth:`Antiskid003._laws`)."""
    return law_with(t, v, lam, Pv, Pl, ph, delta, cfg, law_forms(ph, Pv, Pl, cfg, p))


@numba.njit(**_JITI)
def law_with(t, v, lam, Pv, Pl, ph, delta, cfg, fm):
    """:func:`law_at` given ``fm = law_forms(ph, Pv, Pl, cfg, p)``."""
    if ph == ACCEL:
        return _accel(Pl, cfg[LAMBDA_OPT], delta, cfg, fm)
    if ph == HANDOVER:
        return _accel(Pl, cfg[LAMBDA_D], delta, cfg, fm)
    if ph == CRUISE:
        return _cruise(v, lam, Pv, Pl, delta, cfg)
    if ph == BRAKE_IN:
        return _accel(Pl, -cfg[BAND], delta, cfg, fm)
    if ph == BRAKE:
        return _brake(t, Pv, Pl, delta, cfg, fm)
    return 0.0 * v


@numba.njit(**_JIT)
def law(t, v, lam, ph, st, ubuf, cfg, p):
    """The torque the active phase's law commands (:meth:`Antiskid003._laws`)."""
    n = int(st[PUSHED])
    if cfg[COMPENSATE] == 0.0:
        Pv, Pl = v, lam
    else:
        Pv, Pl = rollout(v, lam, ph, ubuf, n, cfg, p)
    return law_at(t, v, lam, Pv, Pl, ph, st[DELTA], cfg, p)


@numba.njit(**_JITI)
def control_pre(t, lam_true, v, lam, st, ubuf, ev, j, cfg, p):
    """The first part of :func:`control` for run ``j`` (row ``j`` of ``st``,
    ``ubuf`` and ``ev``: rows, not views, so no reference counting per
    sample): phase logic, divergence events and the mismatch estimate;
    returns (phase, to_cruise, to_brake, to_stop)."""
    ph = int(st[j, PH])
    to_cruise = ph == ACCEL and v >= cfg[V_D]
    if to_cruise:
        ph = HANDOVER if cfg[CRUISE_CREEP] != 0.0 else CRUISE
    handed = ph == HANDOVER and abs(lam - cfg[LAMBDA_D]) <= cfg[BAND]
    if handed:
        ph = CRUISE
    to_brake = ph < BRAKE_IN and t >= cfg[T_BRAKE]
    if to_brake:
        ph = BRAKE_IN if cfg[BRAKE_CREEP] != 0.0 else BRAKE
    if ph == BRAKE_IN and lam <= 0:
        ph = BRAKE
    to_stop = (ph == BRAKE_IN or ph == BRAKE) and v <= cfg[V_STOP]
    if to_stop:
        ph = STOPPED
    unres = st[j, UNRES] != 0.0
    bad = (not abs(lam_true) < cfg[LAM_DIVERGED] or unres) and ph < STOPPED
    if bad:
        ev[j, E_T_DIV], ev[j, E_PH_DIV], ev[j, E_HOW] = t, ph, 1.0 if unres else 0.0
    if handed:
        ev[j, E_HANDOVER], ev[j, E_V_HANDOVER], ev[j, E_LAM_HANDOVER] = t, v, lam
    if bad:
        ph = DIVERGED
    observe(v, lam, ph, st, ubuf, j, cfg, p)
    return ph, to_cruise, to_brake, to_stop


@numba.njit(**_JITI)
def control_post(t, v, lam, Pv, Pl, ph, fm, st, ubuf, ev, j, cfg):
    """The last part of :func:`control` for run ``j`` (as :func:`control_pre`):
    the law at the prediction (Pv, Pl) with its model forms ``fm``
    (:func:`law_forms`), the range test, the push into the input history;
    returns (u, phase)."""
    u = law_with(t, v, lam, Pv, Pl, ph, st[j, DELTA], cfg, fm)
    if not abs(u) <= cfg[U_RANGE] and ph < STOPPED:
        ev[j, E_T_DIV], ev[j, E_PH_DIV], ev[j, E_HOW] = t, ph, 2.0
        ph, u = DIVERGED, 0.0
    n = int(st[j, PUSHED])
    ubuf[j, n % ubuf.shape[1]] = u
    st[j, PUSHED], st[j, PH] = n + 1, ph
    return u, ph


@numba.njit(**_JIT)
def control(t, lam_true, v, lam, st, ubuf, ev, cfg, p):
    """One sample of controller (75) (:meth:`Antiskid003.__call__`) seeing
    (v, lam) (measured), the divergence test on the true ``lam_true``:
    updates ``st``, ``ubuf`` and the events ``ev``; returns (u, phase,
    to_cruise, to_brake, to_stop) for the caller's metrics.

    :func:`control_pre`, the predictor (:func:`rollout`) and
    :func:`control_post`; a batch of runs may interleave the predictors of
    several runs between the two parts (:func:`rollout_lanes`)."""
    S, U, E = (st.reshape((1, st.shape[0])), ubuf.reshape((1, ubuf.shape[0])),
               ev.reshape((1, ev.shape[0])))
    ph, to_cruise, to_brake, to_stop = control_pre(t, lam_true, v, lam, S, U, E, 0, cfg, p)
    if cfg[COMPENSATE] == 0.0:
        Pv, Pl = v, lam
    else:
        Pv, Pl = rollout(v, lam, ph, ubuf, int(st[PUSHED]), cfg, p)
    u, ph = control_post(t, v, lam, Pv, Pl, ph, law_forms(ph, Pv, Pl, cfg, p), S, U, E, 0, cfg)
    return u, ph, to_cruise, to_brake, to_stop


@numba.njit(**_JITI)
def rollout_lanes(Pv, Pl, kind, ubuf, st, n, fm, active, cfg, p):
    """:func:`rollout` of several runs ("lanes") at once, in place on
    (Pv[j], Pl[j]) for the lanes with ``active[j]`` and ``kind[j] >= 0``
    (:func:`kind_of`): the same operations per run as :func:`rollout`
    (predictor group 1), their steps interleaved, so that the processor
    overlaps the runs' dependency chains. A step of the nonlinear model is
    done in two passes over the lanes: the model's forms of every lane (an
    ``exp`` each), then the steps (an ``expm1`` each), so that the calls of
    independent lanes follow each other and overlap. ``n[j]``: the lane's
    pushed sample count, overwritten (scratch); ``fm``: (lanes, 5) scratch.

    A traction rollout keeps the forms of its first step, evaluated at the
    sample's (v, lambda), in ``st[j]`` (:data:`STATE`): the next sample's
    mismatch estimate (:func:`observe`) reads them instead of evaluating
    eq (13) again at that point (the same values)."""
    N, f, dt, L, vfl = int(cfg[NC]), cfg[FC], cfg[DT], ubuf.shape[1], cfg[V_FLOOR]
    K = Pv.shape[0]
    first = -1 if f > 0 else 0           # -1: the fraction f of the oldest sample's step
    for j in range(K):
        n[j] = (n[j] - N + first) % L    # ring index of the first sample stepped
    for i in range(first, N):
        step = f * dt if i < 0 else dt
        for j in range(K):
            if active[j] and kind[j] > 0:
                fm[j, 0], fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4] = forms(
                    fmax(Pv[j], vfl), Pl[j], p, kind[j])
                if i == first and kind[j] == TRACTION:
                    st[j, KEPT], st[j, KF20], st[j, KF2U], st[j, KJ0], st[j, KJU] = (
                        1.0, fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4])
        for j in range(K):
            if active[j] and kind[j] > 0:
                Pv[j], Pl[j], _ = stiff_step_at(Pv[j], Pl[j], ubuf[j, n[j]], step, p, vfl,
                                                kind[j], (fm[j, 0], fm[j, 1], fm[j, 2],
                                                          fm[j, 3], fm[j, 4]))
            elif active[j] and kind[j] == 0:
                Pv[j], Pl[j] = _model_step(Pv[j], Pl[j], ubuf[j, n[j]], step, 0, cfg, p)
            n[j] = n[j] + 1 if n[j] + 1 < L else 0
