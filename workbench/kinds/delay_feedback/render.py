"""Markdown and figures of a ``delay-feedback`` design (pure rendering).

Shares the printed forms of the antiskid-cruise report (exact margins, capped
bounds, closed-loop eigenvalues, re-check decades) through
:mod:`workbench.report.synthesis_text`.
"""
from __future__ import annotations

import math

import numpy as np

from ...printed_grid import printed_digits
from ...report.display_math import display_math
from ...report.markdown import (Figure, Rendered, fmt, fmt_floor, latex_matrix, md_table,
                               noise_cell, noise_peak)
from ...report.synthesis_text import (capped_text, closed_loop_eigs_text, exact_margin_text,
                                      recheck_table)
from .requirements_render import gain_text, requirements_section, varying_section

_METHOD = {
    "free-weighting-003": "paper 003's free-weighting problem (60) (Theorem 1 + Remark 3), "
                          "swept over eps; certificate for every constant delay in [0, h]",
    "wirtinger": "Wirtinger-based synthesis (Seuret & Gouaisbaut 2013, Theorem 5, with "
                 "Fridman's descriptor slack), eps searched; certificate at the delay h",
    "bessel-legendre": "Wirtinger-based synthesis with the gain certified by the "
                       "Bessel-Legendre analysis of order N (Seuret & Gouaisbaut 2015); "
                       "certificates at the delay h",
    "requirements": "design to requirements (`workbench/lmi/requirements.py`): the "
                    "exponentially weighted descriptor/Jensen synthesis LMI, one gain for the "
                    "operating point and every vertex, eps searched; the certificate holds for "
                    "every constant delay in [0, h]. h below: the largest cap the rounded gain "
                    "certifies at the required decay rate, gain and input limit",
    "robust-descriptor": "one gain for every polytope vertex: Jensen/descriptor synthesis with "
                         "common Y, V (`workbench/lmi/robust.py`), eps searched; with decay "
                         "rate 0 the certificate holds for every constant delay in [0, h] at "
                         "every vertex, with a decay rate alpha > 0 it proves exponential "
                         "stability with rate alpha at the delay h at every vertex. The LMI is "
                         "affine in (A, B) with Y, V common, so it also holds at every convex "
                         "combination of the vertex matrices (linearisations at parameters "
                         "between vertices are not checked separately)",
}


def model_latex(spec) -> list[str]:
    """LaTeX lines of the definitions and equations, as written (definitions
    kept as named symbols)."""
    import sympy as sp

    from ...expr import parse_expression
    p = spec.plant
    sym = {n: sp.Symbol(n) for n in p.state_names + p.input_names + tuple(p.parameters)}
    tex = {n: sp.Symbol(_tex_name(n)) for n in sym}
    out = []
    for name, text in p.definitions:
        e = parse_expression(text, sym, path=p.path, key=f"definitions.{name}")
        out.append(f"{_tex_name(name)} = " + sp.latex(e.subs(_pairs(sym, tex))))
        sym[name] = sp.Symbol(name)
        tex[name] = sp.Symbol(_tex_name(name))
    for s, text in zip(p.state_names, p.equations):
        e = parse_expression(text, sym, path=p.path, key=f"equations.{s}")
        out.append(rf"\dot{{{_tex_name(s)}}} = " + sp.latex(e.subs(_pairs(sym, tex))))
    return out


def _pairs(sym, tex):
    return {sym[k]: tex[k] for k in sym}


_GREEK = {"lam": r"\lambda", "lambda_": r"\lambda", "mu": r"\mu", "zeta": r"\zeta",
          "tau": r"\tau", "omega": r"\omega", "theta": r"\theta", "eta": r"\eta",
          "alpha": r"\alpha", "beta": r"\beta", "gamma": r"\gamma", "delta": r"\delta",
          "kappa": r"\kappa", "sigma": r"\sigma", "phi": r"\phi", "rho": r"\rho"}


def _tex_name(n: str) -> str:
    head, _, sub = n.partition("_")
    head = _GREEK.get(head, head)
    return f"{head}_{{{sub.replace('_', ',')}}}" if sub else head


def render(design, res) -> Rendered:
    spec, p = design.spec, design.spec.plant
    s, st = res.synthesis, spec.synthesis.settings
    sections = []
    vfigs = []
    if s.requirements is not None:
        sections.append(requirements_section(spec, s.requirements))
        vsec, vfigs = varying_section(spec, s.requirements)
    var = [[f"`{v.name}`", "state", v.unit, v.description, v.source] for v in p.states]
    var += [[f"`{v.name}`", "input", v.unit, v.description, v.source] for v in p.inputs]
    par = [[f"`{k}`", fmt(q.value, 6), q.unit, q.source] for k, q in p.parameters.items()]
    d = spec.delay
    delay = (f"constant h = {fmt(d.h_max)} s" if d.constant
             else f"any constant delay in [{fmt(d.h_min)}, {fmt(d.h_max)}] s")
    sections.append(
        "## Problem\n\nA `delay-feedback` design: the plant below is the text of the design "
        "file, parsed safely (`workbench/expr.py`: Python's `ast` against a whitelist, never "
        "evaluated) into one sympy model, from which every Jacobian and numeric function "
        f"is derived. Input delay: {delay} ({d.source}).\n\n"
        + md_table(["name", "role", "unit", "meaning", "source"], var, "lllll")
        + "\n\n" + md_table(["parameter", "value", "unit", "source"], par, "lrll"))
    sections.append("## Model\n\n" + display_math(model_latex(spec))
                    + "\n\nThe input acts with the delay: u = u(t − h) in the equations.")
    # -- operating point and linearisation ----------------------------------------------
    vals = res.op.as_dict(p)
    ent = {e.name: e for e in p.operating_point}
    op = [[f"`{k}`", fmt(v, 6), "solved from f = 0 in "
           f"[{fmt(ent[k].lo)}, {fmt(ent[k].hi)}]" if ent[k].solved else "given",
           ent[k].source] for k, v in vals.items()]
    ev = np.linalg.eigvals(res.A)
    sections.append(
        "## Operating point and linearisation\n\n"
        + md_table(["name", "value", "how", "source"], op, "lrll")
        + f"\n\nResidual max |f| at the point: {_residual(res.op.residual)}."
        + ("" if p.trim else " The design sets `trim = false`: the model is linearised at "
           "this point although it is not an equilibrium.") + "\n\n"
        "Jacobians at the point (`control.StateSpace(A, B, I, 0)` is the linear model "
        "δx' = A δx + B δu(t − h)):\n\n"
        f"$$\nA = {latex_matrix(res.A, 5)}, \\qquad B = {latex_matrix(res.B, 5)}\n$$\n\n"
        f"Eigenvalues of A (1/s): {_eigs(ev)}.")
    sections.append(_synthesis_section(spec, res))
    sections.append(_exact_section(spec, res))
    from .gain_tables import gain_tables_sections
    gsec, gfigs, anchors = gain_tables_sections(spec, res)
    sections += gsec
    figs = list(gfigs)
    if res.scenarios:
        sec, sfigs = _simulation_section(spec, res)
        figs += sfigs
        sections.append(sec)
        if spec.convergence:
            sections.append(_convergence_section(res))
    if vfigs:
        sections.append(vsec)
        figs = [*figs, *vfigs]
    if res.basin is not None:
        from ...features.basin_render import render_basin_section
        sec, bfigs = render_basin_section(spec, res, res.basin)
        sections.append(sec)
        figs = [*figs, *bfigs]
    if res.implementation is not None:
        from ...features.sampled import render_implementation_section
        sec, ifigs = render_implementation_section(spec, res.implementation)
        sections.append(sec)
        figs = [*figs, *ifigs]
    if spec.montecarlo is not None:
        from .montecarlo import montecarlo_section
        sections.append(montecarlo_section(spec, res))
    return Rendered(tuple(sections), tuple(figs), anchors)


def _residual(r: float) -> str:
    return "0 (below 1e-12)" if r < 1e-12 else fmt(r, 2)


def _eigs(ev) -> str:
    ev = sorted(ev, key=lambda z: (z.real, z.imag))
    return ", ".join(fmt(complex(e).real, 4) if abs(complex(e).imag) < 1e-9
                     else f"{fmt(complex(e).real, 4)} ± {fmt(abs(complex(e).imag), 4)}j"
                     for e in ev if complex(e).imag >= -1e-9)


def _synthesis_section(spec, res) -> str:
    s, st, syn = res.synthesis, spec.synthesis.settings, spec.synthesis
    head = f"## Certified delay bound\n\nMethod: {_METHOD[s.method]}.\n\n"
    if s.method == "robust-descriptor":
        head += f"Decay rate alpha = {fmt(syn.decay_rate)} 1/s.\n\n"
    cap = st.h_max
    if s.method == "free-weighting-003":
        rows = [[fmt(r.eps), fmt(r.h_certified, 5), fmt(r.h_refuted, 5),
                 gain_text(None if r.K is None else np.array(r.K).reshape(res.B.shape[1], -1),
                           st.gain_digits), fmt(r.h_gain, 4), exact_margin_text(r.exact),
                 r.status.value] for r in s.rows]
        table = md_table(["eps", "h_certified (s)", "h_refuted (s)", "K (canonical)",
                          "h certified by K (s)", "exact margin h* (s)", "status"], rows,
                         "rrrlrrl")
        table += (f"\n\nThe gain used below is the row with the largest bound (eps = "
                  f"{fmt(s.eps)}).\n\n" + recheck_table(res.synthesis))
    else:
        table = md_table(
            ["eps (searched)", "h_certified (s)", "h_refuted (s)", "K (canonical)",
             "h certified by K (s)",
             f"h, Bessel-Legendre N = {syn.order} with K (s, 2 digits, rounded down)",
             "status"],
            [[fmt(s.eps, 3), capped_text(s.h_certified, cap), fmt(s.h_refuted, 4),
              gain_text(s.K, st.gain_digits), capped_text(s.h_gain, cap),
              _floor2(s.h_analysis, cap), s.status]], "rrrlrrl")
        if s.robust is not None:
            vt = [[v.name, ", ".join(f"{k} = {fmt(x, 6)}" for k, x in v.values.items()),
                   "yes" if c.stable_at_zero else "**no**", exact_margin_text(c.exact),
                   _floor2(c.h_certified, cap), fmt(ab, 3), v.source]
                  for v, c, ab in res.vertex_checks]
            table += ("\n\nThe gain at every vertex (exact margin, Bessel-Legendre order "
                      f"{syn.order} analysis bound and the spectral abscissa at the delay the "
                      "gain certifies, each independent of the synthesis LMI; the abscissa must "
                      f"be ≤ −alpha = −{fmt(syn.decay_rate)} 1/s):\n\n"
                      + md_table(["vertex", "parameters", "A + BK Hurwitz",
                                  "exact margin h* (s)",
                                  "BL bound with K (s, 2 digits, rounded down)",
                                  "spectral abscissa at h certified by K (1/s)", "source"], vt,
                                 "llllrrl"))
    notes = (f"\n\n*h_certified*: the largest delay at which the LMI was solved to optimality "
             f"**and** every block passed an independent numpy re-check with relative margin "
             f"{fmt(st.margin)}; *h_refuted*: the smallest delay the solver proved infeasible. "
             f"*K (canonical)*: the minimum-norm certificate at {fmt(st.gain_fraction)} × "
             f"h_certified, rounded to {st.gain_digits} significant digits and certified on its "
             f"own with K fixed (*h certified by K*). A bound shown as ≥ cap is the search "
             f"cap h_max = {fmt(cap)} s, a lower bound only. Control law: "
             "u = u_op + K (x − x_ref).")
    eig = closed_loop_eigs_text(res.A, res.B, s.K)
    return head + table + notes + f"\n\nEigenvalues of A + BK (1/s): {eig}."


def _exact_section(spec, res) -> str:
    s, d = res.synthesis, spec.delay
    if res.exact is None:
        return "## Exact delay margin\n\nNo gain was certified: nothing to check."
    w = ", ".join(f"({fmt(a, 5)}, {fmt(b, 5)})" for a, b in res.windows) or "none"
    rng = f"[{fmt(d.h_min)}, {fmt(d.h_max)}] s" if not d.constant else f"h = {fmt(d.h_max)} s"
    from .quantities import covers
    cov = {"yes": f"**yes**: the certificate holds for every constant delay in [0, "
                  f"{fmt(s.h_gain, 4)}] s ⊇ {rng}",
           "at-h-only": f"**at h only**: the certificate reaches {fmt(s.h_gain, 4)} s but is "
                        "a certificate at that single delay; the exact windows settle the range",
           "no": "**no**: the certified bound does not reach the design's largest delay"
           }[covers(res)]
    stable = ("**yes**" if res.range_stable else "**no**")
    return ("## Exact delay margin and stability windows\n\n"
            + md_table(["quantity", "value"], [
                ["exact margin h* of x' = A x + BK x(t − h) (s)", exact_margin_text(res.exact)],
                ["second method", f"{res.exact.outcome.value}"],
                [f"exact stability windows up to {fmt(spec.window_horizon)} s", w],
                [f"every delay in {rng} stable (exact)", stable],
                ["LMI certificate covers the delay range", cov]], "ll")
            + "\n\nThe exact margin and windows (`workbench/margins`: phase sweep, "
              "cross-checked by Chen-Gu-Nett) are independent of the LMIs; the certificate "
              "is the sound claim, the exact set says how conservative it is.")


def _metric_cell(metrics: dict, key: str) -> str:
    """``metrics[key]`` to 4 digits (5 on a rounding tie,
    :func:`~workbench.printed_grid.printed_digits`), or "< 1e-9 × peak" when a final/min error is
    below :data:`~workbench.report.markdown.NOISE_FLOOR` times the same state's
    peak error (:func:`~workbench.report.markdown.noise_cell`)."""
    v = metrics[key]
    return noise_cell(v, noise_peak(key, metrics), printed_digits(v, 4))


def _simulation_section(spec, res):
    p = spec.plant
    rows, figs, parts = [], [], []
    for r in res.scenarios:
        sc = r.scenario
        for k, v in r.metrics.items():
            rows.append([sc.name, k, _metric_cell(r.metrics_coarse, k),
                         _metric_cell(r.metrics, k)])
        parts.append(f"`{sc.name}`: " + ("**with the predictor** (paper 003, Lemma 1), "
                                          if sc.predictor else "")
                     + f"h = {fmt(sc.h)} s, dt = {fmt(sc.dt)} s and "
                     f"{fmt(sc.dt / 2)} s, metrics agree to rtol {fmt(sc.rtol)}: "
                     f"**{'yes' if r.converged else 'no'}**")
        figs.append(Figure(f"sim-{sc.name}", f"Scenario {sc.name} (h = {fmt(sc.h)} s, "
                           f"dt = {fmt(r.run.dt)} s)",
                           lambda fig, r=r: _plot_run(fig, r, p),
                           (6.4, 4.0 + 1.2 * len(sc.plot) + (0.8 if sc.lines else 0.0))))
    md = ("## Nonlinear closed loop with the input delay\n\nThe plant equations above "
          "(not the linearisation), u = u_op + K (x − x_ref(t)) applied after the delay h "
          "(exact ZOH averages of the delayed input, `workbench/sim/delay.py`), classical "
          "Runge-Kutta 4 per step; every scenario runs at dt and dt/2. A scenario with the "
          "predictor applies u = u_op + K (x̂(t + h) − x_ref(t + h)), x̂ the state predicted "
          "by integrating the same model over the inputs already sent (paper 003, Lemma 1).\n\n"
          + "\n\n".join(parts) + "\n\n"
          + md_table(["scenario", "metric", "at dt", "at dt/2 (reported)"], rows, "llrr")
          + "\n\n" + "\n\n".join(f"![{f.caption}]({{figdir}}/{f.name}.png)" for f in figs))
    return md, figs


def _convergence_section(res) -> str:
    """``[convergence]``: every claimed scenario metric at dt, dt/2, dt/4."""
    from ...features.convergence import claim_table
    from ...sim.convergence import P_MAX, P_MIN
    rows = [[f"`{x.quantity}`", *(fmt(v, 5) for v in x.values),
             "—" if x.check is None or x.check.order is None or not math.isfinite(
                 x.check.order) else fmt(x.check.order, 2)] for x in res.refinement]
    return ("## Convergence\n\n`[convergence]`: every scenario also at dt/4 (the delay "
            "unchanged), and every claim on a scenario metric refined over dt, dt/2, dt/4 "
            "(the claim compares the dt/2 value). Observed order p = log2(|q1 − q2| / "
            "|q2 − q4|) and Richardson's estimate of the error left in q4 "
            f"(`workbench/sim/convergence.py`: p clipped to [{fmt(P_MIN)}, {fmt(P_MAX)}]; "
            "differences at rounding level count as converged); the tolerance is the claim's "
            "for `within`, the distance from the value to the bound for `<=`/`>=` "
            "(`workbench/features/refinement.py`). A claim whose metric has not converged is "
            "INCONCLUSIVE with this reason.\n\n"
            + (md_table(["quantity", "q1 (dt)", "q2 (dt/2)", "q4 (dt/4)", "p"], rows, "lrrrr")
               + "\n\n" if rows else "")
            + claim_table(res.refinement))


def _plot_run(fig, r, p):
    run, sc = r.run, r.scenario
    lines = sc.lines or {}
    n = len(p.states) + len(sc.plot) + len(p.inputs)
    from .run import input_history
    U = input_history(run, len(p.inputs))
    step = max(1, run.t.size // 2000)
    t = run.t[::step]
    panels = [(v.name, f"{v.name} ({v.unit})", run.x[i, ::step], "C0")
              for i, v in enumerate(p.states)]
    if sc.plot:                          # definitions of the plant (e.g. the creep ratio)
        from .model import PlantModel
        model = PlantModel(p)
        X, Us = run.x[:, ::step], U[:, ::step]
        panels += [(d, d, model.definition_function(d, p.values())(X, Us), "C2")
                   for d in sc.plot]
    panels += [(v.name, f"{v.name} ({v.unit})", U[j, ::step], "C1")
               for j, v in enumerate(p.inputs)]
    for k, (name, label, y, colour) in enumerate(panels):
        ax = fig.add_subplot(n, 1, k + 1)
        ax.plot(t, y, color=colour)
        if name in lines:
            value, text = lines[name]
            ax.axhline(value, color="k", ls="--", lw=0.8, label=text)
            ax.margins(y=0.4)
            ax.legend(loc="best", fontsize=7, framealpha=0.9)
        ax.set_ylabel(label)
    ax.set_xlabel("t (s)")
    fig.suptitle(f"{sc.name}: h = {sc.h:g} s, dt = {run.dt:g} s")


def _floor2(h, cap) -> str:
    """An analysis bound of a given gain, rounded down to 2 significant digits:
    near a degenerate optimum its third digit depends on the CPU's BLAS
    kernels (0.1966 / 0.1958 s under Haswell / Sandybridge on the heavy wet
    vertex), and a lower bound may only be rounded down."""
    import math
    if h is None or not math.isfinite(h) or h >= cap or h <= 0:
        return capped_text(h, cap)
    return fmt_floor(h, 2)
