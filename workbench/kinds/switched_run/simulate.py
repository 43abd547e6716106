"""Simulate a ``switched-run`` design: a batch of runs of one scenario.

One loop serves the nominal run (a batch of one, recorded for the figures),
the step refinement of ``[convergence]`` and the Monte Carlo batch: the
states are arrays over the runs, every expression is the design's own sympy
expression (:class:`workbench.kinds.delay_feedback.model.PlantModel`, parsed
safely by :mod:`workbench.expr`) turned into numpy by ``lambdify`` once.

Per step n (t = n dt), for every run still going:

1. a run in a terminal phase whose ``until`` is >= 0 at the true state ends
   (completed); a run with a non-finite state, or a state beyond
   :data:`BOUND` (1 + |x0|), diverges, and so does a run switching more than
   ``max_switch_rate`` times within one second (chattering);
2. at a control instant (every step, or every ``period / dt`` steps with
   ``[sampled]``) the controller sees the state (quantised per
   ``[sampled.quantisation]``), predicted h ahead with ``predictor = true``
   (the nominal model integrated over the commands already sent, paper 003
   Lemma 1: X(t + h) = X(t) + int_t^{t+h} f(X(s), U(s - h)) ds, by the same
   Runge-Kutta steps as the plant); the first guard of its phase that is
   >= 0 switches the phase (at most one switch per instant), and the law of
   the (new) phase gives the command, held until the next instant (ZOH);
3. the plant takes a classical Runge-Kutta 4 step with the command of step
   n - h/dt (h a whole number of steps; the input is 0 before t = 0).

Switches happen on the controller's clock (every dt, or every period), so
switch times are step-quantised: they converge at first order in dt.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...features.comfort import RunningComfort

__all__ = ["BOUND", "Compiled", "Batch", "simulate"]

#: A state beyond BOUND (1 + |x0|) in magnitude has diverged.
BOUND = 1e6


class Compiled:
    """The design's expressions as numpy functions (built once per spec).

    ``f(X, U, P)``: the plant, rows of states; ``laws[p](Y, P)``: the commands of
    phase p; ``guards[p]``: ((to index, g(Y, P)), ...); ``until[p]`` or None.
    """

    def __init__(self, spec):
        import sympy as sp

        from ...expr import parse_expression
        from ..delay_feedback.model import PlantModel
        plant = spec.plant
        model = PlantModel(plant)
        self.params = tuple(plant.parameters)
        psyms = tuple(model.p[k] for k in self.params)
        self.n, self.m = len(model.x), len(model.u)
        fn = sp.lambdify(model.x + model.u + psyms, list(model.f), "numpy")
        self.f = lambda X, U, P: _stack(fn(*X, *U, *P), X.shape[1])
        names = dict(zip(plant.state_names, model.x)) | dict(model.p)
        names |= {k: model.definitions[k] for k in spec.usable}
        args = model.x + psyms

        def build(text, key):
            e = parse_expression(text, names, path=plant.path, key=key)
            g = sp.lambdify(args, e, "numpy")
            return lambda Y, P: _full(g(*Y, *P), Y.shape[1:])
        index = {p.name: i for i, p in enumerate(spec.phases)}
        self.laws, self.guards, self.until = [], [], []
        for i, ph in enumerate(spec.phases):
            laws = [build(t, f"phases[{i}].law.{u}") for t, u in zip(ph.law, plant.input_names)]
            self.laws.append(lambda Y, P, laws=laws: np.array([g(Y, P) for g in laws]))
            self.guards.append(tuple((index[to], build(w, f"phases[{i}].next.when"))
                                     for to, w in ph.next))
            self.until.append(build(ph.until, f"phases[{i}].until") if ph.terminal else None)
        self.index = index
        self.speed = None if spec.speed is None else plant.state_names.index(spec.speed)


def _full(v, shape) -> np.ndarray:
    """``v`` (an array or a constant) as a float array of ``shape``."""
    if isinstance(v, np.ndarray) and v.shape == shape:
        return v
    return np.broadcast_to(np.asarray(v, float), shape)


def _stack(out, N: int) -> np.ndarray:
    """The rows of a lambdified vector field as an (n, N) array."""
    if all(isinstance(o, np.ndarray) and o.shape == (N,) for o in out):
        return np.array(out)
    return np.array([_full(o, (N,)) for o in out])


def _rk4(f, X, U, P, dt):
    k1 = f(X, U, P)
    k2 = f(X + 0.5 * dt * k1, U, P)
    k3 = f(X + 0.5 * dt * k2, U, P)
    k4 = f(X + dt * k3, U, P)
    return X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4), k1


@dataclass(frozen=True)
class Batch:
    """Metrics of a batch of runs (arrays over the runs) and, for a batch of
    one run, its recorded trajectory.

    Attributes
    ----------
    metrics : dict[str, numpy.ndarray]
        Metric name (see :func:`workbench.kinds.switched_run.quantities.
        scenario_metrics`) -> value per run (nan: not determined).
    reasons : tuple[str, ...]
        Why each run ended ("until", "t_end", "diverged: ...", "chattering: ...").
    t, x, u, phase, accel : numpy.ndarray or None
        Recorded trajectory (batch of one): times, states (n, K), commands
        (m, K), phase index (K,), speed derivative (K,) or None.
    """

    metrics: dict
    reasons: tuple
    dt: float
    t: np.ndarray | None = field(default=None, repr=False)
    x: np.ndarray | None = field(default=None, repr=False)
    u: np.ndarray | None = field(default=None, repr=False)
    phase: np.ndarray | None = field(default=None, repr=False)
    accel: np.ndarray | None = field(default=None, repr=False)


def simulate(spec, comp: Compiled, scenario, dt: float, plant_params=None,
             record: bool = False) -> Batch:
    """Run ``scenario`` at step ``dt``.

    Parameters
    ----------
    spec : SwitchedRunSpec
    comp : Compiled
    scenario : Scenario
    dt : float
        Integration step (s); the delay and the control period are whole
        multiples of it (checked when the design is read).
    plant_params : dict[str, numpy.ndarray], optional
        Parameter values of the plant per run (Monte Carlo draws); default:
        the design's values with the scenario's overrides, one run.
    record : bool
        Keep the trajectory (a batch of one).

    Returns
    -------
    Batch
    """
    ctrl = spec.plant.values(scenario.parameters)
    Pc = [ctrl[k] for k in comp.params]
    if plant_params is None:
        N, Pp = 1, Pc
    else:
        N = len(next(iter(plant_params.values())))
        Pp = [plant_params.get(k, ctrl[k]) for k in comp.params]
    with np.errstate(all="ignore"):
        return _loop(spec, comp, scenario, dt, N, Pc, Pp, record)


def _loop(spec, comp, sc, dt, N, Pc, Pp, record):
    n, m, P = comp.n, comp.m, len(spec.phases)
    names, inputs = spec.plant.state_names, spec.plant.input_names
    x0 = np.array(sc.x0, float)
    X = np.repeat(x0[:, None], N, axis=1)
    bound = BOUND * (1.0 + np.abs(x0))[:, None]
    k = int(round(spec.h / dt))
    buf, pos = np.zeros((max(k, 1), m, N)), 0
    every = 1 if spec.sampled is None else int(round(spec.sampled.period / dt))
    quant = [] if spec.sampled is None else [
        (names.index(s), q) for s, q in spec.sampled.quantisation.items()]
    steps = int(round(sc.t_end / dt))
    ph = np.full(N, comp.index[sc.phase])
    act = np.ones(N, bool)
    nan = np.full(N, np.nan)
    U = np.zeros((m, N))
    reasons = ["t_end"] * N
    end_t, completed, diverged, div_t = np.full(N, sc.t_end), np.zeros(N), np.zeros(N), nan.copy()
    xmax, xmin = X.copy(), X.copy()
    tgt = [(names.index(s), v) for s, v in sc.target.items()]
    emax = {i: np.abs(X[i] - v) for i, v in tgt}
    umax = np.zeros((m, N))
    tin = np.zeros((P, N))
    first = {(a, b): nan.copy() for a, p in enumerate(spec.phases) for b, _ in comp.guards[a]}
    switches = np.zeros(N)
    history: dict[int, list] = {}
    comfort = None if comp.speed is None else RunningComfort(N, dt, spec.comfort)
    rec = [] if record else None
    for step in range(steps + 1):
        t = step * dt
        # 1. end of runs: until in a terminal phase, divergence
        for p, g in enumerate(comp.until):
            if g is not None:
                hit = act & (ph == p) & (g(X, Pc) >= 0)
                for j in np.flatnonzero(hit):
                    reasons[j] = "until"
                completed[hit], end_t[hit] = 1.0, t
                act &= ~hit
        bad = act & ~np.all(np.isfinite(X) & (np.abs(X) <= bound), axis=0)
        for j in np.flatnonzero(bad):
            i = int(np.argmax(~np.isfinite(X[:, j]) | (np.abs(X[:, j]) > bound[:, 0])))
            reasons[j] = f"diverged: |{names[i]}| beyond {BOUND:g} (1 + |x0|) at t = {t:.6g} s"
        diverged[bad], div_t[bad], end_t[bad] = 1.0, t, t
        act &= ~bad
        if step == steps or not act.any():
            break
        # 2. the controller at its instants
        if step % every == 0:
            Y = X.copy()
            for i, q in quant:
                Y[i] = q * np.round(Y[i] / q)
            for j in range(k if spec.predictor else 0):   # commands n-k .. n-1, oldest first
                Y = _rk4(comp.f, Y, buf[(pos + j) % k], Pc, dt)[0]
            new = ph.copy()
            for p in range(P):
                here = act & (ph == p)
                if not here.any():
                    continue
                undecided = here.copy()
                for to, g in comp.guards[p]:
                    go = undecided & (g(Y, Pc) >= 0)
                    new[go] = to
                    f_ = first[(p, to)]
                    f_[go & np.isnan(f_)] = t
                    undecided &= ~go
            moved = new != ph
            switches += moved
            for j in np.flatnonzero(moved):
                h_ = history.setdefault(j, [])
                h_.append(t)
                while h_ and h_[0] <= t - 1.0:
                    h_.pop(0)
                if len(h_) > sc.max_switch_rate:
                    act[j] = False
                    diverged[j], div_t[j], end_t[j] = 1.0, t, t
                    reasons[j] = (f"chattering: {len(h_)} switches within 1 s at t = {t:.6g} s "
                                  f"(cap {sc.max_switch_rate:g}/s)")
            ph = new
            for p in range(P):
                sel = ph == p
                if sel.any():
                    U[:, sel] = comp.laws[p](Y, Pc)[:, sel]
        # 3. the delayed command and a plant step
        if k:
            ua = buf[pos].copy()
            buf[pos], pos = U, (pos + 1) % k
        else:
            ua = U
        Xn, k1 = _rk4(comp.f, X, ua, Pp, dt)
        a = k1[comp.speed] if comp.speed is not None else None
        if a is not None:
            comfort.add(a, act)
        umax = np.where(act, np.fmax(umax, np.abs(U)), umax)
        for p in range(P):
            tin[p] += dt * (act & (ph == p))
        if rec is not None:
            rec.append((t, X[:, 0].copy(), U[:, 0].copy(), int(ph[0]),
                        np.nan if a is None else float(a[0])))
        X = np.where(act, Xn, X)
        xmax, xmin = np.fmax(xmax, X), np.fmin(xmin, X)
        for i, v in tgt:
            emax[i] = np.fmax(emax[i], np.abs(X[i] - v))
    if rec is not None:     # the last sample (the state the run ended in)
        rec.append((t, X[:, 0].copy(), U[:, 0].copy(), int(ph[0]), np.nan))
    ok = diverged == 0
    cut = lambda v: np.where(ok, v, np.nan)
    out = {}
    for i, s in enumerate(names):
        out[f"final.{s}"], out[f"peak.{s}"], out[f"min.{s}"] = cut(X[i]), cut(xmax[i]), cut(xmin[i])
    for i, v in tgt:
        out[f"final_error.{names[i]}"] = cut(X[i] - v)
        out[f"peak_error.{names[i]}"] = cut(emax[i])
    for i, u in enumerate(inputs):
        out[f"peak_abs.{u}"] = cut(umax[i])
    for p, phase in enumerate(spec.phases):
        out[f"time_in.{phase.name}"] = cut(tin[p])
    for (a, b), v in first.items():
        out[f"switch_time.{spec.phases[a].name}.{spec.phases[b].name}"] = cut(v)
    out["switches"] = cut(switches)
    out["end_time"], out["completed"] = cut(end_t), completed
    out["diverged"], out["diverged_time"] = diverged, div_t
    if comfort is not None:
        out |= {k: cut(v) for k, v in comfort.metrics().items()}
    if rec is None:
        return Batch(out, tuple(reasons), dt)
    t_, x_, u_, p_, a_ = zip(*rec)
    return Batch(out, tuple(reasons), dt, np.array(t_), np.array(x_).T, np.array(u_).T,
                 np.array(p_), np.array(a_))
