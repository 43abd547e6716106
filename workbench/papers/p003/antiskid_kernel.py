"""Compiled batch of antiskid runs: the closed loop of
:func:`workbench.papers.p003.antiskid_scenario.simulate_antiskid` (fixed step,
no recording) with numba, :data:`LANES` runs in flight at a time.

Per run and per sample, as the batched numpy path: the controller
(:func:`workbench.controllers.antiskid003_jit.control`: phase logic,
predictor rollout, laws), the metrics
(:func:`~workbench.papers.p003.antiskid_scenario.metric_updates`, the one
definition that the numpy path's recorder calls too), the plant's input delay line and the plant step with
per-run adaptive halving (:func:`workbench.sim.wheel_slip_jit.stiff_step`).
A run ends when it stops or diverges, as its lane of the batch freezes.

Speed without changing a bit: the small model and controller functions are
inlined into the loop (``inline="always"``), and the predictor rollouts and
plant steps of the runs in flight are interleaved. A model step is a chain
of dependent operations (an ``exp``, an ``expm1``, four divisions) around
two library calls, which the compiler does not reorder; each step is done
in two passes over the lanes (the model's forms of every lane, one ``exp``
each, then the steps, one ``expm1`` each), so that the calls of independent
runs follow each other and the processor overlaps them. Nothing in the loop
makes an array view (a view costs two atomic reference-count updates): the
lanes' state is read by row index, and the settings and the model
parameters are tuples of floats (values the compiler keeps in registers and
hoists: 1/c, 1/J of the controller's model are computed once). Each run
performs exactly the operations it performs alone (a test compares runs in
flight together with runs alone, bit for bit).

:data:`KERNELS` names the two paths a sweep may take, "compiled" (this
module) or "numpy" (:func:`~workbench.papers.p003.antiskid_scenario.simulate_antiskid`
with ``batch``): :mod:`workbench.sim.kernel_path`, re-exported for the
study's modules. The numpy path is the reference: ``tests/test_compiled_kernel.py``
compares every metric of the first 64 runs of the dry design's sweep.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ...controllers.antiskid003_settings import STOPPED
from ...sim.history import split_delay
from ...sim.kernel_path import KERNELS, Kernel, chosen_path, compiled_available, default_kernel
from ...sim.metric_rows import from_rows, initial_rows
from ...sim.perturb import perturbation_arrays, split_delays
from .antiskid_scenario import EVS_SETTLE, METRIC_FIELDS, RunMetrics, RunSettings, metric_updates

#: Runs a compiled batch keeps in flight at a time, their predictor rollouts
#: and plant steps interleaved. Measured on the dry sweep before the steps
#: were split in two passes (one process, ns per sample): 1 lane 828, 2 lanes
#: 632, 4 lanes 619; lanes cost nothing when runs end (a lane takes the next run).
LANES = 4


@lru_cache(maxsize=None)
def compile_kernel():
    """The compiled kernel ``run_batch`` (below), compiled in this process at
    the first call (a few seconds, once per machine: later processes load it
    from the disk cache of :mod:`workbench.sim.jit_cache`). A process pool
    started afterwards by ``fork`` inherits the compiled code."""
    import numba
    from numba import float64, int64, uint64

    from ...controllers import antiskid003_jit as C
    from ...sim.counter_rng import jit_functions
    from ...sim.jit_cache import cached
    from ...sim.jit_tuples import tuple_readers
    from ...sim.wheel_slip import PARAM_ORDER
    from ...sim.wheel_slip_jit import (BY_SIGN, GRADED, delay_at, fmax, forms, measured_state,
                                       split_delay, stiff_step_at)

    _, uniform, normal4 = jit_functions()

    jit = numba.njit(nogil=True, error_model="numpy")
    DT, control_pre, control_post = C.DT, C.control_pre, C.control_post
    record, _ = metric_updates()
    r_i = PARAM_ORDER.index("r")      # the plant's wheel radius in a row of ``plant``
    # the model parameters (PARAM_ORDER, then the slope: 0 for the
    # controller's model) and the settings (:data:`C.CFG`) as tuples of floats
    params_tuple, row_tuple = tuple_readers(jit, len(PARAM_ORDER), 1)
    cfg_tuple, _ = tuple_readers(jit, len(C.CFG))

    @jit
    def run_batch(plant, Np, fp, v0, lam0, u_init, T_end, cfg, pc, settle, st0, ub0, m0,
                  keys, pert, period, phase, out):
        """Simulate each run i (plant parameters ``plant[i]``, input delay
        (Np[i] + fp[i]) dt, initial speed v0[i]) into ``out[i]``; ``keys[i]``
        (v, omega, grade streams), ``pert`` (:data:`~workbench.sim.perturb.PERT`), ``period[i]``,
        ``phase[i]``: the perturbations of :mod:`workbench.sim.perturb`
        (:func:`~workbench.sim.perturb.perturbation_arrays`).

        :data:`LANES` runs are in flight at a time, each with its own state and
        clock; a lane that ends takes the next run at the next sample. Per sample, the lanes'
        predictor rollouts are interleaved (:func:`~workbench.controllers.antiskid003_jit.rollout_lanes`);
        every run performs the operations of a run simulated alone."""
        dt = cfg[DT]
        sv, sw, every = pert[0], pert[1], int(pert[2])
        noisy, graded, varying = sv > 0 or sw > 0, pert[3] != 0.0, pert[7] != 0.0
        B, P, K = plant.shape[0], plant.shape[1], LANES
        Lmax = max(2, np.max(Np) + 2)
        pg = np.zeros((K, P + 1))                 # plant parameters (+ the slope)
        pbuf = np.empty((K, Lmax))                # plant input delay line
        st, ubuf = np.empty((K, st0.shape[0])), np.empty((K, ub0.shape[0]))
        m, rs = np.empty((K, m0.shape[0])), np.zeros((K, 5))
        v, lam, pos = np.zeros(K), np.zeros(K), np.zeros(K)
        vm, lm, Pv, Pl = np.zeros(K), np.zeros(K), np.zeros(K), np.zeros(K)
        f, Lp, N, T, n = (np.zeros(K), np.zeros(K, np.int64), np.zeros(K, np.int64),
                          np.zeros(K, np.int64), np.zeros(K, np.int64))
        run, kind, ncs = np.full(K, -1), np.zeros(K, np.int64), np.zeros(K, np.int64)
        phs, tcs, tbs, tss = (np.zeros(K, np.int64), np.zeros(K, np.bool_),
                              np.zeros(K, np.bool_), np.zeros(K, np.bool_))
        active = np.zeros(K, np.bool_)
        fm = np.empty((K, 5))                     # scratch: the model forms of each lane
        ua_, go = np.zeros(K), np.zeros(K, np.bool_)   # the plant's input; lanes stepping
        form = GRADED if graded else BY_SIGN
        pc = params_tuple(pc)     # the controller's model: constants the compiler hoists
        cfg = cfg_tuple(cfg)      # the settings (:data:`~workbench.controllers.antiskid003_jit.CFG`)
        nxt = 0
        while True:
            busy = False
            for j in range(K):
                if not active[j] and nxt < B:     # the lane takes the next run, at t = 0
                    pg[j, :P] = plant[nxt]
                    N[j], f[j], Lp[j] = Np[nxt], fp[nxt], Np[nxt] + 2
                    pbuf[j, :Lp[j]] = u_init
                    st[j], ubuf[j], m[j] = st0, ub0, m0
                    rs[j] = 0.0
                    rs[j, 0] = v0[nxt]
                    v[j], lam[j], pos[j], T[j], n[j] = v0[nxt], lam0, 0.0, 0, 0
                    run[j], active[j] = nxt, True
                    nxt += 1
                if not active[j]:
                    continue
                busy = True
                i, t = run[j], T[j] * dt
                vm[j], lm[j] = v[j], lam[j]
                if noisy:
                    k = np.uint64(T[j] // every)
                    vm[j], lm[j] = measured_state(v[j], lam[j], normal4(keys[i, 0], k),
                                                  normal4(keys[i, 1], k), sv, sw, pg[j, r_i],
                                                  cfg[C.R_C], cfg[C.V_FLOOR])
                phs[j], tcs[j], tbs[j], tss[j] = control_pre(t, lam[j], vm[j], lm[j], st, ubuf,
                                                             m, j, cfg, pc)
                kind[j], ncs[j] = C.kind_of(phs[j], cfg), int(st[j, C.PUSHED])
                Pv[j], Pl[j] = vm[j], lm[j]
            if not busy:
                break
            C.rollout_lanes(Pv, Pl, kind, ubuf, st, ncs, fm, active, cfg, pc)
            for j in range(K):     # the laws' model forms, a pass of their own (as the steps)
                if active[j]:
                    fm[j, 0], fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4] = C.law_forms(
                        phs[j], Pv[j], Pl[j], cfg, pc)
            for j in range(K):
                if not active[j]:
                    continue
                t = T[j] * dt
                u, ph = control_post(t, vm[j], lm[j], Pv[j], Pl[j], phs[j],
                                     (fm[j, 0], fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4]), st,
                                     ubuf, m, j, cfg)
                record(t, v[j], lam[j], ph, tcs[j], tbs[j], tss[j], dt, m, rs, j, cfg,
                       pg[j, r_i], settle)
                L = Lp[j]
                pbuf[j, n[j] % L] = u
                n[j] += 1
                if varying:
                    N[j], f[j] = split_delay(delay_at(t, pert[8], pert[9], period[run[j]],
                                                      phase[run[j]]), dt)
                a = pbuf[j, (n[j] - 1 - N[j]) % L]
                ua = (1.0 - f[j]) * a + f[j] * pbuf[j, (n[j] - 2 - N[j]) % L]
                if T[j] >= T_end or ph >= STOPPED:
                    out[run[j]] = m[j]
                    active[j] = False
                    continue
                if graded:
                    jj = np.uint64(math.floor(fmax(pos[j], 0.0) / pert[6]))
                    pg[j, P] = pert[4] + (pert[5] - pert[4]) * uniform(keys[run[j], 2], jj)
                    pos[j] = pos[j] + dt * v[j]
                ua_[j], go[j] = ua, True
            # the plant steps in two passes over the lanes, as the rollouts
            # (C.rollout_lanes): the model's forms of every lane, then the steps
            for j in range(K):
                if go[j]:      # BY_SIGN reads the first P entries only
                    fm[j, 0], fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4] = forms(
                        fmax(v[j], 1e-3), lam[j], row_tuple(pg, j), form)
            for j in range(K):
                if go[j]:
                    v[j], lam[j], unres = stiff_step_at(
                        v[j], lam[j], ua_[j], dt, row_tuple(pg, j), 1e-3, form,
                        (fm[j, 0], fm[j, 1], fm[j, 2], fm[j, 3], fm[j, 4]))
                    st[j, C.UNRES] = 1.0 if unres else 0.0
                    T[j] += 1
                    go[j] = False

    a1, a2 = float64[::1], float64[:, ::1]
    run_batch = cached(run_batch, "antiskid_kernel.run_batch")
    run_batch.compile((a2, int64[::1], a1, a1, float64, float64, int64, a1, a1, float64, a1, a1,
                       a1, uint64[:, ::1], a1, a1, a1, a2))
    return run_batch


def simulate_batch_compiled(run: RunSettings, dt: float) -> RunMetrics:
    """Compiled counterpart of ``simulate_antiskid(run, dt, record_dt=None,
    batch=B)``: the same :class:`RunMetrics` (arrays of B runs).

    Parameters
    ----------
    run : RunSettings
        ``plant_params`` entries, ``h`` and ``x0[0]`` may be (B,) arrays.
    dt : float
        Step and sampling period (s).
    """
    from ...controllers.antiskid003_jit import initial_state, settings_array
    B = max(np.size(x) for x in (*run.plant_params, run.h, run.x0[0]))
    plant = np.column_stack([np.broadcast_to(np.asarray(x, float), (B,)) for x in run.plant_params])
    Np, fp = split_delays(np.broadcast_to(np.asarray(run.h, float), (B,)), dt)
    v0 = np.array(np.broadcast_to(np.asarray(run.x0[0], float), (B,)))
    cs = run.controller
    st0, ub0 = initial_state(cs, dt, run.u_init)
    m0 = initial_rows(RunMetrics, 1)[0]
    out = np.empty((B, len(METRIC_FIELDS)))
    keys, pert, period, phase = perturbation_arrays(run.perturb, B)
    if run.perturb is not None and run.perturb.delay is not None:
        Np[:] = split_delay(run.perturb.delay[1], dt)[0]     # the ring holds the longest delay
    compile_kernel()(plant, Np, fp, v0, float(run.x0[1]), float(run.u_init),
                     int(round(run.t_end / dt)), settings_array(cs, dt),
                     np.asarray(cs.params, float), EVS_SETTLE, st0, ub0, m0,
                     keys, pert, period, phase, out)
    return from_rows(RunMetrics, out, single=False)


def simulate_batch(run: RunSettings, dt: float, kernel: Kernel) -> RunMetrics:
    """A batch's :class:`RunMetrics` by the ``kernel`` path (:data:`KERNELS`;
    "compiled" runs the numpy path for the literal recursive predictor, which
    the compiled kernel does not cover)."""
    cs = run.controller
    if chosen_path(kernel, not (cs.compensate and cs.predictor != "rollout")) == "compiled":
        return simulate_batch_compiled(run, dt)
    from .antiskid_scenario import simulate_antiskid
    B = max(np.size(x) for x in (*run.plant_params, run.h, run.x0[0]))
    return simulate_antiskid(run, dt, record_dt=None, batch=B)[1]
