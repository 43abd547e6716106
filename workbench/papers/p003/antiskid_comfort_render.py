"""Markdown and figures of an antiskid run's comfort and torque
(:func:`workbench.features.comfort.comfort_of`; pure rendering).

The comfort columns, the phase switches near each stretch above the jerk
limit and the acceleration/jerk figure are the general
:mod:`workbench.features.comfort_render`, the torque against its limits
:func:`workbench.report.case_figures.plot_against_limits`; what stays here is
paper 003's: which switches (the phases of controller (75), the step of eq
(76)), T_adh and the torque range as the limits, and the section's wording."""
from __future__ import annotations

import numpy as np

from ...controllers.antiskid003_settings import PHASE_NAMES
from ...features.comfort_render import (comfort_table, converged_text, jerk_text, limits_text,
                                         phase_switches, window_text)
from ...features.comfort_render import plot_comfort as plot_comfort_traces
from ...report.case_figures import plot_against_limits
from ...report.markdown import fmt
from .antiskid_run import RECORD_DT
from .antiskid_run_figures import color_of
from .antiskid_run_spec import peak_adhesion_torque

#: Heading of the section (findings on its quantities link here).
HEADING = "Passenger comfort and wheel torque"
#: Quantities the section shows (a pattern for :class:`~workbench.report.markdown.Rendered`).
PATTERN = r"cases\[[^\]]+\]\.(a_max_abs|jerk_max_abs|time_above_|u_max_over_peak|comfort_)"


#: Phases of braking (their start is t_brake, :func:`_switches`).
_BRAKING = ("handover to braking", "braking")


def _switches(c, spec) -> list[tuple[float, str]]:
    """(time, what) of each change of the controller phase in a case's run,
    and of the step of eq (76) at omega <= omega_switch (v_s* jumps to 0).
    Braking starts at the first step at or after t_brake, an input that is
    also a record sample: which sample first shows it (300 or 300.05 s)
    depends on the last bit of the accumulated time, so that switch is given
    at t_brake itself (it lies within one step, dt, after it)."""
    t_b = c.metrics["t_brake"]
    out = phase_switches(c.run.t, c.run.phase, PHASE_NAMES, (_BRAKING, t_b, 2 * RECORD_DT))
    t3 = t_b + c.metrics["omega3_after_brake"]
    if np.isfinite(t3):
        out.append((float(t3), f"omega <= {fmt(spec.profile['omega_switch'])} rad/s, where "
                               "v_s* of eq (76) steps to 0"))
    return sorted(out)


def comfort_section(res, spec) -> str:
    """``## Passenger comfort and wheel torque``."""
    cf = spec.comfort
    u_peak = peak_adhesion_torque(spec)
    table = comfort_table([(c.case.name, c.comfort, None if c.quarter is None else (
        c.comfort_coarse, c.comfort, c.quarter[2]), [fmt(c.comfort.u_max_over_peak, 3)])
        for c in res.cases], cf, ["max |u| / T_adh"])
    done = [c for c in res.cases if np.isnan(c.metrics["t_diverged"])]
    where = "".join("\n\n" + jerk_text(c.case.name, c.comfort, _switches(c, spec), cf)
                    for c in done)
    if done:   # why a run that works still commands more than T_adh in traction
        J, r = spec.params["J"].value, spec.params["r"].value
        extra = J * float(np.max(done[0].comfort.a)) / r
        where += (f"\n\nIn traction the commanded torque exceeds T_adh by what accelerates "
                  f"the wheel itself, J omega' ≈ J a / r: at `{done[0].case.name}`'s largest "
                  f"acceleration {fmt(extra, 3)} N m, i.e. {fmt(1 + extra / u_peak, 3)} T_adh "
                  "(next to its largest |u| / T_adh in the table).")
    return (
        f"## {HEADING}\n\nPaper 003 states no comfort limit; the design's limits are "
        f"{limits_text(cf)}. a is the train's acceleration v', jerk its rate, each "
        f"{window_text(cf)} of the run recorded at dt/2; a run that diverged ends there. "
        "The torque is the controller's commanded u(t) against the peak adhesion "
        f"torque T_adh = mu(lambda_opt) m g r = {fmt(u_peak / 1e3, 3)} kN m of the nominal "
        "model, the most the rail transmits in steady state (the paper gives no drive or "
        f"brake limit; the design's only torque bound, `torque_range` = "
        f"{fmt(spec.torque_range)} T_adh, is its divergence test).\n\n"
        + table
        + "\n\n" + converged_text() + " (no claim states the case's convergence)."
        + where
        + "\n\n![comfort]({figdir}/comfort.png)\n\nAcceleration (top) and jerk (bottom) "
        "against time with the comfort limits (dashed); dotted: the phase switches of the "
        "first case that does not diverge."
        "\n\n![torque]({figdir}/torque.png)\n\n" + TORQUE_CAPTION)


#: Caption of ``torque.png`` (in the comfort section, or under Figures without one).
TORQUE_CAPTION = ("Commanded torque u(t) of every case (it acts h later) against ±T_adh = "
                  "±mu(lambda_opt) m g r (dashed: the most the rail transmits in steady "
                  "state) and the design's torque range (dotted: its divergence test); "
                  "symmetric-log axis, linear within ±T_adh. The runs are recorded every "
                  f"{fmt(RECORD_DT)} s and the divergence test acts on every step, so a case "
                  "that diverged ends at its last record, before the command that left the "
                  "range.")


def plot_comfort(fig, res, spec):
    ref = next((c for c in res.cases if np.isnan(c.metrics["t_diverged"])), None)
    plot_comfort_traces(fig, [(c.case.name, color_of(c.case.name), c.comfort) for c in res.cases],
                        spec.comfort, () if ref is None else [ts for ts, _ in _switches(ref, spec)])


def plot_torque(fig, res, spec):
    u_peak = peak_adhesion_torque(spec)
    ax = fig.add_subplot(111)
    plot_against_limits(ax, [(c.case.name, c.run.t, c.run.u[0]) for c in res.cases], color_of,
                        [(u_peak, "--", "±T_adh (peak adhesion)"),
                         (spec.torque_range * u_peak, ":",
                          f"±{fmt(spec.torque_range)} T_adh (torque range)")], lw=0.8)
    ax.set_yscale("symlog", linthresh=u_peak)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("u (N m), commanded")
    ax.legend(fontsize=7, ncol=3)
