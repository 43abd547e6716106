"""Markdown and figures of a ``platoon`` design (pure rendering).

A paper's ``[analysis]`` module may replace the parts only it can word (its
law's equations, its comparison, its margin discussion): the hooks of
:data:`HOOKS`, each ``f(spec, res) -> str`` or a fixed ``str``; without one,
the general text.
"""
from __future__ import annotations

import numpy as np

from ...features.reproducible import window
from ...report.markdown import Figure, Rendered, fmt, md_table
from ...report.param_table import param_table
from . import realism_render as realism

__all__ = ["HOOKS", "render"]

#: Hooks an ``[analysis]`` module may provide (attribute name -> what it writes).
HOOKS = {"problem_note": "the design's choices (end of the problem section)",
         "law_section": "the control-law section",
         "chatter_note": "the note under the results table on a chattering run",
         "comparison": "a section after the results",
         "reaching_text": "(intro, outro) of the reaching section",
         "realism_preface": "the first sentence of the realistic scenario",
         "bound_note": "who assumes the lumped disturbance stays below G_w + G_d",
         "margin_section": "the delay-margin section"}
WORDS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six"}


def _hook(spec, name: str, res, default):
    f = getattr(spec.analysis, name, None) if spec.analysis is not None else None
    return default() if f is None else f if isinstance(f, str) else f(spec, res)

DOC = {"m": "mass", "c0": "Davis, constant", "c1": "Davis, linear", "c2": "Davis, quadratic",
       "g": "gravity"}


def _constants_note(spec, res) -> str:
    return ("**Design choices**: true trains differ "
            + spread(spec) + " Constants: " + ", ".join(
                f"{k} = {fmt(q.value, 4)} {q.unit}" for k, q in spec.constants.items()) + ".")


def spread(spec) -> str:
    return (f"from the nominal one by U(±{fmt(spec.mass_spread * 100)} %) in mass and "
            f"U(±{fmt(spec.davis_spread * 100)} %) in each Davis coefficient, and feel an external "
            f"force w(t), piecewise linear between uniform random knots every {fmt(spec.hold)} s, "
            f"|w| ≤ G_w = {fmt(spec.G_w)} N; G_d = {fmt(spec.G_d)} N; seed {spec.seed}.")


def _law_section(spec, res) -> str:
    rows = [[f"`{x.name}`", x.label, "; ".join(f"`{k} = {t}`" for k, t in x.definitions)
             or "—", f"`{x.law}`"] for x in spec.laws]
    return ("## Control laws\n\nThe followers' laws as the design writes them (force, N): "
            "e = x_{i−1} − x_i − D (m), de = ė (m/s), a_pred the predecessor's acceleration "
            "of the previous step (as communicated), u1 the nominal resistance and gradient "
            "force, m the nominal mass.\n\n"
            + md_table(["law", "label", "definitions", "force u (N)"], rows, "llll"))


def _reaching_text(spec, res) -> tuple[str, str]:
    rc = spec.reaching
    run = spec.run_spec(rc.run)
    return ((f"Run '{run.label}' started with spacing errors "
             f"{', '.join(fmt(x) for x in run.initial_errors)} m (trains at rest). "
             f"t_e: first |s| ≤ {fmt(rc.reach_band)} m. The design's sliding time "
             f"({rc.prediction}) to e = 0, and to the band |e| = {fmt(rc.converge_band)} m; "
             "measured: from t_e until |e| stays inside the band."), "")


def render(design, res) -> Rendered:
    spec = design.spec
    labels = {r.name: r.label for r in spec.runs}
    sec = []
    sec.append(
        "## Problem\n\n"
        f"{spec.n} trains, leader-follower, spacing D = {fmt(spec.D.value)} m"
        + (f" plus a time headway of {fmt(spec.headway)} s (desired gap D + h v_i; e_i = gap − "
           f"D − h v_i)" if spec.headway else "") + ", step "
        f"T = {fmt(spec.T)} s (zero-order hold, the same step integrates the trains), "
        f"{fmt(spec.horizon)} s. The leader accelerates ({fmt(spec.accel)} m/s², jerk "
        f"{fmt(spec.jerk)} m/s³), cruises at {fmt(res.profile.v_cruise * 3.6, 3)} km/h for "
        f"{fmt(spec.cruise_time)} s and brakes ({fmt(spec.brake)} m/s²) to the next station "
        f"({fmt(res.profile.spec.distance, 4)} m), tracking that profile with a speed loop of "
        f"gain {fmt(spec.leader_gain)} 1/s. Gradients "
        f"{', '.join(fmt(x * 1000) for x in spec.route.grade)} ‰ "
        f"from {', '.join(fmt(x) for x in spec.route.grade_from)} m (ours).\n\n"
        + param_table(spec.plant, DOC, 4)
        + "\n\n" + _hook(spec, "problem_note", res, lambda: _constants_note(spec, res)))
    sec.append(_hook(spec, "law_section", res, lambda: _law_section(spec, res)))
    rows = []
    for name, label in labels.items():
        m = res.metrics[name]
        rows.append([label, " / ".join(fmt(x, 3) for x in m.max_abs_e),
                     " / ".join(fmt(x, 3) for x in m.cruise_abs_e),
                     " / ".join(fmt(x, 3) for x in m.cruise_abs_de),
                     fmt(m.string_ratio, 3), " / ".join(fmt(x, 3) for x in m.chatter),
                     " / ".join(fmt(x, 3) for x in m.sign_rate), fmt(m.lumped_ratio, 3),
                     fmt(max(m.max_speed) * 3.6, 4)])
    w0, w1 = res.cruise_window
    chatter = [r for r in spec.runs if r.chatters and r.name in spec.figures]
    sec.append(
        "## Results\n\nPer follower (trains "
        + " / ".join(str(i) for i in range(2, spec.n + 1)) + "). Cruise window "
        f"{fmt(w0, 4)}–{fmt(w1, 4)} s (10 s after the leader's acceleration ends until it "
        "brakes).\n\n"
        + md_table(["run", "max |e| (m)", "cruise max |e| (m)", "cruise max |ė| (m/s)",
                    "string ratio max ‖e_{i+1}‖∞/‖e_i‖∞", "chatter (1/t)Σ|Δu|/m (m/s³)",
                    "sign flips of s (Hz)", "max |w+d| / (G_w+G_d)", "max speed (km/h)"],
                   rows, "lrrrrrrrr")
        + "\n\n*Chatter* is the total variation of the commanded acceleration per second; "
        f"*sign flips* count changes of sign(s) per second in the cruise window (at most "
        f"{fmt(1 / spec.T)} Hz). *max |w+d|* is the lumped disturbance as the controller sees "
        "it, m·v' − (u − u1), while moving: "
        + _hook(spec, "bound_note", res, lambda: "the design assumes it stays below G_w + G_d")
        + "".join(f"; in the run '{labels[k]}' it exceeds the bound, most at t = "
                  f"{fmt(m.lumped_peak_time, 3)} s" for k, m in res.metrics.items()
                  if m.lumped_ratio > 1.0)
        + ". The string ratio compares whole-run maxima, so it means something only for "
        "runs started at exact spacing.\n\n"
        "![platoon speeds]({figdir}/platoon-speeds.png)\n\n"
        + (_hook(spec, "chatter_note", res, lambda: "".join(
            f"The spacing error of the run '{r.label}' is drawn as its worst |e| per follower, "
            "not as a trace: it chatters, and its last digits are not reproducible.\n\n"
            for r in chatter)) if chatter else "")
        + "![spacing errors]({figdir}/spacing-errors.png)")
    extra = _hook(spec, "comparison", res, lambda: "")
    if extra:
        sec.append(extra)
    if spec.reaching is not None:
        rc = spec.reaching
        crow = []
        for i, c in enumerate(res.convergence):
            crow.append([f"train {i + 2}", fmt(c.e0), fmt(c.t_reach, 3), fmt(c.e_reach, 3),
                         fmt(c.slide_eq22, 3), fmt(c.slide_band, 3), fmt(c.slide_measured, 3),
                         fmt(None if c.slide_measured is None or not c.slide_band
                             else c.slide_measured / c.slide_band, 3)])
        intro, outro = _hook(spec, "reaching_text", res, lambda: _reaching_text(spec, res))
        sec.append(
            f"## Reaching and convergence times ({rc.prediction})\n\n" + intro + "\n\n"
            + md_table(["follower", "e(0) (m)", "t_e (s)", "e(t_e) (m)",
                        f"{rc.prediction}: t_f − t_e (s)", "to band (s)", "measured (s)",
                        "measured / to band"], crow, "lrrrrrrr")
            + "\n\n" + (outro + "\n\n" if outro else "")
            + "![convergence]({figdir}/convergence.png)")
    rz = res.realism
    sec.append(realism.scenario_section(spec, rz, _hook(spec, "realism_preface", res,
                                                        lambda: ""))
               + "\n\n" + realism.gap_section(spec, rz))
    if rz.margin is not None:
        sec.append(_hook(spec, "margin_section", res, lambda: realism.margin_section(spec, rz)))
    figs = (Figure("platoon-speeds", spec.captions["speeds"],
                   lambda fig: _plot_speeds(fig, res), (7.0, 5.0)),
            Figure("spacing-errors", spec.captions["errors"],
                   lambda fig: _plot_errors(fig, res), (7.0, 5.0)))
    if spec.reaching is not None:
        figs += (Figure("convergence", spec.captions["reaching"],
                        lambda fig: _plot_convergence(fig, res), (7.0, 5.0)),)
    return Rendered(tuple(sec), figs + realism.figures(spec, rz))


def _plot_speeds(fig, res):
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for ax, name in zip((ax1, ax2), res.spec.figures):
        r = res.runs[name]
        for i in range(r.v.shape[1]):
            ax.plot(r.t, r.v[:, i] * 3.6, lw=1, label=f"train {i + 1}")
        ax.set_ylabel("speed (km/h)")
        ax.set_title(res.spec.run_spec(name).label, fontsize=9)
    ax1.legend(fontsize=7)
    ax2.set_xlabel("time (s)")


def _plot_errors(fig, res):
    """Spacing errors of the two runs of ``[figures]``. A run that chatters at
    the sampling rate (``chatters = true``: its sub-millimetre trace moves by
    about 1 % under a 3-ulp change of the inputs, the last-bit perturbation
    test) is drawn as its reproducible worst |e| per follower (dashed, +-)."""
    axes = fig.subplots(2, 1, sharex=True)
    for ax, name in zip(axes, res.spec.figures):
        r, rs = res.runs[name], res.spec.run_spec(name)
        if rs.chatters:
            for i, m in enumerate(res.metrics[name].max_abs_e):
                for sign in (1.0, -1.0):
                    ax.plot([r.t[0], r.t[-1]], [sign * m * 1000.0] * 2, lw=0.8, ls="--",
                            color=f"C{i}", label=f"max |e{i + 2}|" if sign > 0 else None)
            ax.text(0.5, 0.5, "trace not drawn: it chatters, and its last digits are not "
                    "reproducible", transform=ax.transAxes, ha="center", va="center",
                    fontsize=7)
            ax.set_ylabel("spacing error (mm)")
            ax.set_title(rs.label + ": worst |e| per follower", fontsize=9)
        else:
            for i in range(r.e.shape[1]):
                ax.plot(r.t, r.e[:, i], lw=0.6, label=f"e{i + 2}")
            ax.set_ylabel("spacing error (m)")
            ax.set_title(rs.label, fontsize=9)
    axes[0].legend(fontsize=7)
    axes[1].set_xlabel("time (s)")


def _plot_convergence(fig, res):
    r = res.runs[res.spec.reaching.run]
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    keep = window(r.t, -np.inf, 30.0)   # 30 s is a sample time
    for i in range(r.e.shape[1]):
        ax1.plot(r.t[keep], r.e[keep, i], lw=1, label=f"e{i + 2}")
        ax2.plot(r.t[keep], r.s[keep, i], lw=1, label=f"s{i + 2}")
        c = res.convergence[i]
        if c.t_reach is not None:
            ax1.axvline(c.t_reach + c.slide_eq22, color=f"C{i}", ls=":", lw=1)
    ax1.set_ylabel("e (m)")
    ax1.set_title(f"dotted: t_e + {res.spec.reaching.prediction}", fontsize=9)
    ax1.legend(fontsize=7)
    ax2.set_ylabel("s (m)")
    ax2.set_xlabel("time (s)")
    ax2.set_yscale("symlog", linthresh=1e-3)
