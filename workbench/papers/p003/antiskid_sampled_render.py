"""Markdown and figures of the sampled-data section of an antiskid run
(:mod:`workbench.papers.p003.antiskid_sampled`; pure rendering).

The tables, the variants' words, the summary of the lowest rates, the mesh
checks' text, the Radau table and its words and the figure panels are
general (:mod:`workbench.features.rate_sweep_render`); what stays here is
paper 003's wording: the cells of a rate (creep ratio, stop, e_vs), why a
rate fails (traction or braking), the section's prose, the Radau table's
headings and the two figures' layout."""
from __future__ import annotations

import math
from functools import partial

from ...features import rate_sweep_render as RR
from ...report.case_figures import Palette
from ...report.markdown import Figure, fmt
from .antiskid_sampled import MESH_ATOL, MESH_CHECK_MAX_HZ, TRACE_SECONDS
from .antiskid_sampled_check import RTOL, WINDOW_SAMPLES
from .antiskid_sampled_kernel import BRAKING_LEAD, EVS_SETTLE, TRACTION_TAIL

#: Heading of the section (findings on its quantities link here).
HEADING = "Sampled-data controller: rate f_c, zero-order hold"
#: Quantities the section shows (a pattern for :class:`~workbench.report.markdown.Rendered`).
PATTERN = r"sampled\."
#: The emulation row's label.
EMULATION = "emulation (continuous law, step-dependent)"
_color = Palette({"zoh": "tab:blue", "zoh_q_tau": "tab:red", "emulation": "k"})
#: m/s, the bound of the run designs' creep-speed-tracking claim (drawn for reference).
EVS_BOUND = 0.01


#: What a variant is, in words (:func:`workbench.features.rate_sweep_render.variant_label`).
variant_label = partial(RR.variant_label, input_name="torque", unit="N m")


def _outcome(m: dict, which: str) -> str:
    """Traction or braking at a rate, in words
    (:func:`workbench.features.rate_sweep_render.outcome`)."""
    if which == "braking":
        return RR.outcome(m, which, "no stop")
    return RR.outcome(m, which, "no cruise" if math.isnan(m["lam_max_over_opt"]) else
                      "λ > requirement")


def _row(label: str, m: dict) -> list:
    # a sum of equal sub-steps (time above) lands on rounding ties: one more digit there
    n = lambda k, sig: RR.printed(m[k], sig)
    return [label, n("lam_max_over_opt", 7), n("time_above", 2), n("t_cruise", 5),
            _outcome(m, "traction"), n("braking_duration", 3), n("stop_distance", 4),
            n("lam_min_brake", 3), n("evs_max_tracking", 2), n("u_max_over_peak", 3),
            _outcome(m, "braking")]


def sampled_section(res, rail: str) -> str:
    """``## Sampled-data controller: rate f_c, zero-order hold``."""
    sp = res.spec
    hw = RR.variant_sources(sp.quantisation, sp.measurement_delay, "N m")
    head = ["f_c (Hz)", "max λ/λ_opt", f"time λ > λ_opt (1 + {fmt(sp.creep_margin)}) (s)",
            "time to v_d (s)", "traction", "t_brake → stop (s)", "stop distance (m)",
            "min λ, braking", "max e_vs (m/s)", "max |u| / T_adh", "braking"]
    tables = RR.rate_tables(res.variants, variant_label, head, _row, _row(
        f"{EMULATION}, dt/2 = {fmt(res.reference_step)} s", res.reference.metrics))
    return (
        f"## {HEADING}\n\n"
        "The other sections run the laws as an *emulation*: the law is evaluated at every "
        "integration step and held as the torque that moves the stiff creep ratio of the "
        "exponential-Euler step by the rate the continuous law asks for, with an estimate "
        "of the model mismatch the paper does not have (see the numerics appendix); what "
        "it computes depends on the step. Here the same case (`" + sp.case + "`) runs as a "
        "sampled controller: the state is measured at t_k = k / f_c (optionally some time "
        "before) and the printed law is evaluated once per sample, with the predictor of "
        "eq (2) over the horizon h plus the measurement delay (its rollout steps through "
        "the commands it sent, whole samples at a time and at least "
        f"{fmt(1e3 * sp.predictor_step)} ms per step, with their exact average); the torque is "
        "rounded to the command's step and held until the next sample (zero-order hold), "
        "and the wheel receives it h later." + hw + " The plant is integrated on a mesh "
        "independent of f_c: every stretch between two events (a measurement, a sample, a "
        "command reaching the wheel) in equal exponential-Euler sub-steps of at most "
        f"{fmt(1e3 * sp.plant_step)} ms under the torque held on it, the metrics taken on "
        "that mesh (between samples too).\n\n"
        f"Two scenarios per rate, each only as long as its requirement needs. *Traction*: "
        f"from the design's initial state until {fmt(TRACTION_TAIL)} s after the cruise "
        "law took over; it meets the requirement when nothing diverges, the cruise law is "
        f"reached and lambda <= lambda_opt (1 + {fmt(sp.creep_margin)}) throughout. "
        f"*Braking*: from the cruise equilibrium (v_d, lambda_d) {fmt(BRAKING_LEAD)} s "
        "before t_brake; it meets the requirement when the train reaches v <= v_stop "
        "without diverging. The emulation row is the case's controller as the other "
        "sections run it (every step of dt/2, the plant stepped with it) in the same two "
        f"scenarios. e_vs: largest creep-speed error |v_s - v_s*| of eq (76) from "
        f"{fmt(EVS_SETTLE)} s after t_brake while omega > 3 rad/s (the run's own metric). "
        f"T_adh: the peak adhesion torque mu(lambda_opt) m g r = {fmt(res.u_peak / 1e3, 3)} "
        "kN m.\n\n"
        f"**Lowest control rate meeting both requirements, {rail} rail:**\n\n"
        + "\n".join(RR.summary_lines(res.variants, variant_label, lambda v, row: RR.missed(
            row.metrics, ("traction", "braking"), _outcome))) + "\n\n" + "\n\n".join(tables)
        + "\n\n![sampled]({figdir}/sampled.png)\n\n" + SAMPLED_CAPTION
        + "\n\n![sampled traction]({figdir}/sampled-traction.png)\n\n"
        + TRACE_CAPTION + "\n\n" + _checks_text(res))


SAMPLED_CAPTION = (
    "Metrics against the control rate f_c (log axis), one line per variant; dashed black: "
    "the emulation; top left: max lambda / lambda_opt - 1 (symmetric-log axis, linear within "
    "a thousandth of the margin) with lambda_opt (solid grey, 0) and the requirement "
    "lambda_opt (1 + margin) (dotted); top right: e_vs with the "
    f"{fmt(EVS_BOUND)} m/s of the creep-speed-tracking claim (dotted); bottom: the braking "
    "run; × at the top of a panel: that scenario's run diverged at that rate (no value).")
TRACE_CAPTION = (
    f"The first {fmt(TRACE_SECONDS)} s of traction: lambda / lambda_opt - 1 on the plant's "
    "mesh, where the approach to lambda_opt ends and the largest creep ratio of the run "
    "falls; dotted: the requirement.")


def three_level_text(res) -> str:
    """*Mesh, three levels* (:func:`workbench.features.rate_sweep_render.three_level_text`)."""
    return RR.three_level_text(
        res.variants, variant_label, max_rate=MESH_CHECK_MAX_HZ, step=res.spec.plant_step,
        scenarios="traction or braking", not_covered=(
            "the metrics claims compare above 1 kHz (the gaps to the emulation at the top "
            "rate), the lowest passing rate and the bisection brackets (outcomes at 2 and 5 "
            "kHz and at the bisection rates)"))


def _checks_text(res) -> str:
    sp = res.spec
    return (
        "**Checks of the plant's integration.** "
        + RR.mesh_text(res.variants, variant_label, MESH_ATOL, max_rate=MESH_CHECK_MAX_HZ,
                       step=sp.plant_step)
        + "\n\n" + three_level_text(res)
        + "\n\n" + RR.replay_text(RR.replay_table(
            res.checks, ["f_c (Hz)", "window", "t (s)", "v (m/s)", "torque pieces",
                         "max |Δλ| / λ_opt", "max |Δv| / v"],
            (lambda c: c.d_abs[1] / res.lambda_opt, lambda c: c.d_rel[0])),
            input_name="torque", receiver="the wheel", samples=WINDOW_SAMPLES,
            variant="ZOH variant", rtol=RTOL, model="the same lambdified model")
        + "\n\nWhy not Radau for every run: a sampled run restarts the integration at every "
        "sample and every arriving command (10 000 restarts per simulated second at 5 kHz), "
        "each with a creep-ratio transient of time constant ~v/4000 s to resolve; scipy's "
        "Radau, restarted from Python, costs about a millisecond per restart (the replays "
        "above), tens of minutes for one variant's grid; the compiled mesh takes seconds.")


def sampled_figures(res) -> tuple[Figure, Figure]:
    """``sampled.png``, the metrics against f_c, and ``sampled-traction.png``,
    lambda / lambda_opt - 1 at the start of traction."""
    return (Figure("sampled", "Sampled-data controller: metrics against the control rate.",
                   lambda fig: plot_sampled(fig, res), (9.0, 6.5)),
            Figure("sampled-traction", "Creep ratio at the start of traction, sampled.",
                   lambda fig: plot_traces(fig, res), (7.0, 4.0)))


def plot_sampled(fig, res):
    keys = (("lam_max_over_opt", "max λ / λ_opt − 1, traction (symlog)", "traction_diverged"),
            ("evs_max_tracking", "max e_vs (m/s), braking", "braking_diverged"),
            ("braking_duration", "t_brake → stop (s)", "braking_diverged"),
            ("stop_distance", "stop distance (m)", "braking_diverged"))
    # the top left panel shows the excess over 1
    axes = RR.plot_rate_panels(fig, res.variants, keys,
                               lambda v: _color(v.name), variant_label,
                               res.reference.metrics, EMULATION, {"lam_max_over_opt": 1.0})
    m = res.spec.creep_margin
    RR.mark_requirement(axes[0], m, "requirement λ_opt (1 + margin)", "λ_opt")
    axes[0].set_yscale("symlog", linthresh=m / 1000)
    axes[0].set_ylim(bottom=-m / 1000)
    axes[1].axhline(EVS_BOUND, color="dimgrey", ls=":", lw=1.0)
    axes[1].set_yscale("log")
    axes[0].legend(fontsize=6, loc="lower left")


def plot_traces(fig, res):
    ax = fig.add_subplot(111)
    RR.plot_traces(ax, res.traces, "y", lambda tr: _color(tr.variant),
                   lambda tr: EMULATION if tr.variant == "emulation" else
                   f"{variant_label(res.variant(tr.variant))}, {fmt(tr.rate)} Hz",
                   {100.0: "-", 1000.0: "--"})
    RR.mark_requirement(ax, res.spec.creep_margin)
    ax.set_ylim(-3 * res.spec.creep_margin, 2 * res.spec.creep_margin)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("λ / λ_opt − 1")
    ax.legend(fontsize=6, loc="lower right")
