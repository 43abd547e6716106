"""Figures of the ``antiskid-run`` study: draw functions of matplotlib
figures, pure functions of the study result (see
:mod:`workbench.papers.p003.antiskid_run_render`).

The layout (cases on shared axes, a colour per case, snapped data, axis
ends on a grid) is :mod:`workbench.report.case_figures`; what stays here is
paper 003's: which quantities are drawn (wheel speed, creep ratio against
lambda_opt, the creep-speed error of eq (76), the adhesion curve)."""
from __future__ import annotations

import math

import numpy as np

from ...controllers.antiskid003_settings import BRAKE, BRAKE_IN, CreepSpeedProfile
from ...printed_grid import axis_end
from ...report.case_figures import (Palette, plot_cases, plot_on_curve, plot_phase_plane,
                                    time_window)
from ...sim.wheel_slip import ArrayOps, creep_speed, wheel_speed

#: The colour of a case in every figure.
color_of = Palette({"paper": "tab:red", "compensated": "tab:blue", "uncompensated": "tab:orange",
                    "recursive": "tab:purple"})


def plot_speed(fig, res):
    ax = fig.add_subplot(111)
    vmax = max(float(np.nanmax(c.run.x[0])) for c in res.cases)
    for c in res.cases:
        r, name = c.run, c.case.name
        v, lam = r.x
        vw = wheel_speed(v, lam, 1.0, ArrayOps)          # v_w = omega r, eqs (4)-(5)
        plot_cases(ax, [(name, r.t, v, f"{name}: v")], color_of, vmax)
        plot_cases(ax, [(name, r.t, vw, f"{name}: v_w")], color_of, vmax, ls=":")
    ax.set_ylim(-5.0, axis_end(1.3 * vmax))   # a data-derived end moves every pixel
    ax.set_xlabel("t (s)")
    ax.set_ylabel("speed (m/s), clipped")
    ax.legend(fontsize=7, ncol=2)


def plot_creep(fig, res):
    ax1, ax2 = fig.subplots(2, 1)
    for ax in (ax1, ax2):
        plot_cases(ax, [(c.case.name, c.run.t, np.clip(c.run.x[1], -1, 1), c.case.name)
                        for c in res.cases], color_of, 1.0)
        ax.axhline(res.lambda_opt, color="k", ls="--", lw=0.8, label="lambda_opt (traction)")
        ax.axhline(-res.lambda_opt, color="k", ls="-.", lw=0.8, label="−lambda_opt (braking)")
        ax.axhline(res.lambda_d, color="gray", ls=":", lw=0.8, label="lambda_d")
        ax.set_ylabel("creep ratio")
    t_c = min((c.metrics["t_cruise"] for c in res.cases
               if not math.isnan(c.metrics["t_cruise"])), default=0.0)
    ax1.set_ylim(-0.2, 0.3)
    ax2.set_xlim(*time_window(t_c, 1.0, 4.0))
    ax2.set_ylim(-0.1, 1.0)
    ax2.set_xlabel("t (s)")
    ax1.legend(fontsize=7, ncol=3)


def plot_adhesion(fig, res, spec):
    from ...plants.adhesion import NumericAdhesion
    from .antiskid_run_spec import plant_values
    mu = NumericAdhesion.from_dict(plant_values(spec, spec.mass_factor)).mu
    lam = np.linspace(-0.6, 0.6, 601)
    ax_mu, ax_pp = fig.subplots(1, 2)
    plot_on_curve(ax_mu, lam, mu, [(c.case.name, np.clip(c.run.x[1], -0.6, 0.6))
                                   for c in res.cases], color_of, "mu(lambda), plant")
    plot_phase_plane(ax_pp, [(c.case.name, c.run.x[0], np.clip(c.run.x[1], -1, 1))
                             for c in res.cases], color_of, lw=0.8)
    for a in (res.lambda_opt, -res.lambda_opt):
        ax_mu.axvline(a, color="gray", ls="--", lw=0.8)
    ax_mu.set_xlabel("creep ratio lambda")
    ax_mu.set_ylabel("adhesion coefficient mu")
    ax_mu.legend(fontsize=7)
    ax_pp.axhline(res.lambda_opt, color="gray", ls="--", lw=0.8)
    ax_pp.set_xlabel("v (m/s)")
    ax_pp.set_ylabel("lambda (clipped to ±1)")


def plot_evs(fig, res, spec):
    ax = fig.add_subplot(111)
    prof = CreepSpeedProfile(t_brake=spec.scenario["t_brake"], **spec.profile)
    r_wheel = spec.params["r"].value
    for c in res.cases:
        r = c.run
        sel = (r.phase == BRAKE) | (r.phase == BRAKE_IN)
        if not sel.any():
            continue
        t, v, lam = r.t[sel], r.x[0][sel], r.x[1][sel]
        om = wheel_speed(np.maximum(v, 1e-3), lam, r_wheel, ArrayOps)
        vs, _ = prof(t, v, 0 * v, om, ArrayOps)
        ax.plot(t, creep_speed(v, lam, ArrayOps) - vs, color=color_of(c.case.name), label=c.case.name)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("e_vs = v_s - v_s* (m/s)")
    ax.set_ylim(-0.3, 0.3)
    ax.legend(fontsize=7)
