"""Compiled sampled-data loop of paper 003's antiskid controller (issue 20).

Paper 003: Cai, Yue, Huang, "Antiskid control of high-speed trains with
input delay": controller (75) (laws (61), (64), (69), predictor of Lemma 1,
eq (2)) on the adhesion plant of eqs (12)-(16), scenario of section 4.

A real traction controller samples the measured state at t_k = t0 + k T_c
(T_c = 1 / f_c), possibly ``tau_m`` old, evaluates its law once, quantises
the torque and holds it (zero-order hold, ZOH) until the next sample; the
plant receives the held torque h later (the input delay). Here:

* the controller is :func:`workbench.controllers.antiskid003_jit.control`
  (the laws of :mod:`workbench.controllers.antiskid003`, compiled), run with
  ``sampling = "zoh"``, step T_c, at the sample instants only, on the state
  measured ``tau_m`` before; its predictor's horizon is h + tau_m (the known
  loop delay) and its input history holds the quantised commands it sent;
* the plant is integrated on a mesh that does not depend on f_c in its
  accuracy: every stretch between two events (a measurement, a sample, the
  instant a held command reaches the wheel) is split into equal sub-steps of
  at most ``dt_p``, each an exponential-Euler step of
  :func:`workbench.sim.wheel_slip_jit.stiff_step` (the lambdified sympy model,
  never retyped) under a torque that is constant on it. When T_c and h are
  multiples of ``dt_p`` (and ``tau_m``) the mesh is the fixed grid k dt_p for
  every rate.
  Metrics are taken on that mesh, between samples too.

Why not :func:`scipy.integrate.solve_ivp` for the whole grid: a 5 kHz run
restarts the integration 10 000 times a second of simulated time (each sample,
each arriving command), each time with a fast creep-ratio transient (time
constant ~ v/4000 s) to resolve; scipy's Radau, restarted from Python, costs
about a millisecond per restart, a quarter of an hour per 5 kHz run. Radau is
kept as the independent check of this mesh (:mod:`.antiskid_sampled_check`).

Why this loop stays in papers/ (issue 35): it is paper 003's controller
(the laws, the predictor over the commands it sent, the mismatch-free hold)
compiled together with the adhesion plant's event mesh in one numba loop;
nothing of it serves another system. The general sampled-data machinery
calls it only through the sweep's ``run`` callback
(:func:`.antiskid_sampled.model`, :class:`workbench.features.rate_sweep.Runs`)
and the replay's ``record`` callback (:mod:`.antiskid_sampled_check`,
:func:`workbench.features.mesh_replay.replay_windows`).

:func:`kernel` is the loop, :func:`run_once` runs one scenario with it;
:data:`OUT` names its results.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...controllers.antiskid003_settings import CRUISE
from ...sim.wheel_slip import PARAM_ORDER, holding_torque
from .antiskid_scenario import EVS_SETTLE

#: Entries of the result array of the loop (:func:`kernel`; NaN: did not happen).
OUT = ("t_end", "lam_max", "lam_min", "time_above", "time_past_peak", "t_cruise",
       "t_handover", "t_stop", "stop_distance", "t_omega3", "evs_max", "t_diverged",
       "u_max_abs", "samples", "plant_steps", "unresolved", "v_end", "lam_end")

#: Scenario codes of :func:`kernel`'s loop.
TRACTION_SCENARIO, BRAKING_SCENARIO = 0, 1
#: Seconds the traction scenario runs on after the cruise law took over.
TRACTION_TAIL = 5.0
#: Seconds of cruise at (v_d, lambda_d) before t_brake in the braking scenario.
BRAKING_LEAD = 5.0


@lru_cache(maxsize=None)
def kernel():
    """The compiled loop ``run`` (below; compiled on first use, about 10 s,
    once per machine: the disk cache of :mod:`workbench.sim.jit_cache`).

    ``p``, ``pc``: plant and controller parameters (PARAM_ORDER); ``cfg``,
    ``st``, ``ubuf``, ``ev``: the compiled controller's settings (step T_c),
    state, input history and events; from ``t0`` at (``v0``, ``lam0``), the
    wheel receiving ``u_init`` until the first command arrives; commands
    rounded to multiples of ``q`` (0: none); plant sub-steps <= ``dt_p``.
    ``scenario``: TRACTION_SCENARIO ends ``tail`` s after the handover to the
    cruise law, BRAKING_SCENARIO at v <= ``v_stop`` (interpolated); both at
    ``t_cap`` or a divergence (the controller's test, or |lambda| >=
    ``lam_div`` on the mesh). On the mesh: the time with lambda >
    ``lam_thr`` and with lambda < -``lam_peak`` (past the braking peak); the
    largest creep-speed error |v_s - v_s*| of eq (76) from ``t_brake +
    settle`` while omega > ``omega_sw`` and lambda >= -``lam_peak``; the
    stopping distance from ``t_brake``. Results in ``out`` (:data:`OUT`)."""
    from ...sim.jit_cache import require_numba
    require_numba("a design's [sampled] table")
    import numba

    from ...controllers import antiskid003_jit as C
    from ...sim.jit_cache import cached
    from ...sim.wheel_slip_jit import BY_SIGN, creep_speed, stiff_step, wheel_speed

    jit = numba.njit(nogil=True, error_model="numpy")
    control, profile, E_HAND, E_TDIV = C.control, C.profile, C.E_HANDOVER, C.E_T_DIV
    PH, PUSHED, UNRES = C.PH, C.PUSHED, C.UNRES
    (T_END, L_MAX, L_MIN, T_ABOVE, T_PEAK, T_CRUISE, T_HAND, T_STOP, DIST, T_OM3, EVS, T_DIV,
     U_MAX, N_SAMPLES, N_STEPS, N_UNRES, V_END, L_END) = range(len(OUT))

    @jit
    def run(p, cfg, pc, v0, lam0, t0, Tc, h, tau_m, q, dt_p, u_init, st, ubuf, ev,
            scenario, t_cap, tail, lam_thr, lam_peak, v_d, v_stop, lam_div, omega_sw, r,
            t_brake, settle, rec_t0, rec_t1, rec, rec_u, out):
        """One run (module docstring, :func:`kernel`); ``rec`` (n, 4): t, v,
        lambda, applied u at every mesh point in [rec_t0, rec_t1]; ``rec_u``
        (n, 2): t_k, u_k of every sample there; returns how many of each."""
        out[:] = math.nan
        eps = 1e-9 * Tc
        Lq = int(math.ceil(tau_m / Tc)) + 3
        mq = np.zeros((Lq, 2))
        Lc = int(math.ceil(h / Tc)) + 3
        cmd = np.zeros(Lc)
        v, lam, t = v0, lam0, t0
        km, ks, kw = 0, 0, 0
        u_app = u_init
        lam_max, lam_min, above, past, dist = lam, lam, 0.0, 0.0, 0.0
        u_max, evs, steps, n_unres = 0.0, math.nan, 0, 0
        nrec, nrecu = 0, 0
        finished = False
        while not finished:
            # -- events at t: measurement (at t0 also those before it: the
            # initial state), then sample (the law), then the wheel
            while t0 + km * Tc - tau_m <= t + eps:
                mq[km % Lq, 0], mq[km % Lq, 1] = v, lam
                km += 1
            if t0 + ks * Tc <= t + eps:
                tk = t0 + ks * Tc
                mv, ml = mq[ks % Lq, 0], mq[ks % Lq, 1]
                u, ph, tc, tb, ts = control(tk, ml, mv, ml, st, ubuf, ev, cfg, pc)   # divergence on the sampled lambda
                if q > 0:
                    u = q * math.floor(u / q + 0.5)
                    ubuf[(int(st[PUSHED]) - 1) % ubuf.shape[0]] = u
                cmd[ks % Lc] = u
                if rec_t0 <= tk <= rec_t1 and nrecu < rec_u.shape[0]:
                    rec_u[nrecu, 0], rec_u[nrecu, 1] = tk, u
                    nrecu += 1
                u_max = max(u_max, abs(u))
                ks += 1
                if ev[E_TDIV] == ev[E_TDIV] and out[T_DIV] != out[T_DIV]:
                    out[T_DIV] = ev[E_TDIV]
                    finished = True
                if scenario == TRACTION_SCENARIO:
                    if ev[E_HAND] == ev[E_HAND] and tk >= ev[E_HAND] + tail:
                        finished = True
                    if ph == CRUISE and cfg[C.CRUISE_CREEP] == 0.0 and out[T_CRUISE] == \
                            out[T_CRUISE]:
                        finished = finished or tk >= out[T_CRUISE] + tail
            if t0 + kw * Tc + h <= t + eps:
                u_app = cmd[kw % Lc]
                kw += 1
            if finished or t >= t_cap:
                break
            # -- the plant to the next event
            t_next = min(t0 + km * Tc - tau_m, t0 + ks * Tc, t0 + kw * Tc + h, t_cap)
            span = t_next - t
            if span > eps:
                n = max(1, int(math.ceil(span / dt_p - 1e-9)))
                step = span / n
                for i in range(n):
                    tp = t + step
                    nv, nl, bad = stiff_step(v, lam, u_app, step, p, 1e-3, BY_SIGN)
                    steps += 1
                    if bad:
                        n_unres += 1
                        st[UNRES] = 1.0
                    lam_max, lam_min = max(lam_max, nl), min(lam_min, nl)
                    if nl > lam_thr:
                        above += step
                    if nl < -lam_peak:
                        past += step
                    if nv >= v_d and v < v_d and out[T_CRUISE] != out[T_CRUISE]:
                        out[T_CRUISE] = t + step * (v_d - v) / (nv - v)
                    if tp > t_brake:
                        dist += 0.5 * (v + nv) * (tp - max(t, t_brake))
                        if out[T_OM3] != out[T_OM3]:
                            if wheel_speed(max(nv, 1e-3), nl, r) <= omega_sw:
                                out[T_OM3] = tp
                            elif tp >= t_brake + settle and nl >= -lam_peak:
                                vs_on, _ = profile(tp, nv, 0.0, math.inf, cfg)
                                e = abs(creep_speed(nv, nl) - vs_on)
                                evs = e if evs != evs else max(evs, e)
                    if rec_t0 <= tp <= rec_t1 and nrec < rec.shape[0]:
                        rec[nrec, 0], rec[nrec, 1], rec[nrec, 2], rec[nrec, 3] = tp, nv, nl, u_app
                        nrec += 1
                    if scenario == BRAKING_SCENARIO and nv <= v_stop:
                        out[T_STOP] = t + step * (v - v_stop) / (v - nv)
                        dist -= 0.5 * (v_stop + nv) * (tp - out[T_STOP])
                        finished = True
                    elif not abs(nl) < lam_div or not nv == nv:
                        out[T_DIV] = tp
                        finished = True
                    v, lam, t = nv, nl, tp
                    if finished:
                        break
            if not finished:
                t = t_next
        out[T_END], out[L_MAX], out[L_MIN] = t, lam_max, lam_min
        out[T_ABOVE], out[T_PEAK], out[T_HAND] = above, past, ev[E_HAND]
        out[DIST] = dist if scenario == BRAKING_SCENARIO else math.nan
        out[U_MAX], out[EVS] = u_max, evs
        out[N_SAMPLES], out[N_STEPS], out[N_UNRES] = ks, steps, n_unres
        out[V_END], out[L_END] = v, lam
        return nrec, nrecu

    return cached(run, "antiskid_sampled_kernel.run")


@dataclass(frozen=True)
class Context:
    """What every run of a design shares: the case's controller settings,
    the plant, the scenario."""

    cs: object                # ControllerSettings of the case
    plant: np.ndarray
    h: float
    x0: tuple
    u_init: float
    t_brake: float
    t_end: float
    u_peak: float
    margin: float


def run_once(ctx: Context, rate: float, scenario: int, *, q: float = 0.0, tau: float = 0.0,
             dt_p: float, predictor_step: float = 0.0, emulation: bool = False,
             record: tuple | None = None, t_cap: float | None = None) -> tuple[dict, tuple]:
    """One scenario at f_c = ``rate`` (Hz): (kernel outputs by name, (mesh
    record, sample record)); ``record`` = (t0, t1, capacity) or None;
    ``t_cap``: end the run there at the latest (s). ``emulation``: the
    case's own hold (stiff, with its mismatch estimate)."""
    from ...controllers.antiskid003_jit import initial_state, settings_array
    run = kernel()
    Tc = 1.0 / rate
    cs = dataclasses.replace(ctx.cs, sampling="stiff" if emulation else "zoh",
                             h_model=ctx.cs.h_model + tau)
    group = max(1, int(math.floor(predictor_step / Tc + 1e-9)))
    cfg = settings_array(cs, Tc, group)
    st, ubuf = initial_state(cs, Tc, ctx.u_init)
    ev = np.full(6, np.nan)
    if scenario == BRAKING_SCENARIO:       # the cruise equilibrium, its torque held
        v0, l0 = cs.v_d, cs.lambda_d
        u0 = holding_torque(v0, l0, ctx.plant)
        st[0], ubuf[:] = CRUISE, u0
        t0, cap = ctx.t_brake - BRAKING_LEAD, ctx.t_end
    else:
        (v0, l0), u0, t0, cap = ctx.x0, ctx.u_init, 0.0, ctx.t_brake
    cap = cap if t_cap is None else min(cap, t_cap)
    t_a, t_b, n = record if record is not None else (-1.0, -1.0, 1)
    rec, rec_u = np.zeros((n, 4)), np.zeros((n, 2))
    out = np.empty(len(OUT))
    r = cs.params[PARAM_ORDER.index("r")]
    f = float
    nr, nu = run(ctx.plant, cfg, np.asarray(cs.params, float), f(v0), f(l0), f(t0), f(Tc),
                 f(ctx.h), f(tau), f(q), f(dt_p), f(u0), st, ubuf, ev, int(scenario), f(cap),
                 TRACTION_TAIL, f(cs.lambda_opt * (1 + ctx.margin)), f(cs.lambda_opt),
                 f(cs.v_d), f(cs.v_stop), f(cs.lam_diverged), f(cs.profile.omega_switch), f(r),
                 f(ctx.t_brake), EVS_SETTLE, f(t_a), f(t_b), rec, rec_u, out)
    return dict(zip(OUT, (float(x) for x in out))), (rec[:nr], rec_u[:nu])
