"""Markdown and figures of paper 000's station stops (designs/stopping-line5.toml,
``[analysis] module = "p000.station_stopping"``): pure rendering of a
:class:`~workbench.papers.p000.station_stopping_run.StopResult`, in the paper's wording."""
from __future__ import annotations

import numpy as np
import sympy as sp

from ...kinds.stop_accuracy.error_samples import (plot_abs_ecdf, plot_grouped_boxes, ride_table,
                                                  section_table, within_rows)
from ...kinds.stop_accuracy.render import quantity_table, ranges_table, sections_table
from ...kinds.stop_accuracy.run import controller_index
from ...kinds.stop_accuracy.trace_figures import plot_tracked_stops
from ...plants.brake000 import brake_model
from ...report.display_math import display_math
from ...report.markdown import Figure, Rendered, fmt, md_table
from .station_stopping_fair_render import fair_section, figures
from .station_stopping_spec import CONTROLLERS, VARIANTS, gains, label


#: Stop window of the accuracy table and figure (m): the usual platform-screen-door tolerance.
STOP_WINDOW_M = 0.3


def model_section() -> str:
    """The brake model of paper 000 rendered from the sympy source."""
    m = brake_model()
    lat = sp.latex
    eqs = [r"\dot x = v,\quad \dot v = " + lat(m.rhs[0]) + r"\qquad\text{(eqs 5, 10)}",
           r"\dot b_e = " + lat(m.rhs[1]) + r",\quad e_{in}(t) = \min(c(t - T_1),\ \mathrm{cap}(t))"
           r"\qquad\text{(eq 2)}",
           r"\dot b_a = " + lat(m.rhs[2]) + r",\quad d_{air}(t) = c(t - T_3) - \min(c(t-T_3),"
           r"\ \mathrm{cap}(t))\qquad\text{(eqs 7, 9)}",
           r"a_{res} = " + lat(m.a_res) + r"\qquad\text{(eqs 3-4; } v \text{ in m/s)}"]
    return ("## Brake model (paper 000, eqs 1-10)\n\nRendered from `workbench/plants/brake000.py` "
            "(sympy, the single source of the numeric model). Decelerations are positive, SI "
            "units; c is the brake command (demanded deceleration, m/s²), kappa the "
            "load-weighing gain (estimated / true mass), theta the gradient (‰). cap(t) is "
            "infinite above the hand-over speed v_ho and then falls at k_bra (eq 8). Unit "
            "slips resolved: eq 3 and eq 7 use V in km/h (the paper writes cm/s); K1/K2 "
            "(Table 1: 85.16) is read as the air-brake deceleration in cm/s² of a full 1 m/s² "
            "demand at standstill, hence the division by 100; only the ratio K1/K2 enters.\n\n"
            + display_math(eqs))


def render(design, res) -> Rendered:
    spec = design.spec
    # c, k_s, eta, phi, lam, theta_min, theta_max of the SMARC row (eqs 22, 26-27)
    g = spec.controllers[controller_index(spec, VARIANTS["smarc"][0])].smarc.values(spec.constants)
    pid, ref, rp = gains(spec, "pid"), spec.reference, spec.sections
    sections = [
        "## Problem\n\nStation stops of paper 000 (section 3.2) on the seven Beijing Line 5 "
        "sections of Table 3, **synthetic**: the ATO logs are not public. Each run starts "
        f"where the target curve (v_max {fmt(ref.v_max, 4)} m/s, braking at "
        f"{fmt(ref.a_dec, 3)} m/s²) begins to brake and tracks it to the stopping point. "
        f"{rp.count} repeats per section (seed {rp.seed}); the three controllers meet the "
        "same uncertain plants.\n\n"
        + quantity_table("parameter", spec.params, 5)
        + "\n\nUncertainty (uniform, per repeat):\n\n"
        + ranges_table(spec)
        + "\n\n" + sections_table(spec, res.planned_time)
        + "\n\nEvery section reaches v_max before braking, so the public data (lengths) do not "
        "distinguish the sections' braking phases: they differ here only by their random "
        "draws. Controllers: PID on the speed error with the target deceleration as "
        f"feed-forward (kp {fmt(pid['kp'])}, ki {fmt(pid['ki'])}, kd "
        f"{fmt(pid['kd'])}); SMC = eq 22 with the fixed estimate theta = 1; SMARC = eq 22 "
        f"with eqs 26-27 (c {fmt(g['c'])} 1/s, k_s {fmt(g['k_s'])} 1/s, eta {fmt(g['eta'])} m/s², "
        f"boundary layer phi {fmt(g['phi'])} m/s, lambda {fmt(g['lam'])}, theta in "
        f"[{fmt(g['theta_min'])}, {fmt(g['theta_max'])}]); SMARC (sgn) = "
        "the same with the discontinuous sgn(z) of eq 22 as printed (phi = 0); sampled every "
        f"{fmt(spec.dt_ctrl)} s, plant stepped at {fmt(spec.dt)} s.",
        model_section(),
    ]
    cells = [(label(c), [res.stats[c, i] for i in range(len(res.sections))])
             for c in CONTROLLERS]
    series = [(lab, [e for c in cs for e in c.errors]) for lab, cs in cells]   # all errors, cm
    sections.append(
        "## Stop accuracy (cf. Tables 3-4)\n\nStop error = stop position − stopping point "
        "(cm, + = overshoot), per section over the repeats: mean |error|, signed mean, "
        "variance (cm²).\n\n" + section_table(cells)
        + "\n\nRide quality and time (braking phase, up to standstill):\n\n"
        + ride_table(cells, np.mean(res.planned_time))
        + f"\n\nThe command rate measures chattering of the brake command. With the robust "
        f"gain eta = {fmt(g['eta'])} m/s² the switching term of eq 22 is small beside k_s z, so "
        "the boundary layer changes little here (compare the two SMARC rows); the brake's "
        "delays and lags filter the rest before it reaches the jerk."
        + "\n\nShare of stops beyond the stopping point (overshoots): " + ", ".join(
            f"{lab} {fmt(100 * float(np.mean([e > 0 for e in es])), 3)} %" for lab, es in series)
        + ": the errors are mostly a systematic overshoot, set by the air stage's delay and lag "
        "after the hand-over, not scatter."
        + f"\n\nFinal SMARC mass estimates theta_hat span [{fmt(res.theta_hat_final[0], 3)}, "
        f"{fmt(res.theta_hat_final[1], 3)}] (per unit of the nominal mass; > 1 absorbs the "
        "brake's under-delivery, P1 and the air gain).\n\n"
        "![stop errors]({figdir}/stop-errors.png)\n\n![curves]({figdir}/stop-curves.png)"
        + "\n\n" + _within_section(series))
    sections.append(fair_section(spec, res))
    if spec.paper.published:
        prow = []
        for k, smarc, smc, pid, m4, v4, src in spec.paper.published:
            ours = [res.stats[c, k - 1].mean_abs for c in ("smarc", "smc", "pid")]
            st = res.stats["smarc", k - 1]
            prow.append([k, fmt(smarc, 3), fmt(ours[0], 3), fmt(smc, 3), fmt(ours[1], 3),
                         fmt(pid, 3), fmt(ours[2], 3), fmt(m4, 3), fmt(st.mean, 3), fmt(v4, 3),
                         fmt(st.var, 3), src])
        sections.append(
            "## Comparison with the printed Tables 3-4\n\nPrinted stop accuracy (cm, Table 3) "
            "beside our mean |stop error|, and SMARC's printed signed mean (cm) and variance "
            "(cm², Table 4) beside ours, on the synthetic stops (data for comparison, never an "
            "input).\n\n"
            + md_table(["#", "SMARC printed", "SMARC ours", "SMC printed", "SMC ours",
                        "PID printed", "PID ours", "SMARC mean printed", "ours",
                        "SMARC var printed", "ours", "source"], prow, "rrrrrrrrrrrl")
            + _consistency(spec.paper.published))
    figs = (Figure("stop-errors", "Stop-error distribution per controller and section.",
                   lambda fig: plot_grouped_boxes(
                       fig.add_subplot(111), [(lab, [c.errors for c in cs]) for lab, cs in cells],
                       xlabel="section (Table 3 order)", ylabel="stop error (cm, + overshoot)"),
                   size=(7.0, 4.0)),
            Figure("stop-curves", "Speed against distance to the stopping point, section 1.",
                   lambda fig, res=res: _plot_curves(fig, res), size=(7.0, 4.0)),
            Figure("stop-error-cdf", "Distribution of |stop error| per controller.",
                   lambda fig: plot_abs_ecdf(fig.add_subplot(111), series, 100 * STOP_WINDOW_M,
                                             window_label=f"{fmt(STOP_WINDOW_M)} m", unit="cm",
                                             linthresh=1.0), size=(7.0, 4.0))) + figures(res)
    return Rendered(tuple(sections), figs)


def _within_section(series) -> str:
    """P(|e| <= 30 cm) per ``(label, every stop error (cm))`` of ``series``,
    Wilson 95 % interval."""
    rows = within_rows(series, 100 * STOP_WINDOW_M)
    w = fmt(STOP_WINDOW_M)
    return (f"**Stops within ±{w} m** (the usual platform-screen-door tolerance), over all "
            "sections and repeats, with the Wilson 95 % interval of the proportion:\n\n"
            + md_table(["controller", f"stops within {w} m", f"P(|e| <= {w} m)", "95 % interval",
                        "95th percentile of |e| (cm)"], rows, "lrrrr")
            + "\n\n![stop error distribution]({figdir}/stop-error-cdf.png)\n\nThese are the paper "
            "rows over the repeats' uniform ranges; the Monte Carlo over continuous distributions, "
            "the nominal row and the rows with known-delay compensation follow.")


def _consistency(published) -> str:
    """Check the printed tables against |mean e| <= mean |e| (Jensen)."""
    bad = [(k, m4, smarc) for k, smarc, _, _, m4, _, _ in published
           if m4 is not None and abs(m4) > smarc]
    if not bad:
        return ""
    rows = "; ".join(f"section {k}: |{fmt(m4, 3)}| > {fmt(a, 3)}" for k, m4, a in bad)
    return ("\n\n**The printed tables are not mutually consistent** if Table 3 is the mean "
            "|stop error| of Table 4's runs: |mean e| ≤ mean |e| always, but " + rows
            + ". Table 3 must come from other runs (or be another statistic).")


def _plot_curves(fig, res):
    _, _, _, xd, vd = res.example["pid"]
    plot_tracked_stops(fig, [(label(c), *(res.example[c][j] for j in (0, 1, 2, 4)))
                             for c in CONTROLLERS], (xd, vd), title="speed error (cf. fig 8)")
