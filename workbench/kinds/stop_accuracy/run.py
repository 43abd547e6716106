"""Compute a ``stop-accuracy`` design: every controller from every speed on
the nominal plant and under every fault, the Monte Carlo, and the step
refinement.

* nominal and faults: one batch (:func:`workbench.sim.stopping.simulate`),
  the laws compiled once from the design's sympy expressions (``lambdify``);
* ``[montecarlo]``: one batch of ``samples`` runs per (speed, controller),
  every case meeting the same draws (common random numbers), the factors
  acting through :func:`.pipeline.apply_factors`; statistics by
  :func:`.pipeline.group_statistics` (share within the tolerance with its
  Wilson 95 % interval, 95th percentile of |error|, mean, overshoot share);
* ``[grid]``: every corner of the error grid per (speed, controller), in one
  batch (itertools.product of the factors' values, in the order written);
* ``[[sections]]`` with ``[repeats]``: every repeating controller's stops on
  every section, in one batch (:func:`run_sections`, :mod:`.sections`);
* ``[convergence]``: the nominal and fault batch again at dt/2 and dt/4, every
  stop error and every claim on one through :mod:`workbench.features.convergence`
  (a claim whose error has not converged is INCONCLUSIVE).

References
----------
L. F. Richardson, Phil. Trans. R. Soc. A 226:299-361, 1927 (step refinement).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...jsonable import json_method
from .pipeline import LAW_NAMES, apply_factors, group_statistics, open_loop_distance

__all__ = ["StopAccuracyResult", "compile_laws", "constant_sweep", "controller_index",
           "controller_montecarlo", "factor_traces", "grid_corners", "montecarlo_draws",
           "montecarlo_statistics", "run", "run_sections", "section_example", "section_runs",
           "section_statistics", "simulate_cases", "simulate_runs", "stopping_points",
           "speed_key"]


def speed_key(s: float) -> str:
    """``v50`` for 50 km/h: the prefix of a speed's quantities."""
    return f"v{s:g}"


@dataclass(frozen=True)
class StopAccuracyResult:
    spec: object
    distance: dict                                  # speed -> D (m)
    nominal: dict                                   # (speed, controller) -> error (m)
    faults: dict                                    # (speed, controller, fault) -> error (m)
    mc: dict = field(default_factory=dict)          # (speed, controller) -> StopStatistics
    levels: dict = field(default_factory=dict)      # quantity -> (dt, dt/2, dt/4) errors
    checks: dict = field(default_factory=dict)      # quantity -> Refinement
    refinement: tuple = ()                          # RefinementRow of claims on errors
    traces: dict = field(default_factory=dict, repr=False)  # (speed, ctl) -> (x - D, v)
    grid: dict = field(default_factory=dict)        # (speed, controller) -> errors per corner
    sections: dict = field(default_factory=dict)    # (section index, controller) -> CellStats

    JSON_FIELDS = {"distance": lambda r: {speed_key(s): d for s, d in r.distance.items()},
                   "nominal": lambda r: {f"{speed_key(s)}.{c}": e
                                         for (s, c), e in r.nominal.items()},
                   "montecarlo": lambda r: {f"{speed_key(s)}.{c}": [m.k, m.n]
                                            for (s, c), m in r.mc.items()},
                   "refinement": lambda r: {x.claim_id: x.outcome for x in r.refinement}}
    to_json = json_method


def controller_index(spec, name: str) -> int:
    """The index of the controller ``name`` in ``spec.controllers``."""
    return [c.name for c in spec.controllers].index(name)


def grid_corners(spec, order=None) -> list:
    """Every corner of ``[grid]`` (the product of the factors' values, in the
    order written), each a tuple of its factors' values, the factors as
    written or in ``order`` (their names)."""
    import itertools
    keys = [k for k, _ in spec.grid]
    at = [keys.index(k) for k in (order or keys)]
    return [tuple(c[j] for j in at) for c in itertools.product(*(v for _, v in spec.grid))]


def _law_names(spec) -> tuple:
    from .modules import REFERENCE_NAMES
    return tuple(LAW_NAMES) + (tuple(REFERENCE_NAMES) if spec.reference else ())


def compile_laws(spec) -> list:
    """law(values) -> command, per controller: the design's expressions as numpy
    functions of the law names, the constants and the definitions; with the
    named module ``pid``, (law, error, (kp, ki, kd)) (a PID is stateful: one
    :class:`~workbench.controllers.pid.BatchPID` per simulation)."""
    import sympy as sp

    from ...expr import parse_expression
    names = _law_names(spec) + tuple(spec.constants)
    out = []
    for i, c in enumerate(spec.controllers):
        if c.law is None:                  # the named module ``smarc`` is the whole law
            out.append(None)
            continue
        syms = {k: sp.Symbol(k, real=True) for k in names}
        args = tuple(syms[k] for k in names)
        for k, text in c.definitions:
            syms[k] = parse_expression(text, syms, path=spec.path,
                                       key=f"controllers[{i}].definitions.{k}")
        e = parse_expression(c.law, syms, path=spec.path, key=f"controllers[{i}].law")
        law = sp.lambdify(args, e, "numpy")
        if c.pid is not None:
            e = parse_expression(c.pid[0], syms, path=spec.path,
                                 key=f"controllers[{i}].pid.error")
            law = (law, sp.lambdify(args, e, "numpy"),
                   tuple(spec.constants[g].value for g in c.pid[1:]))
        out.append(law)
    return out


def _simulate(spec, laws, dt, cases, draws=None, record=False):
    """Stop errors (m) of ``cases`` [(speed, controller index, fault or None, D)],
    each repeated over the Monte Carlo ``draws`` (dict of arrays) when given."""
    tr, D = simulate_cases(spec, laws, dt, cases, draws)
    traces = {}
    if record:
        traces = {(c[0], spec.controllers[c[1]].name): (tr.x[:, k] - D[k], tr.v[:, k])
                  for k, c in enumerate(cases) if c[2] is None}
    return tr.x_stop - D, traces


def simulate_cases(spec, laws, dt, cases, draws=None, dt_rec=None, constants=None):
    """Simulate ``cases`` [(speed km/h, controller index, fault or None, D m)],
    each repeated over the Monte Carlo ``draws`` (factor -> array) when given,
    with ``constants`` (name -> array over the runs) in place of the design's,
    recorded every ``dt_rec`` (default dt_ctrl), in one batch (every operation
    is elementwise over runs: a run's result does not depend on the others in
    its batch).

    Returns
    -------
    tr : workbench.sim.stopping.Traces
        Recorded every control period.
    D : ndarray
        The stopping point of each run (m).
    """
    from ...sim.stopping import batch_params
    N = 1 if draws is None else len(next(iter(draws.values())))
    n = len(cases) * N
    base = spec.base()
    rep = lambda f: np.repeat(np.array([f(c) for c in cases], float), N)
    D = rep(lambda c: c[3])
    values = {} if draws is None else {k: np.tile(v, len(cases)) for k, v in draws.items()}
    for j, (_, _, fault, _) in enumerate(cases):
        for k, x in (fault.disturbance if fault else {}).items():
            values.setdefault(k, np.full(n, next(f.nominal for f in spec.factors
                                                 if f.name == k)))
            values[k][j * N:(j + 1) * N] = x
    over, theta, kappa = apply_factors(base, spec.factors, values, n)
    p = batch_params(base, n, over)
    for j, (_, _, fault, _) in enumerate(cases):
        for k, x in (fault.parameters if fault else {}).items():
            p[k][j * N:(j + 1) * N] = x
    ratio = rep(lambda c: c[2].speed_ratio if c[2] else 1.0)
    ctl = np.repeat([c[1] for c in cases], N)
    v0, x0 = rep(lambda c: c[0] / 3.6), 0.0
    if spec.reference is not None:    # start where the target starts braking
        x0, v0 = (rep(lambda c, k=k: spec.reference.start(c[3])[k]) for k in (0, 1))
    axles = None
    if any(c[2] is not None and c[2].axles for c in cases):
        k = len(next(c[2].axles for c in cases if c[2] is not None and c[2].axles))
        axles = np.repeat([list(c[2].axles if c[2] is not None and c[2].axles else "o" * k)
                           for c in cases], N, axis=0)
    tr, _ = simulate_runs(spec, laws, dt, p, ctl, D, x0=x0, v0=v0, ratio=ratio, theta=theta,
                          kappa=kappa, axles=axles, dt_rec=dt_rec, constants=constants)
    return tr, D


def simulate_runs(spec, laws, dt, p, ctl, D, *, x0, v0, ratio, theta, kappa, axles=None,
                  constants=None, dt_rec=None):
    """Simulate a batch of runs, each its own: brake parameters ``p``
    (:func:`workbench.sim.stopping.batch_params`), controller index ``ctl``,
    stopping point ``D`` (m), start ``x0`` (m), ``v0`` (m/s), speed-sensor
    ``ratio``, gradient ``theta`` and load-weighing gain ``kappa`` (arrays
    over the runs, or scalars); ``axles`` (shape (n, axles), states of
    :data:`.decel_loop.AXLE_STATES`; default all healthy) for the module
    ``deceleration_loop``, ``constants`` (name -> array over the runs) in place
    of the design's values, ``dt_rec`` the recording period (default dt_ctrl).

    Returns
    -------
    tr : workbench.sim.stopping.Traces
    track : .modules.Tracking
        The modules' state at the end (e.g. each SMARC's estimates).
    """
    from ...sim.stopping import simulate
    n = D.size
    groups = []
    from .modules import Tracking
    track = Tracking(spec, [(spec.controllers[i], np.flatnonzero(ctl == i))
                            for i in range(len(laws))], D)
    for i, law in enumerate(laws):
        idx = np.flatnonzero(ctl == i)
        pid = None
        if isinstance(law, tuple):         # the named module ``pid``: law + PID(error)
            from ...controllers.pid import BatchPID
            law, err, (kp, ki, kd) = law
            lim = spec.c_max if spec.controllers[i].pid_limited else np.inf
            pid = (err, BatchPID(kp, ki, kd, idx.size, dt=spec.dt_ctrl, u_min=-lim, u_max=lim))
        loop, c = None, spec.controllers[i]
        if c.loop is not None:             # the named module ``deceleration_loop``
            from .decel_loop import DecelerationLoop
            st = (np.full((idx.size, c.loop.axles), "o") if axles is None else
                  np.asarray(axles)[idx])
            loop = DecelerationLoop(c.loop.values(spec.constants), st, spec.dt_ctrl,
                                    spec.c_max)
        groups.append((law, idx, pid, c.name, loop, c.levels))
    const = {k: np.full(n, q.value) for k, q in spec.constants.items()}
    for k, x in (constants or {}).items():
        const[k] = np.broadcast_to(np.asarray(x, float), (n,))
    names = _law_names(spec) + tuple(const)
    longest = max(float(p["T1"].max()), float(p["T3"].max()))
    if not longest <= spec.t_end:       # the delay line would outgrow the run (memory)
        from ...errors import DesignError
        raise DesignError(spec.path, "sim.t_end", spec.t_end, "a horizon above every "
                          f"transmission delay a fault or draw gives (longest {longest:.4g} s)")

    def policy(t, o):
        x, v, ref = track.state(t, o)          # measured, or predicted (module predictor)
        vals = {"x": x, "v": v * ratio, "decel": np.maximum(-o.a, 0.0), "d_go": D - x,
                "D": D, "v0": v0, "t": np.full(n, t)} | ref | const
        c = np.zeros(n)
        with np.errstate(all="ignore"):    # a law's nan (e.g. sqrt(-1)) is a run without a stop
            for law, idx, pid, name, loop, _ in groups:
                if idx.size and law is None:
                    c[idx] = track.smarc_command(name, idx, vals["x"], vals["v"], ref)
                elif idx.size:
                    args = [vals[k][idx] for k in names]
                    c[idx] = np.broadcast_to(law(*args), idx.shape)
                    if pid is not None:
                        c[idx] += pid[1].step(np.broadcast_to(pid[0](*args), idx.shape))
                    if loop is not None:   # the law is the loop's target deceleration
                        c[idx] = loop.command(c[idx], vals["v"][idx])
        c = np.clip(c, spec.c_min, spec.c_max)
        for _, idx, _, _, _, levels in groups:
            if levels and idx.size:        # a channel of ``levels`` steps of c_max / levels
                c[idx] = np.round(c[idx] / spec.c_max * levels) / levels * spec.c_max
        return track.finish(c, o)

    tr = simulate(p, policy, n=n, t_end=spec.t_end, dt=dt, dt_ctrl=spec.dt_ctrl,
                  dt_rec=spec.dt_ctrl if dt_rec is None else dt_rec, x0=x0, v0=v0, theta=theta,
                  kappa=kappa, c_min=spec.c_min, c_max=spec.c_max)
    return tr, track


def _deterministic(spec, laws, dt, D, record=False):
    cases = [(s, i, f, D[s]) for s in spec.speeds_kmh for i in range(len(laws))
             for f in (None, *spec.faults)]
    err, traces = _simulate(spec, laws, dt, cases, record=record)
    q = {}
    for (s, i, f, _), e in zip(cases, err):
        name = f"{speed_key(s)}.{spec.controllers[i].name}."
        q[name + ("nominal_m" if f is None else f"fault[{f.name}].error_m")] = float(e)
    return q, traces


def stopping_points(spec) -> dict:
    """speed (km/h) -> the stopping point D (m): the design's distance, or the
    nominal stopping distance of its held command (paper 004 section 1)."""
    base = spec.base()
    return {s: spec.distance if spec.distance is not None else
            open_loop_distance(base, spec.command, s / 3.6, dt=spec.dt, dt_ctrl=spec.dt_ctrl)
            for s in spec.speeds_kmh}


def constant_sweep(spec, controller: str, name: str, values, distance: dict,
                   dt_rec=None) -> dict:
    """Stop error (m) of ``controller`` on the nominal plant from every speed
    for each of ``values`` of the constant ``name``, in one batch
    (:func:`simulate_cases`): {(value, speed km/h): error}, speed by speed.

    Parameters
    ----------
    distance : dict
        speed (km/h) -> the stopping point D (m) (:func:`stopping_points`).
    """
    ctl = controller_index(spec, controller)
    keys = [(x, s) for s in spec.speeds_kmh for x in values]
    tr, D = simulate_cases(spec, compile_laws(spec), spec.dt,
                           [(s, ctl, None, distance[s]) for _, s in keys], dt_rec=dt_rec,
                           constants={name: np.array([x for x, _ in keys], float)})
    return {k: float(e) for k, e in zip(keys, tr.x_stop - D)}


def montecarlo_draws(spec, mc) -> dict:
    """The drawn factors of ``mc`` (a MonteCarloSpec): factor -> array over
    its samples (:func:`workbench.features.montecarlo.draw`, every factor's
    stream at its position in ``[disturbances]``)."""
    from ...features.montecarlo import draw
    d = draw(mc, tuple(f.name for f in spec.factors), {f.name: f.nominal for f in spec.factors})
    return {k: v for k, v in d.items() if k in mc.distributions}


def montecarlo_statistics(spec, laws, cases, keys, dt_rec=None) -> dict:
    """key -> :class:`~workbench.features.montecarlo.StopStatistics` (m) of
    each of ``cases`` [(speed km/h, controller index, fault or None, D m)]
    over the ``[montecarlo]`` draws of ``spec``, every case meeting the same
    draws (common random numbers); ``keys`` names the cases in order."""
    mc = spec.montecarlo
    tr, D = simulate_cases(spec, laws, spec.dt, cases, montecarlo_draws(spec, mc), dt_rec=dt_rec)
    return group_statistics(tr.x_stop - D, keys, mc.samples, spec.tolerance)


def controller_montecarlo(spec, names, distance: dict, laws=None, dt_rec=None) -> dict:
    """{(speed km/h, controller): StopStatistics} of the controllers ``names``
    from every speed to its stopping point (``distance``: speed -> D m) over
    the ``[montecarlo]`` draws, all meeting the same draws
    (:func:`montecarlo_statistics`; ``laws`` of :func:`compile_laws`)."""
    cases = [(s, c) for s in spec.speeds_kmh for c in names]
    return montecarlo_statistics(spec, compile_laws(spec) if laws is None else laws, [
        (s, controller_index(spec, c), None, distance[s]) for s, c in cases], cases, dt_rec=dt_rec)


def factor_traces(spec, names, speed: float, D: float, factor: str, values,
                  dt_rec=None) -> dict:
    """{(value, controller): (position - D (m), speed (m/s))}: the recorded
    stops of the controllers ``names`` from ``speed`` (km/h) to ``D`` (m) with
    the factor ``factor`` at each of ``values`` (the others nominal), in one
    batch (:func:`simulate_cases`)."""
    tr, Dk = simulate_cases(spec, compile_laws(spec), spec.dt, [
        (speed, controller_index(spec, c), None, D) for c in names],
        {factor: np.array(values, float)}, dt_rec=dt_rec)
    n = len(values)
    return {(x, c): (tr.x[:, j * n + k] - Dk[j * n + k], tr.v[:, j * n + k])
            for j, c in enumerate(names) for k, x in enumerate(values)}


def section_runs(spec, laws, dt: float):
    """Every repeating controller's repeats on every section, in one batch
    (:func:`simulate_runs`; [[sections]], [repeats], :mod:`.sections`).

    Returns
    -------
    tr : workbench.sim.stopping.Traces
    track : .modules.Tracking
        The modules' state at the end (each SMARC's estimates).
    runs : dict
        ``controller``, ``section``, ``repeat`` (indices) and ``D`` (m) of every run.
    """
    from ...sim.stopping import batch_params
    from .sections import draw_sections
    rp = spec.sections
    ns, R = len(rp.sections), rp.count
    d = draw_sections(rp.seed, rp.ranges, ns, R)
    idx = [j for j, c in enumerate(spec.controllers) if not rp.controllers
           or c.name in rp.controllers]
    nc = len(idx)
    ci = np.repeat(idx, ns * R)
    si = np.tile(np.repeat(np.arange(ns), R), nc)
    ri = np.tile(np.arange(R), nc * ns)
    n = ci.size
    D = np.array([rp.sections[i].length for i in si])
    base = spec.base()
    over, theta, kappa = apply_factors(base, spec.factors, {k: v[si, ri] for k, v in d.items()},
                                       n)
    starts = [spec.reference.start(s.length) for s in rp.sections]
    x0 = np.array([starts[i][0] for i in si])
    v0 = np.array([starts[i][1] for i in si])
    tr, track = simulate_runs(spec, laws, dt, batch_params(base, n, over), ci, D, x0=x0, v0=v0,
                              ratio=np.ones(n), theta=theta, kappa=kappa)
    return tr, track, {"controller": ci, "section": si, "repeat": ri, "D": D}


def section_example(spec, tr, runs, name: str, section: int = 0) -> tuple:
    """(t (s), position - D (m), v (m/s), x_d - D (m), v_d (m/s)) of the first
    repeat of the controller ``name`` on the section ``section`` (index) of
    :func:`section_runs` (its ``tr`` and ``runs``), with its target."""
    ci, si, D = runs["controller"], runs["section"], runs["D"]
    j = int(np.flatnonzero((ci == controller_index(spec, name)) & (si == section))[0])
    xd, vd, _ = spec.reference.braking(D[j], tr.t)
    return tr.t, tr.x[:, j] - D[j], tr.v[:, j], xd, vd


def section_statistics(spec, tr, runs) -> dict:
    """{(section index, controller): CellStats} of :func:`section_runs`."""
    from .sections import batch_rates, cell_stats
    ci, si = runs["controller"], runs["section"]
    err_cm, rates = (tr.x_stop - runs["D"]) * 100.0, batch_rates(tr, spec.dt_ctrl)
    return {(s, c.name): cell_stats(err_cm, tr, (ci == j) & (si == s), rates)
            for s in range(len(spec.sections.sections)) for j, c in enumerate(spec.controllers)
            if j in set(ci.tolist())}


def run_sections(spec, laws, dt: float) -> dict:
    """{(section index, controller): CellStats}: every controller's repeats on
    every section, in one batch (:func:`section_runs`)."""
    tr, _, runs = section_runs(spec, laws, dt)
    return section_statistics(spec, tr, runs)


def run(spec, claims=()) -> StopAccuracyResult:
    """Compute a design (see the module docstring)."""
    laws = compile_laws(spec)
    D = stopping_points(spec)
    q, traces = _deterministic(spec, laws, spec.dt, D, record=True)
    nominal = {(s, c.name): q[f"{speed_key(s)}.{c.name}.nominal_m"]
               for s in spec.speeds_kmh for c in spec.controllers}
    faults = {(s, c.name, f.name): q[f"{speed_key(s)}.{c.name}.fault[{f.name}].error_m"]
              for s in spec.speeds_kmh for c in spec.controllers for f in spec.faults}
    mc = {}
    if spec.montecarlo is not None:
        mc = controller_montecarlo(spec, [c.name for c in spec.controllers], D, laws)
    grid = {}
    if spec.grid:
        corners = grid_corners(spec)
        g = {k: np.array([c[j] for c in corners], float) for j, (k, _) in enumerate(spec.grid)}
        cases = [(s, i, None, D[s]) for s in spec.speeds_kmh for i in range(len(laws))]
        err, _ = _simulate(spec, laws, spec.dt, cases, draws=g)
        N = len(corners)
        grid = {(s, spec.controllers[i].name): tuple(float(e) for e in err[j * N:(j + 1) * N])
                for j, (s, i, _, _) in enumerate(cases)}
    sections = {}
    if spec.sections is not None:
        sections = run_sections(spec, laws, spec.dt)
    levels, checks, rows = {}, {}, ()
    if spec.convergence:
        from ...features.convergence import by_metric, level_checks, rows_of, three_levels
        levels = by_metric(three_levels(lambda h: _deterministic(spec, laws, h, D)[0], spec.dt,
                                        first=q))
        checks = level_checks(levels, finite=True)
        rows = tuple(rows_of(((c, levels[c.quantity]) for c in claims if c.quantity in levels),
                             determined=math.isfinite))
    return StopAccuracyResult(spec, D, nominal, faults, mc, levels, checks, rows, traces, grid,
                              sections)
