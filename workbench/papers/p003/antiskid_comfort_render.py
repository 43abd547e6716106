"""Markdown and figures of an antiskid run's comfort and torque
(:func:`workbench.features.comfort.comfort_of`; pure rendering).

The comfort columns and the acceleration/jerk figure are the general
:mod:`workbench.features.comfort_render`; what stays here is paper 003's:
the controller's phase switches near each stretch above the jerk limit, the
wheel torque against T_adh and the section's wording."""
from __future__ import annotations

import numpy as np

from ...controllers.antiskid003_settings import PHASE_NAMES
from ...features.comfort import COMFORT_RTOL
from ...features.comfort_render import comfort_cells, comfort_headers
from ...features.comfort_render import plot_comfort as plot_comfort_traces
from ...report.markdown import Figure, fmt, md_table
from ...sim.convergence import P_MIN
from ...features.comfort import comfort_quantities
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
    and of the step of eq (76) at omega <= omega_switch (v_s* jumps to 0)."""
    run = c.run
    ph = np.asarray(run.phase)
    k = np.flatnonzero(ph[1:] != ph[:-1]) + 1
    t_b = c.metrics["t_brake"]
    # Braking starts at the first step at or after t_brake, an input that is
    # also a record sample: which sample first shows it (300 or 300.05 s)
    # depends on the last bit of the accumulated time, so that switch is
    # given at t_brake itself (it lies within one step, dt, after it).
    at = lambda i: (t_b if PHASE_NAMES[ph[i]] in _BRAKING and PHASE_NAMES[ph[i - 1]] not in
                    _BRAKING and np.isfinite(t_b) and abs(run.t[i] - t_b) <= 2 * RECORD_DT
                    else float(run.t[i]))
    out = [(float(at(i)), f"{PHASE_NAMES[ph[i - 1]]} → {PHASE_NAMES[ph[i]]}") for i in k]
    t3 = c.metrics["t_brake"] + c.metrics["omega3_after_brake"]
    if np.isfinite(t3):
        out.append((float(t3), f"omega <= {fmt(spec.profile['omega_switch'])} rad/s, where "
                               "v_s* of eq (76) steps to 0"))
    return sorted(out)


def _windows_text(c, spec) -> str:
    """The stretches with |jerk| above the limit of one case, each with the
    phase switches within one window of it."""
    T = spec.comfort.window.value
    sw = _switches(c, spec)
    parts = []
    for t0, t1, peak in c.comfort.jerk_windows:
        near = [f"{what} at {fmt(ts, 4)} s" for ts, what in sw if t0 - T <= ts <= t1 + T]
        parts.append(f"{fmt(t0, 4)}-{fmt(t1, 4)} s (peak {fmt(peak, 2)} m/s³; "
                     + ("; ".join(near) if near else "no phase switch within the window") + ")")
    return "; ".join(parts)


def comfort_section(res, spec) -> str:
    """``## Passenger comfort and wheel torque``."""
    cf = spec.comfort
    u_peak = peak_adhesion_torque(spec)
    rows = []
    for c in res.cases:
        m = c.comfort
        agree = comfort_quantities(c.case.name, m, c.comfort_coarse,
                                   None if c.quarter is None else c.quarter[2])[
            f"cases[{c.case.name}].comfort_converged"]
        agree = "—" if c.quarter is None else (agree or "**not converged**")
        rows.append([f"`{c.case.name}`", *comfort_cells(m), fmt(m.u_max_over_peak, 3), agree])
    done = [c for c in res.cases if np.isnan(c.metrics["t_diverged"])]
    where = "".join(f"\n\n`{c.case.name}`: |jerk| > {fmt(cf.jerk_max.value)} m/s³ at "
                    + (_windows_text(c, spec) or "no time") + "." for c in done)
    if done:   # why a run that works still commands more than T_adh in traction
        J, r = spec.params["J"].value, spec.params["r"].value
        extra = J * float(np.max(done[0].comfort.a)) / r
        where += (f"\n\nIn traction the commanded torque exceeds T_adh by what accelerates "
                  f"the wheel itself, J omega' ≈ J a / r: at `{done[0].case.name}`'s largest "
                  f"acceleration {fmt(extra, 3)} N m, i.e. {fmt(1 + extra / u_peak, 3)} T_adh "
                  "(next to its largest |u| / T_adh in the table).")
    return (
        f"## {HEADING}\n\nPaper 003 states no comfort limit; the design's limits are "
        f"|a| <= {fmt(cf.a_max.value)} m/s² ({cf.a_max.source}) and |jerk| <= "
        f"{fmt(cf.jerk_max.value)} m/s³ ({cf.jerk_max.source}). a is the train's "
        f"acceleration v', jerk its rate, each averaged over a {fmt(cf.window.value)} s "
        f"window ({cf.window.source}) of the run recorded at dt/2; a run that diverged ends "
        "there. The torque is the controller's commanded u(t) against the peak adhesion "
        f"torque T_adh = mu(lambda_opt) m g r = {fmt(u_peak / 1e3, 3)} kN m of the nominal "
        "model, the most the rail transmits in steady state (the paper gives no drive or "
        f"brake limit; the design's only torque bound, `torque_range` = "
        f"{fmt(spec.torque_range)} T_adh, is its divergence test).\n\n"
        + md_table(["case", *comfort_headers(cf), "max |u| / T_adh",
                    f"converged, dt to dt/4 ({fmt(100 * COMFORT_RTOL)} %)"],
                   rows, "lrrrrrl")
        + "\n\nConverged: the |a| and |jerk| peaks at dt, dt/2 and dt/4 have a Richardson "
        f"error estimate within {fmt(100 * COMFORT_RTOL)} % of the peak (levels whose "
        f"differences change sign: the larger difference at order {fmt(P_MIN)}); — : no dt/4 run "
        "(no claim states the case's convergence)."
        + where
        + "\n\n![comfort]({figdir}/comfort.png)\n\nAcceleration (top) and jerk (bottom) "
        "against time with the comfort limits (dashed); dotted: the phase switches of the "
        "first case that does not diverge."
        "\n\n![torque]({figdir}/torque.png)\n\n" + TORQUE_CAPTION)


def comfort_figure(res, spec) -> Figure:
    """``comfort.png``: acceleration and jerk against time (a design with ``[comfort]``)."""
    return Figure("comfort", "Acceleration and jerk against time, with the comfort limits.",
                  lambda fig, res=res, sp=spec: plot_comfort(fig, res, sp), (7.0, 5.5))


def torque_figure(res, spec) -> Figure:
    """``torque.png``: commanded torque against ±T_adh and the torque range."""
    return Figure("torque", "Commanded wheel torque against the adhesion and torque limits.",
                  lambda fig, res=res, sp=spec: plot_torque(fig, res, sp), (7.0, 4.0))


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
    for c in res.cases:
        ax.plot(c.run.t, c.run.u[0], color=color_of(c.case.name), label=c.case.name, lw=0.8)
    for s in (1, -1):
        ax.axhline(s * u_peak, color="k", ls="--", lw=0.8,
                   label="±T_adh (peak adhesion)" if s > 0 else None)
        ax.axhline(s * spec.torque_range * u_peak, color="k", ls=":", lw=0.8,
                   label=f"±{fmt(spec.torque_range)} T_adh (torque range)" if s > 0 else None)
    ax.set_yscale("symlog", linthresh=u_peak)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("u (N m), commanded")
    ax.legend(fontsize=7, ncol=3)
