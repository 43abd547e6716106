"""``[montecarlo]`` of a ``delay-feedback`` design: every scenario again with
the plant's parameters drawn (issue 35, "Done when", second bullet).

Table (optional; absent: nothing changes)::

    [montecarlo]
    samples = 100
    seed = 1
    [montecarlo.distributions]
    m = { dist = "normal", mean = 5e5, sd = 2.5e4, lo = 4e5, hi = 6e5, source = "..." }

Draws are those of :func:`workbench.features.montecarlo.draw` (seeded, per
parameter). The gain K and the operating point stay the design's (the
controller does not know the draw); the predictor, when a scenario has one,
integrates the nominal model. Each batch runs at the scenario's reported step
dt/2 with the same Runge-Kutta 4 steps and exact delayed ZOH averages
(:class:`workbench.sim.history.DelayLine`) as the nominal run. A scenario
with a parameter schedule is not drawn (its schedule already sets those
parameters). Quantities: ``montecarlo.<s>.runs``, ``.diverged`` (count) and
``montecarlo.<s>.max.<metric>`` of the nominal metrics
(``peak_error.<x>``, ``final_error.<x>``, ``peak_input_dev.<u>``).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...features.montecarlo_stats import finite_span

__all__ = ["MonteCarloScenario", "load_montecarlo_table",
           "montecarlo_batch", "montecarlo_names", "montecarlo_values", "run_montecarlo",
           "montecarlo_section"]

#: A run whose error passes this factor of (1 + |x_op| + |x0|) has diverged (as the nominal run).
SCALE = 1e6


@dataclass(frozen=True)
class MonteCarloScenario:
    """The drawn runs of one scenario: their metrics (arrays over the runs)."""

    name: str
    samples: int
    metrics: dict = field(repr=False)


def load_montecarlo_table(root, plant):
    """``[montecarlo]`` (a :class:`workbench.features.montecarlo.MonteCarloSpec`) or None."""
    if not root.has("montecarlo"):
        return None
    from ...features.montecarlo import load_montecarlo
    return load_montecarlo(root, {k: False for k in plant.parameters}, max_samples=2000)


def _metric_names(spec) -> list[str]:
    p = spec.plant
    return ([f"peak_error.{s}" for s in p.state_names] + [f"final_error.{s}" for s in
                                                         p.state_names]
            + [f"peak_input_dev.{u}" for u in p.input_names])


def _drawn(spec):
    return [s for s in spec.scenarios if not s.parameters]


def montecarlo_names(spec) -> set[str]:
    """Claimable Monte Carlo quantities (known before running)."""
    out = set()
    for s in _drawn(spec):
        out |= {f"montecarlo.{s.name}.runs", f"montecarlo.{s.name}.diverged"}
        out |= {f"montecarlo.{s.name}.max.{m}" for m in _metric_names(spec)}
    return out


def montecarlo_values(r) -> dict:
    """Their values (None: no run determined the metric)."""
    out = {}
    for mc in r.montecarlo or ():
        out[f"montecarlo.{mc.name}.runs"] = mc.samples
        out[f"montecarlo.{mc.name}.diverged"] = int(mc.metrics["diverged"].sum())
        for k, v in mc.metrics.items():
            if k != "diverged":
                out[f"montecarlo.{mc.name}.max.{k}"] = finite_span(v)[1]
    return out


def run_montecarlo(spec, model, values, op, K, reference, predict, *, folder=None,
                   design: str = "", resume: bool = False) -> tuple[MonteCarloScenario, ...]:
    """Every scenario without a parameter schedule, with the plant's
    parameters drawn (see the module docstring); ``reference`` and
    ``predict`` are the nominal run's (:mod:`.run`, which calls this).
    The one path of the report and of ``workbench sweep``
    (:func:`workbench.features.montecarlo_chunks.run_groups`): one batch per
    scenario, or with ``folder`` (``sweep --out``) the chunk files of
    :func:`~workbench.features.montecarlo_chunks.run_chunks` (its manifest:
    the ``design``'s name, the scenarios, samples and seed); a chunk's runs equal the one batch's up to the last
    bits of the gain's matrix product (the only operation not elementwise
    over the runs)."""
    from ...features.montecarlo import drawn_factors
    from ...features.montecarlo_chunks import Group, run_groups
    mc = spec.montecarlo
    draws = drawn_factors(mc, tuple(spec.plant.parameters))
    batch = montecarlo_batch(spec, model, values, op, K, reference, predict)
    scen = {sc.name: sc for sc in _drawn(spec)}
    got = run_groups([Group(name, draws) for name in scen],
                     lambda g, d: (batch(scen[g.name], d).metrics, None), folder,
                     {"design": design, "scenarios": list(scen), "samples": mc.samples,
                      "seed": mc.seed}, resume)
    return tuple(MonteCarloScenario(name, mc.samples, got[name].metrics) for name in scen)


def montecarlo_batch(spec, model, values, op, K, reference, predict):
    """``batch(scenario, drawn) -> MonteCarloScenario``: the runs of one
    scenario for the drawn parameters ``drawn`` (name -> array over the
    runs; a parameter left out is nominal), the model compiled once.
    Every operation but the gain's matrix product is elementwise over the
    runs (``sweep --out`` cuts a sweep into such batches,
    :mod:`workbench.features.montecarlo_chunks`)."""
    import sympy as sp
    names = tuple(spec.plant.parameters)
    fn = sp.lambdify(model.x + model.u + tuple(model.p[k] for k in names), list(model.f),
                     "numpy")
    Pn = [values[k] for k in names]
    K = np.atleast_2d(K)

    def batch(sc, drawn) -> MonteCarloScenario:
        N = len(next(iter(drawn.values())))
        P = [drawn.get(k, values[k]) for k in names]

        def stack(out):
            return np.array([np.broadcast_to(np.asarray(o, float), (N,)) for o in out])
        f = lambda x, u: stack(fn(*x, *u, *P))
        f_nom = lambda x, u: stack(fn(*x, *u, *Pn))
        return _batch(spec, op, K, sc, f, f_nom, N, reference(spec, op, sc), predict)
    return batch


def _rk4(f, x, u, h):
    k1 = f(x, u)
    k2 = f(x + 0.5 * h * k1, u)
    k3 = f(x + 0.5 * h * k2, u)
    k4 = f(x + h * k3, u)
    return x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)


def _batch(spec, op, K, sc, f, f_nom, N, ref, predict) -> MonteCarloScenario:
    from ...sim.history import DelayLine
    dt = sc.dt / 2
    names = spec.plant.state_names
    x0 = op.x.copy()
    for k, v in sc.x0.items():
        x0[names.index(k)] = v
    scale = (SCALE * (1.0 + np.abs(op.x) + np.abs(x0)))[:, None]
    x = np.repeat(x0[:, None], N, axis=1)
    u_op = op.u[:, None]
    line = DelayLine(sc.h, dt, np.repeat(u_op, N, axis=1))
    steps = int(round(sc.t_end / dt))
    peak = np.zeros_like(x)
    du = np.zeros((op.u.size, N))
    bad = np.zeros(N, bool)
    with np.errstate(all="ignore"):
        for n in range(steps + 1):
            t = n * dt
            e = np.abs(x - ref(t)[:, None])
            bad |= ~np.all(np.isfinite(e) & (e < scale), axis=0)
            x[:, bad] = np.nan
            peak = np.fmax(peak, e)
            if n == steps:
                break
            if sc.predictor:
                xp = predict(f_nom, x, line.pieces(), dt)
                u = u_op + K @ (xp - ref(t + sc.h)[:, None])
            else:
                u = u_op + K @ (x - ref(t)[:, None])
            du = np.fmax(du, np.abs(u - u_op))
            line.push(u)
            x = _rk4(f, x, line.delayed(), dt)
    cut = lambda v: np.where(bad, np.nan, v)
    out = {}
    for i, s in enumerate(names):
        out[f"peak_error.{s}"], out[f"final_error.{s}"] = cut(peak[i]), cut(e[i])
    for j, u in enumerate(spec.plant.input_names):
        out[f"peak_input_dev.{u}"] = cut(du[j])
    out["diverged"] = bad.astype(float)
    return MonteCarloScenario(sc.name, N, out)


def montecarlo_section(spec, r) -> str:
    """The report section (Markdown)."""
    from ...report.markdown import fmt, md_table
    mc = spec.montecarlo
    dist = [[f"`{k}`", d.describe(), d.source] for k, d in mc.distributions.items()]
    rows = []
    for m in r.montecarlo or ():
        for k, v in m.metrics.items():
            if k == "diverged":
                rows.append([f"`{m.name}`", "diverged (runs)", f"{int(v.sum())} of {m.samples}",
                             ""])
            else:
                rows.append([f"`{m.name}`", f"`{k}`", *(fmt(x, 4) for x in finite_span(v))])
    skipped = [s.name for s in spec.scenarios if s.parameters]
    return ("## Monte Carlo\n\nEvery scenario again with the plant's parameters drawn "
            f"({mc.samples} runs, seed {mc.seed}; `workbench/features/montecarlo.py`); the gain, "
            "the operating point and the predictor's model stay nominal. Runs at each "
            "scenario's reported step dt/2, as the nominal run."
            + (" Not drawn (parameter schedule): " + ", ".join(f"`{s}`" for s in skipped) + "."
               if skipped else "") + "\n\n"
            + md_table(["parameter", "distribution", "source"], dist, "lll") + "\n\n"
            + md_table(["scenario", "metric", "min over runs", "max over runs"], rows, "llrr"))
