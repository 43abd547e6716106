"""Markdown and figures of a ``switched-run`` design (pure rendering)."""
from __future__ import annotations

import math

import numpy as np

from ...features.comfort import TIMES
from ...features.convergence import claim_table
from ...features.montecarlo_stats import finite_span
from ...report.case_tables import fmt_finite
from ...report.display_math import display_math
from ...report.markdown import Figure, Rendered, fmt, md_table
from ...sim.convergence import P_MAX, P_MIN
from .quantities import scenario_metrics
from .simulate import BOUND
from .study import ALPHA, P_SHOWN, runs_for

__all__ = ["render"]


def render(design, res) -> Rendered:
    """The report sections and figures of a ``switched-run`` design."""
    from ..delay_feedback.render import model_latex
    spec = design.spec
    sections = [_problem(spec), "## Model\n\n" + display_math(model_latex(spec))
                + "\n\nThe input acts with the delay: u = u(t − h) in the equations."]
    sec, figs = _runs(spec, res)
    sections.append(sec)
    if spec.convergence:
        sections.append(_convergence(spec, res))
    if spec.montecarlo is not None:
        sec, mfigs = _montecarlo(spec, res)
        sections.append(sec)
        figs += mfigs
    anchors = (("scenario\\.", "Runs"), ("montecarlo\\.", "Monte Carlo"))
    return Rendered(tuple(sections), tuple(figs), anchors)


def _control_text(spec) -> str:
    parts = [f"input delay h = {fmt(spec.h)} s ({spec.h_source})"]
    parts.append("the law and the guards act on the state **predicted h ahead** (the nominal "
                 "model integrated over the commands already sent, paper 003 Lemma 1)"
                 if spec.predictor else "no predictor (the law sees the current state)")
    if spec.sampled is None:
        parts.append("the controller acts at every integration step")
    else:
        q = ", ".join(f"{k} to {fmt(v)}" for k, v in spec.sampled.quantisation.items())
        parts.append(f"sampled: the controller acts every T = {fmt(spec.sampled.period)} s "
                     f"({fmt(1 / spec.sampled.period)} Hz) and holds its command (ZOH)"
                     + (f"; measurements quantised ({q})" if q else ""))
    return "; ".join(parts) + "."


def _problem(spec) -> str:
    p = spec.plant
    var = [[f"`{v.name}`", "state", v.unit, v.description, v.source] for v in p.states]
    var += [[f"`{v.name}`", "input", v.unit, v.description, v.source] for v in p.inputs]
    par = [[f"`{k}`", fmt(q.value, 6), q.unit, q.source] for k, q in p.parameters.items()]
    ph = []
    for x in spec.phases:
        law = "; ".join(f"{u} = `{t}`" for u, t in zip(p.input_names, x.law))
        nxt = "; ".join(f"→ {to} when `{w}` ≥ 0" for to, w in x.next) or "—"
        end = f"ends when `{x.until}` ≥ 0" if x.terminal else "—"
        ph.append([f"`{x.name}`", law, nxt, end])
    return ("## Problem\n\nA `switched-run` design: the plant is the text of the design file, "
            "parsed safely (`workbench/expr.py`: Python's `ast` against a whitelist, never "
            "evaluated) into one sympy model; each phase has its own control law, and its "
            "guards, tried in order at each control instant, switch the phase when they "
            f"become ≥ 0 (one switch per instant). Control: {_control_text(spec)}\n\n"
            + md_table(["name", "role", "unit", "meaning", "source"], var, "lllll")
            + "\n\n" + md_table(["parameter", "value", "unit", "source"], par, "lrll")
            + "\n\n" + md_table(["phase", "law", "guards (in order)", "terminal"], ph, "llll"))


def _runs(spec, res):
    rows, figs = [], []
    for r in res.scenarios:
        sc = r.scenario
        units = scenario_metrics(spec, sc.name)
        for k, v in r.values.items():
            rows.append([f"`{sc.name}`", f"`{k}`", fmt(v, 5), units[k]])
        over = ", ".join(f"{k} = {fmt(v, 6)}" for k, v in sc.parameters.items())
        cap = (f"Scenario {sc.name} (h = {fmt(spec.h)} s, dt = {fmt(sc.dt)} s"
               + ("" if spec.sampled is None else f", T = {fmt(spec.sampled.period)} s")
               + (", predictor" if spec.predictor else "") + ")")
        figs.append(Figure(f"run-{sc.name}", cap, lambda fig, r=r: _plot_run(fig, r, spec),
                           (6.4, 1.5 * (len(spec.plant.states) + len(spec.plant.inputs)
                                        + 1 + (spec.speed is not None)))))
        rows.append([f"`{sc.name}`", "ended", r.nominal.reasons[0], ""])
        if over:
            rows.append([f"`{sc.name}`", "parameter overrides", over, ""])
    md = ("## Runs\n\nThe plant equations (not a linearisation), classical Runge-Kutta 4 per "
          "step, the command applied h later (h a whole number of steps; 0 before t = 0). "
          "Each scenario's metrics at its designed step dt (the values the claims compare). "
          "`final`/`peak`/`min`: the state at the end, its largest and smallest value; "
          "`final_error`: the state minus its target at the end; `time_in`: seconds in a "
          "phase; `switch_time.a.b`: the first switch a → b (nan: none); `diverged`: a "
          f"non-finite state, a state beyond {fmt(BOUND)} (1 + |x0|), or more switches within "
          "one second "
          "than the scenario's cap (chattering) — the run then stops there; "
          "`peak_abs_accel`/`peak_abs_jerk`: the largest |d speed/dt| (the plant's right-hand "
          "side) and |d² speed/dt²| (its step-to-step difference / dt)." + _limits_text(spec)
          + "\n\n"
          + md_table(["scenario", "metric", "value", "unit"], rows, "llrl")
          + "\n\n" + "\n\n".join(f"![{f.caption}]({{figdir}}/{f.name}.png)" for f in figs))
    return md, figs


def _limits_text(spec) -> str:
    """The comfort limits of ``[comfort]`` behind the ``time_above_*`` metrics ("" without)."""
    lim = spec.comfort
    given = [] if lim is None else [
        f"`{name}`: the time with |{what}| > {fmt(q.value)} {q.unit} ({q.source})"
        for name, what, q in zip(TIMES, ("d speed/dt", "d² speed/dt²"), (lim.a_max, lim.jerk_max))
        if q is not None]
    return "".join(f" {g}." for g in given)


def _plot_run(fig, r, spec):
    b, p = r.nominal, spec.plant
    step = max(1, b.t.size // 3000)
    t = b.t[::step]
    panels = [(f"{v.name} ({v.unit})", b.x[i, ::step], "C0") for i, v in enumerate(p.states)]
    panels += [(f"{v.name} ({v.unit})", b.u[j, ::step], "C1") for j, v in enumerate(p.inputs)]
    if spec.speed is not None:
        unit = next(v.unit for v in p.states if v.name == spec.speed)
        panels.append((f"d{spec.speed}/dt ({unit}/s)", b.accel[::step], "C2"))
    n = len(panels) + 1
    for k, (label, y, colour) in enumerate(panels):
        ax = fig.add_subplot(n, 1, k + 1)
        ax.plot(t, y, color=colour, lw=1.0)
        ax.set_ylabel(label, fontsize=7)
        name = label.split(" ")[0]
        if name in r.scenario.target:
            ax.axhline(r.scenario.target[name], color="k", ls="--", lw=0.7, label="target")
            ax.legend(loc="best", fontsize=6)
    ax = fig.add_subplot(n, 1, n)
    ax.step(t, b.phase[::step], where="post", color="C3", lw=1.0)
    ax.set_yticks(range(len(spec.phases)), [x.name for x in spec.phases], fontsize=6)
    ax.set_ylabel("phase", fontsize=7)
    ax.set_xlabel("t (s)")


def _convergence(spec, res) -> str:
    rows = []
    for r in res.scenarios:
        for m, c in r.checks:
            rows.append([f"`{r.scenario.name}`", f"`{m}`", *(fmt(x, 5) for x in c.values),
                         fmt_finite(c.order, 2), fmt(c.estimate, 2)])
    return ("## Convergence\n\nEvery scenario again at dt/2 and dt/4 (the delay and the "
            "control period unchanged: they are whole numbers of the finest step). Observed "
            "order p = log2(|q1 − q2| / |q2 − q4|) and Richardson's estimate of the error "
            "left in q4 (`workbench/sim/convergence.py`, with its guards: p clipped to "
            f"[{fmt(P_MIN)}, {fmt(P_MAX)}]; differences at rounding level count as converged). "
            "Switch instants lie "
            "on the controller's clock, so metrics that depend on them converge at first "
            "order.\n\n"
            + md_table(["scenario", "metric", "q1 (dt)", "q2 (dt/2)", "q4 (dt/4)", "p",
                        "estimate"], rows, "llrrrrr")
            + "\n\nEvery claim on a scenario metric against its tolerance (the claim's "
            "tolerance for `within`, the distance from the value to the bound for `<=`/`>=`, "
            "half a printed unit for `==` with digits; `workbench/features/refinement.py`): a claim "
            "whose metric has not converged is INCONCLUSIVE with this reason.\n\n"
            + claim_table(res.refinement))


def _montecarlo(spec, res):
    mc = spec.montecarlo
    dist = [[f"`{k}`", d.describe(), d.source] for k, d in mc.distributions.items()]
    parts, figs = [], []
    for r in res.scenarios:
        m = r.montecarlo
        sc = r.scenario
        units = scenario_metrics(spec, sc.name)
        rows = []
        for k, v in m.metrics.items():
            lo, hi = finite_span(v)          # None (printed —) when no run has it
            rows.append([f"`{k}`", fmt(lo, 4), fmt(hi, 4), units[k]])
        bad = sorted({x for x in m.reasons if x not in ("until", "t_end")})[:3]
        parts.append(
            f"### Scenario `{sc.name}`\n\n{m.samples} runs: {int(m.metrics['completed'].sum())} "
            f"ended by their terminal condition, {int(m.metrics['diverged'].sum())} diverged or "
            "chattered" + (" (first reasons: " + "; ".join(bad) + ")" if bad else "") + ".\n\n"
            + md_table(["metric", "min over runs", "max over runs", "unit"], rows, "lrrl"))
        claimed = [c for c in spec.claims if c.scenario == sc.name     # continuous metrics
                   and c.claim.digits is None][:4]
        if claimed:
            figs.append(Figure(f"montecarlo-{sc.name}",
                               f"Monte Carlo, scenario {sc.name} ({m.samples} runs, seed "
                               f"{m.seed}, h = {fmt(spec.h)} s, dt = {fmt(sc.dt)} s)",
                               lambda fig, m=m, c=claimed: _plot_mc(fig, m, c, units),
                               (6.4, 2.0 * len(claimed) + 0.6)))
            parts[-1] += f"\n\n![{figs[-1].caption}]({{figdir}}/{figs[-1].name}.png)"
    rates = [[f"`{c.claim_id}`", f"{c.passes} / {c.n}", fmt(c.p, 4),
              f"[{fmt(c.lo, 4)}, {fmt(c.hi, 4)}]",
              "—" if c.success_run_lower is None else fmt(math.floor(
                  c.success_run_lower * 1e4) / 1e4, 4)] for c in res.claim_rates]
    md = ("## Monte Carlo\n\nThe plant's parameters drawn per run (seeded: numpy "
          f"`default_rng([seed, k])`, k the parameter's index; seed {mc.seed}, {mc.samples} "
          "runs; `workbench/features/montecarlo.py`); the controller keeps the design's "
          "values (it does not know the draw). A run whose metric is not determined (it "
          "diverged) counts as failing every claim.\n\n"
          + md_table(["parameter", "distribution", "source"], dist, "lll")
          + "\n\nShare of runs that pass each claim on a scenario metric, with its Wilson "
          "score 95 % interval. Success-run rule: with no failure in n runs, the pass "
          f"probability is at least {fmt(ALPHA)}^(1/n) with {fmt(100 * (1 - ALPHA))} % "
          "confidence (one-sided; rounded down to 4 digits): 0 failures in n ≥ "
          f"{runs_for(P_SHOWN)} runs show P ≥ {fmt(P_SHOWN)}.\n\n"
          + (md_table(["claim", "runs passing", "share", "Wilson 95 %",
                       "success-run lower bound"], rates, "lrrrr") if rates
             else "_No claim on a scenario metric._")
          + "\n\n" + "\n\n".join(parts))
    return md, figs


def _plot_mc(fig, m, claimed, units):
    for k, c in enumerate(claimed):
        ax = fig.add_subplot(len(claimed), 1, k + 1)
        v = m.metrics[c.metric]
        v = v[~np.isnan(v)]
        ax.hist(v, bins=30, color="C0")
        cl = c.claim
        lines = ([cl.value - cl.tolerance, cl.value + cl.tolerance] if cl.compare == "within"
                 else [cl.value + cl.tolerance] if cl.compare == "<="
                 else [cl.value - cl.tolerance] if cl.compare == ">=" else [cl.value])
        for x in lines:
            ax.axvline(x, color="k", ls="--", lw=0.8)
        ax.set_xlabel(f"{c.metric} ({units[c.metric]}) — claim {cl.id}", fontsize=7)
        ax.set_ylabel("runs", fontsize=7)
