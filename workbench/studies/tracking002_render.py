"""Markdown and figures of the ``ato-tracking`` study (pure rendering)."""
from __future__ import annotations

import numpy as np

from ..controllers.mfac import MFACGains, frozen_ppd_poles
from ..plants.train002 import latex_equations
from ..report.markdown import Figure, Rendered, fmt, md_table
from .tracking002 import INDICES

LABEL = {"stop_error": "stop error K_s (m)", "punctuality": "punctuality K_t (-)",
         "comfort": "comfort K_c (m/s³)", "energy": "energy K_e (J/(kg·m))",
         "rms_speed_error": "RMS speed error (m/s)"}
DOC = {"f": "static map gain", "e": "static map offset", "delay": "pure delay T_d",
       "lag": "lag time constant T_l", "c0": "Davis, constant (per mass)",
       "c1": "Davis, linear (per mass)", "c2": "Davis, quadratic (per mass)", "g": "gravity"}

INDEX_FORMULAS = r"""$$
K_s = |s_t - s_o|, \qquad K_t = \frac{|T_t - T_o|}{T_o}, \qquad
K_c = \frac{1}{T_t}\sum_k |a(k+1) - a(k)|, \qquad
K_e = \frac{1}{S}\int_0^{T_t} \max(a_{\mathrm{applied}}, 0)\, v \, dt
$$"""

MFAC_EQS = r"""$$
\hat\phi(k) = \hat\phi(k-1) + \frac{\eta\,\Delta u(k-1)}{\mu + \Delta u(k-1)^2}
\big(\Delta y(k) - \hat\phi(k-1)\Delta u(k-1)\big) \qquad \text{(eq 9)}
$$

$$
\hat\phi(k) = \hat\phi(1) \ \text{ if } |\hat\phi(k)| \le \varepsilon \text{ or } |\Delta u(k-1)|
\le \varepsilon \text{ or } \operatorname{sign}\hat\phi(k) \ne \operatorname{sign}\hat\phi(1)
$$

$$
u(k) = u(k-1) + \frac{\rho\,\hat\phi(k)}{\lambda + \hat\phi(k)^2}\big(y^*(k+1) - y(k)\big)
\qquad \text{(eq 8)}
$$"""


def _row(comp, ctrl):
    return [ctrl] + [fmt(comp.value(ctrl, i), 3) for i in (*INDICES, "rms_speed_error")]


def render(design, res) -> Rendered:
    spec = design.spec
    m = res.main
    sec = []
    prow = [[f"`{k}`", fmt(q.value, 5), q.unit, DOC[k], q.source] for k, q in spec.train.items()]
    sec.append(
        "## Problem\n\n"
        f"Route **{m.section.name}**: {fmt(m.section.route.distance, 5)} m, planned "
        f"{fmt(m.section.run_time, 4)} s, limit {fmt(m.section.v_limit * 3.6, 3)} km/h "
        "(paper 002 §4). **Table 1 of paper 002 (train model, PID and MFAC parameters) was "
        "lost** in the extracted text: every train parameter below is our documented choice, "
        "not the paper's, and both controllers are tuned here by one rule (below).\n\n"
        + md_table(["parameter", "value", "unit", "meaning", "source"], prow, "lrlll")
        + f"\n\nCommand limits {fmt(spec.u_limits[0])} … {fmt(spec.u_limits[1])} m/s² "
        f"(the command is a demanded acceleration). Control sample Ts = {fmt(spec.Ts)} s, "
        f"plant step {fmt(spec.dt)} s (lag integrated exactly over a step, delay as a FIFO).")
    eqs = "\n\n".join(f"$$\n{e}\n$$" for e in latex_equations())
    sec.append(
        "## Model, controllers and indices\n\nTrain (rendered from `workbench/plants/train002.py`"
        "; i is the gradient):\n\n" + eqs
        + "\n\nCFDL-MFAC (standard form; the paper's formulas were lost), y = speed, "
        "u = command:\n\n" + MFAC_EQS
        + "\n\nPID: the shared sampled PID (`workbench/controllers/pid.py`) on "
        "e(k) = y\\*(k+1) − y(k), output limits with conditional integration. Both controllers "
        "see the same one-sample-ahead target.\n\nQuality indices (eqs 10-13; formulas of 11-13 "
        "lost, reconstructed as in SEEDS.md; smaller is better). s_t, T_t: position and time "
        "where the train first stands still after the profile's braking began (it is then "
        "held); s_o = S, T_o: planned stop and run time; a(k) = (v(k+1) − v(k))/Ts the net "
        "acceleration; a_applied the lag output (traction/brake per unit mass):\n\n"
        + INDEX_FORMULAS)
    prof = m.profile
    sec.append(
        "## Target profile\n\nJerk-limited accelerate-cruise-brake curve (our construction, "
        f"`workbench/profiles.py`): acceleration {fmt(spec.profile['accel'])} m/s², braking "
        f"{fmt(spec.profile['brake'])} m/s², jerk {fmt(spec.profile['jerk'])} m/s³; the cruise "
        f"speed solves T(v) = T_o: **{fmt(prof.v_cruise * 3.6, 4)} km/h** "
        "(end position error of the sampled curve "
        f"{fmt(abs(prof.s[-1] - m.section.route.distance), 2)} m).")
    g = res.mfac_gains
    gains_txt = ", ".join(f"{k} = {fmt(v, 3)}" for k, v in g.items())
    pid_txt = ", ".join(f"{k} = {fmt(v, 3)}" for k, v in res.pid_gains.items())
    sec.append(
        "## Tuning (same rule for both)\n\n"
        f"Every combination of the design's grids was simulated on {m.section.name} "
        f"({res.tuning_counts[0]} MFAC, {res.tuning_counts[1]} PID parameter sets, one batch "
        "each); the set with the smallest RMS speed error among the runs that stopped is "
        f"kept.\n\n- MFAC: {gains_txt}, ε = {fmt(spec.epsilon)}\n- PID: {pid_txt}")
    win = [["winner"] + [m.winner(i) for i in INDICES] + [""]]
    sec.append(
        "## Indices on " + m.section.name + "\n\n"
        + md_table(["controller"] + [LABEL[i] for i in (*INDICES, "rms_speed_error")],
                   [_row(m, "MFAC"), _row(m, "PID")] + win, "lrrrrr")
        + f"\n\nStop tolerance {fmt(res.stop_tolerance)} m. The MFAC estimate was reset "
        f"{res.resets} times in {len(m.mfac.t)} samples. The target is indexed by time (y*(k) "
        "of the paper), so the stop position is the integral of the whole run's speed error: "
        "nothing closes a position loop, and the stop error's ranking between the two "
        "controllers is fragile (compare the λ sweep below, where MFAC's stop error jumps "
        "by an order of magnitude between neighbouring λ).\n\n"
        "![speed tracking]({figdir}/speed-tracking.png)\n\n"
        "![acceleration and jerk]({figdir}/accel-jerk.png)")
    sec.append(_findings(res, spec.Ts))
    lrows = []
    for c in res.line:
        lrows.append([c.section.name, fmt(c.section.route.distance, 5), fmt(c.section.run_time, 4),
                      " ".join(fmt(x * 1000, 3) for x in c.section.route.grade)]
                     + [f"{fmt(c.value('MFAC', i), 3)} / {fmt(c.value('PID', i), 3)}"
                        for i in INDICES])
    if lrows:
        sec.append(
            "## Line of adjacent stations (SYNTHETIC)\n\nThe station data of Nanning Line 1 are "
            "not public in the paper: these sections (distances, planned times, gradient "
            "sections in ‰) are **synthetic**, metro-like, and labelled so. Same controllers, "
            "no re-tuning. Cells are MFAC / PID.\n\n"
            + md_table(["section", "S (m)", "T_o (s)", "gradients (‰)"]
                       + [LABEL[i] for i in INDICES], lrows, "lrrlrrrr")
            + "\n\n![line stop errors]({figdir}/line-indices.png)")
    srows = [[fmt(lam, 3)] + [fmt(getattr(q, i)[0], 3) for i in (*INDICES, "rms_speed_error")]
             for lam, q in res.lambda_sweep]
    orow = [[k, fmt(v, 3)] for k, v in res.oat.items()]
    sec.append(
        "## Sensitivity of MFAC\n\nλ swept around the tuned value (others fixed):\n\n"
        + md_table(["λ"] + [LABEL[i] for i in (*INDICES, "rms_speed_error")], srows, "rrrrrr")
        + "\n\nOne at a time: each parameter multiplied by "
        + ", ".join(fmt(f) for f in spec.oat_factors)
        + " (ρ, η capped at 1); largest relative change of the RMS speed error:\n\n"
        + md_table(["parameter", "max |ΔRMS| / RMS"], orow, "lr")
        + "\n\n![lambda sensitivity]({figdir}/lambda-sensitivity.png)")
    figs = (Figure("speed-tracking", "Target and tracked speed; speed error.",
                   lambda fig: _plot_speed(fig, m), (7.0, 5.0)),
            Figure("accel-jerk", "Net acceleration and jerk of both controllers.",
                   lambda fig: _plot_accel(fig, m, spec.Ts), (7.0, 5.0)),
            Figure("line-indices", "Stop error and comfort per section (synthetic line).",
                   lambda fig: _plot_line(fig, res), (7.0, 4.0)),
            Figure("lambda-sensitivity", "MFAC speed error for each lambda.",
                   lambda fig: _plot_lambda(fig, res), (7.0, 4.0)))
    return Rendered(tuple(sec), figs)


def _findings(res, Ts: float) -> str:
    g = res.mfac_gains
    gains = MFACGains(g["lam"], g["rho"], g["eta"], g["mu"], g["phi1"])
    z = frozen_ppd_poles(gains, g["phi1"], Ts)
    return (
        "## Why MFAC struggles on this plant\n\nThe train's speed integrates the command, so "
        "the CFDL model Δy(k+1) = φ(k)Δu(k) has no bounded φ (Δy follows u, not Δu) and "
        "the control law is integral action with an adaptive gain. With φ frozen at φ(1) "
        "on a sampled pure integrator y(k+1) = y(k) + Ts u(k), the loop's characteristic "
        "polynomial is z² − (2 − G Ts) z + 1, G = ρφ/(λ + φ²): its roots multiply to 1, so "
        "for 0 < G Ts < 4 they lie on the unit circle (for the tuned set, φ = φ(1) and "
        f"Ts = {fmt(Ts)} s: "
        f"|z| = {fmt(abs(z[0]), 4)}, {fmt(abs(z[1]), 4)}). Lag and delay push them outside; "
        "what bounds the MFAC runs is the command limit and the PPD resets, which appear as "
        "the bang-bang acceleration in the figure. PID's proportional and derivative terms "
        "supply the damping that MFAC lacks.")


def _plot_speed(fig, m):
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    t = m.mfac.t
    ax1.plot(m.pid.t, m.pid.target[0] * 3.6, "k--", lw=1, label="target")
    ax1.plot(t, m.mfac.v[0] * 3.6, label="MFAC")
    ax1.plot(m.pid.t, m.pid.v[0] * 3.6, label="PID")
    ax1.set_ylabel("speed (km/h)")
    ax1.legend()
    ax1.set_title(m.section.name)
    ax2.plot(t, (m.mfac.v[0] - m.mfac.target[0]) * 3.6, label="MFAC")
    ax2.plot(m.pid.t, (m.pid.v[0] - m.pid.target[0]) * 3.6, label="PID")
    ax2.set_ylabel("speed error (km/h)")
    ax2.set_xlabel("time (s)")


def _plot_accel(fig, m, Ts):
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for run, lab in ((m.mfac, "MFAC"), (m.pid, "PID")):
        ax1.plot(run.t, run.a[0], label=lab, lw=1)
        ax2.plot(run.t[:-1], np.diff(run.a[0]) / Ts, label=lab, lw=0.8)
    ax1.plot(m.profile.t, m.profile.a, "k--", lw=1, label="target")
    ax1.set_ylabel("acceleration (m/s²)")
    ax1.legend()
    ax2.set_ylabel("jerk (m/s³)")
    ax2.set_xlabel("time (s)")


def _plot_line(fig, res):
    comps = (res.main, *res.line)
    names = [c.section.name.replace(" (synthetic)", "*") for c in comps]
    x = np.arange(len(comps))
    ax1, ax2 = fig.subplots(1, 2)
    for k, (ctrl, off) in enumerate((("MFAC", -0.2), ("PID", 0.2))):
        ax1.bar(x + off, [c.value(ctrl, "stop_error") for c in comps], 0.4, label=ctrl)
        ax2.bar(x + off, [c.value(ctrl, "comfort") for c in comps], 0.4, label=ctrl)
    ax1.axhline(res.stop_tolerance, color="k", ls="--", lw=1, label="tolerance")
    ax1.set_yscale("log")
    ax1.set_ylabel("stop error (m)")
    ax2.set_ylabel("comfort K_c (m/s³)")
    for ax in (ax1, ax2):
        ax.set_xticks(x, names, rotation=60, ha="right", fontsize=7)
    ax1.legend(fontsize=7)


def _plot_lambda(fig, res):
    ax = fig.add_subplot(111)
    run = res.lambda_runs
    for i, (lam, _) in enumerate(res.lambda_sweep):
        ax.plot(run.t, (run.v[i] - run.target[i]) * 3.6, lw=0.8, label=f"λ = {fmt(lam, 3)}")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("speed error (km/h)")
    ax.legend(fontsize=7)
