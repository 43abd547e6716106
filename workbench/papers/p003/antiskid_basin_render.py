"""Markdown and figure of the cruise-basin check (pure rendering of
:class:`~workbench.papers.p003.antiskid_basin.CruiseBasin` and
:class:`~workbench.features.basin_points.GainSweep`).

Paper 003's wording (laws (61), (69), eqs (75)-(76), the k2 rule) and the
cruise figure's look stay here; the figure itself is the general
:func:`workbench.features.basin_plot.basin_figure`, the switch-state and gain
tables, what their verdicts mean and the certified gain range's sentence
those of :mod:`workbench.features.basin_points_render`."""
from __future__ import annotations

from ...features.basin_plot import BasinPlotStyle, basin_figure
from ...features.basin_points_render import (gain_edge_text, gain_sweep_table, points_table,
                                              points_verdict_text)
from ...features.basin_scalar_render import frozen_switch_table, scalar_method_text
from ...report.markdown import fmt
from ...report.synthesis_text import gain_text
from ...roa.render import render_basin_markdown
from .antiskid_basin import LAM_DIVERGED


#: Heading of the basin section (findings on switch and basin quantities link here).
HEADING = ("Regions of attraction: does each switch land in the basin of the law that "
           "takes over?")


def render_basin_result(res, *, rail: str) -> str:
    """Section of a :class:`~workbench.papers.p003.antiskid_basin_run.BasinResult`:
    loop, certified bracket, switch verdicts, k2 rule."""
    basin = res.basin
    head = (
        f"## {HEADING}\n\n"
        f"Cruise law (61) with K = {gain_text(basin.K)} on {rail} rail, at (v_d, lambda_d) = "
        f"({fmt(basin.v_d)} m/s, {fmt(basin.lambda_d, 4)}). The loop is the **delay-free** "
        "loop under exact prediction (as paper 003's Theorems 2-3 argue for laws (64) and "
        "(69)): law (61) as printed feeds the current error K E(t) to its numerator, so the "
        "real loop keeps the delayed term B K E(t - h); that term's local stability is what "
        "the LMI certificate (Theorem 1) proves. A switch is safe when both hold. "
        "V = E' P E with P = S^-T diag(1, w) S^-1 in the modal coordinates of A + B K "
        f"(w = {fmt(basin.w)}: the grid value that certifies the switch states best).\n\n")
    body = render_basin_markdown(basin.check, heading="### Certified level set")
    sw = ("\n### Switch states (acceleration → cruise)\n\n"
          + points_table(basin.check, [tr.fate for tr in basin.trajectories],
                         ["case", "v (m/s)", "lambda", "V", "in the certified basin?",
                          "delay-free trajectory"], shift=(basin.v_d, basin.lambda_d))
          + "\n\n" + points_verdict_text("delay-free", f"\"diverges\": |lambda| reaches "
                                         f"{fmt(LAM_DIVERGED)}, the wheel spins") + "\n")
    text = head + body + sw + brake_text(res.brake) + _k2_text(res.sweep, res.compare_source)
    if res.mass_factor != 1.0:
        text += (f"\nThe plant of this design has {fmt(res.mass_factor, 3)} x the nominal mass; "
                 "the basin is that of the controller's nominal model (the switch states are "
                 "this design's simulated ones).\n")
    return text


def brake_text(brake) -> str:
    """Subsection of the cruise -> braking switch (:mod:`.antiskid_basin_brake`;
    the table and the frozen loop's method:
    :func:`workbench.features.basin_scalar_render.frozen_switch_table`,
    :func:`~workbench.features.basin_scalar_render.scalar_method_text`)."""
    from .antiskid_basin_brake import FATE_RTOL, LAM_LIMIT, T_FATE, TRACK_TOL
    if not brake:
        return ("\n### Switch states (cruise → braking)\n\nNo case reached the braking "
                "phase.\n")
    return (
        "\n### Switch states (cruise → braking)\n\n"
        "Law (69) takes over at t_brake. It tracks the time-varying creep speed v_s*(t) of "
        "eq (76), so it has no fixed equilibrium: a basin exists only for the loop **frozen "
        "at the switch instant**. Assumptions: exact prediction (the delay-free loop, as "
        "Theorem 3 argues); the speed v frozen at its value at t_brake (the creep ratio "
        "moves on a time scale of about v / 4000 s, the speed by about 1 % a second); "
        "v_s* frozen at v_s*(t_brake), with d v_s*/dt = 0; the controller's nominal model, "
        "traction form (eq 12) for lambda >= 0 and braking form (eq 15) below, as the "
        "plant; law (69) computed on the braking form (eq 16) whatever the sign of lambda, "
        "as printed. " + scalar_method_text(LAM_LIMIT, name="lambda")
        + " The last column drops the frozen assumptions: the delay-free loop with "
        "v and lambda integrated and v_s*(t), d v_s*/dt of eq (76) as printed (Radau, rtol "
        f"{fmt(FATE_RTOL)}, over {fmt(T_FATE)} s; \"tracks\": lambda < 0 and |v lambda - "
        f"v_s*| < {fmt(TRACK_TOL)} m/s at the end).\n\n"
        + frozen_switch_table(brake, ["case", "v (m/s)", "lambda", "v_s* frozen (m/s)",
                                      "frozen loop", "in a basin of law (69)?",
                                      "delay-free loop, time-varying"], LAM_LIMIT, index=1,
                              name="lambda", at="t_brake")
        + "\n\nREFUTED here means that the state lies in the basin of no equilibrium of the "
          "frozen loop: on the traction side the braking form that law (69) is built on "
          "(its adhesion branch grows like e^{b lambda} for lambda > 0) is not the plant, "
          "and the law raises lambda further. The simulated runs are not this loop (their "
          "predictor integrates the braking form, eq (70), which is not the plant there "
          "either, and the law is held over each sample): what they do after t_brake is in "
          "the phase-switch section.\n")


def _k2_text(sweep, compare_source) -> str:
    v, lam = sweep.point
    rule = gain_edge_text(sweep, "k2", "the switch at (v_d, lambda_opt)",
                          kept=f"**Certified switching rule.** With k1 = {fmt(sweep.gain[0], 4)}, ")
    return ("\n### Which cruise gains make the printed switch safe?\n\n"
            f"Switch state of eq (75) as printed: v = {fmt(v, 4)} m/s, lambda = lambda_opt = "
            f"{fmt(lam, 4)}. Each k2 is judged with every P of the weight grid (CERTIFIED if "
            "one certifies the state); the gains compared (" + compare_source + ") are judged "
            "with their own k1.\n\n"
            + gain_sweep_table(sweep, ["k1", "k2", "row", "switch state in a certified basin?",
                                       "w", "delay-free trajectory"], digits=(4, 5))
            + "\n\n" + rule + " The rule is sufficient (a quadratic V); where the "
            "trajectory column says \"diverges\" the state is outside the true basin of the "
            "delay-free loop as well.\n")


#: The cruise figure's look: paths clipped to lambda - lambda_d in [-0.3, 0.5].
_STYLE = BasinPlotStyle(sampled_lw=0.7, sampled_alpha=0.8, point_lw=1.8, point_ms=9, cx_ms=8,
                        point_label="switch `{label}`: {outcome}", clip=(None, (-0.3, 0.5)),
                        legend_loc="upper left")


def plot_basin(fig, basin) -> None:
    """(v - v_d, lambda - lambda_d) plane: certified and refuted level sets,
    the counterexample, sampled delay-free trajectories, switch states
    (:func:`workbench.features.basin_plot.basin_figure`), lambda = lambda_opt."""
    basin_figure(fig, basin.check.estimate, basin.check.points, basin.trajectories, (0, 1),
                 _STYLE, ("v - v_d (m/s)", "lambda - lambda_d"), ylim=(-0.15, 0.3),
                 extra=lambda ax: ax.axhline(basin.lambda_opt - basin.lambda_d,
                                             color="tab:purple", ls=":", lw=0.8,
                                             label="lambda = lambda_opt"))
