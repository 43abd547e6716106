"""Markdown and figures of the ``antiskid-run`` study (pure rendering).

The layout is general (:mod:`workbench.report.case_tables`: per-case metrics
and convergence tables, rows per case; :mod:`workbench.features.linear_delay_check_render`:
the linear cross-check of the LMI delay bound; :mod:`workbench.report.case_figures`;
:mod:`workbench.features.frozen_loop_render`: the loop frozen at a phase switch;
:mod:`workbench.features.montecarlo_render`: the Monte Carlo tables, figures and
their text, with the sweep's words of :mod:`.antiskid_montecarlo_render`). What
stays here is paper 003's and has no general counterpart: the wording of the
scenario, of the phase switches of controller (75) and of the numerics, the
metric labels, the creep-ratio and lambda_opt lines."""
from __future__ import annotations

import math

from ...controllers.antiskid003_settings import DIVERGED_HOW, PHASE_NAMES, ControllerSettings
from ...features.frozen_loop_render import FROZEN_ALIGN, FROZEN_HEADS, frozen_loop_cells
from ...features.linear_delay_check_render import linear_check_figure, linear_check_section
from ...report.binned_fractions import binned_fraction_table
from ...report.case_tables import (CaseLevels, case_convergence_section, case_metric_table,
                                   case_rows, event_cell)
from ...report.markdown import Figure, Rendered, fmt, md_table
from ...report.synthesis_text import gain_text
from ...sim.convergence import P_MIN
from ...sim.wheel_slip import MAX_DLAMBDA, MAX_HALVINGS
from .antiskid_basin_render import HEADING as BASIN_HEADING
from .antiskid_comfort_render import (HEADING, PATTERN, TORQUE_CAPTION, comfort_section,
                                      plot_comfort, plot_torque)
from .antiskid_montecarlo_render import WORDS
from .antiskid_run_figures import plot_adhesion, plot_creep, plot_evs, plot_speed

_LABELS = {  # metric -> (label, unit, sig)
    "t_cruise": ("time to reach v_d", "s", 4),
    "lam_max_traction": ("max creep ratio, traction", "-", 4),
    "lam_max_over_opt": ("max creep ratio / lambda_opt", "-", 4),
    "v_max": ("max speed, traction", "m/s", 4),
    "v_err_at_brake": ("v - v_d at t_brake", "m/s", 2),
    "lam_err_at_brake": ("lambda - lambda_d at t_brake", "-", 2),
    "braking_duration": ("braking: t_brake to v <= v_stop", "s", 3),
    "omega3_after_brake": ("braking: t_brake to omega <= 3 rad/s", "s", 3),
    "lam_min_brake": ("min creep ratio, braking", "-", 3),
    "evs_max_tracking": ("max creep-speed error (omega > 3 rad/s, after 5 s)", "m/s", 2),
    "evs_last": ("creep-speed error at the stop", "m/s", 2),
    "t_diverged": ("diverged at", "s", 4),
}


def _diverged_text(c) -> str:
    m = c.metrics
    return event_cell(m["t_diverged"], lambda: f"{PHASE_NAMES[int(m['phase_diverged'])]}; "
                                               f"{DIVERGED_HOW[int(m['diverged_how'])]}")


def render(design, res) -> Rendered:
    spec = design.spec
    sc = spec.scenario
    sections = []
    rows = [["v(0), lambda(0)", f"{fmt(sc['v0'])} m/s, {fmt(sc['lambda0'])}"],
            ["u on [-h, 0)", f"{fmt(sc['u_init'])} N m"],
            ["input delay h (plant and predictor)", f"{fmt(sc['h'], 4)} s"],
            ["v_d, lambda_d (solved), lambda_opt",
             f"{fmt(sc['v_d'])} m/s, {fmt(res.lambda_d, 4)}, {fmt(res.lambda_opt, 4)}"],
            ["braking from", f"{fmt(sc['t_brake'])} s"],
            ["plant mass / nominal", fmt(spec.mass_factor, 3) + " (the controller keeps the nominal model)"],
            ["cruise gain K used", f"{gain_text(res.K)} — {res.K_how}"
             + (f", h_certified = {fmt(res.h_certified, 4)} s" if res.h_certified else "")],
            ["printed gain", f"{gain_text(spec.K_table, 5)} ({spec.K_source})"],
            ["k_ac, k_de", f"{fmt(spec.k_ac)}, {fmt(spec.k_de)} 1/s"],
            ["step dt (reported at dt/2)", f"{fmt(res.dt)} s ({fmt(res.dt / 2)} s)"]]
    sections.append(
        f"## Scenario (paper 003, section 4)\n\nRail: **{spec.rail}**. Controller (75): "
        "acceleration law (64), cruise law (61), braking law (69) with the desired creep speed "
        "of eq (76); the predictor X(t+h) of Lemma 1, eq (2).\n\n"
        + md_table(["item", "value"], rows, "ll") + "\n\n" + _cases_text(spec))
    sections.append(_results_section(res))
    sections.append(_switch_section(res, spec))
    sections.append(_convergence_section(res, spec))
    sections.append(linear_check_section(
        res.linear, linearisation="the cruise linearisation",
        closing=": with this gain the loop decays at delays two orders of magnitude above h_m, "
        "as its infinite exact margin says."))
    anchors = [(r"cases\[[^\]]+\]\.(diverged|stopped|t_|braking|lam_|evs|omega3|v_)",
                "What happens"),
               (r"switch\.|basin\.", BASIN_HEADING),
               (r"montecarlo\.", "Monte Carlo robustness (reduced sample)")]
    extra_figs = (Figure("torque", "Commanded wheel torque against the adhesion and torque limits.",
                         lambda fig: plot_torque(fig, res, spec), (7.0, 4.0)),)
    if spec.comfort is not None:
        sections.append(comfort_section(res, spec))
        extra_figs += (Figure("comfort", "Acceleration and jerk against time, with the comfort "
                              "limits.", lambda fig: plot_comfort(fig, res, spec), (7.0, 5.5)),)
        anchors.insert(0, (PATTERN, HEADING))
    if res.sampled is not None:
        from .antiskid_sampled_render import (HEADING as SAMPLED_HEADING, PATTERN as SAMPLED,
                                              sampled_figures, sampled_section)
        sections.append(sampled_section(res.sampled, spec.rail))
        extra_figs += sampled_figures(res.sampled)
        anchors.insert(0, (SAMPLED, SAMPLED_HEADING))
    if res.montecarlo is not None:
        sections.append(_montecarlo_section(design, res.montecarlo, res.halving))
    figs = (
        Figure("speed", "Train speed v and wheel speed v_w = omega r.",
               lambda fig, res=res: plot_speed(fig, res), (7.0, 4.0)),
        Figure("creep-ratio", "Creep ratio against ±lambda_opt and lambda_d.",
               lambda fig, res=res: plot_creep(fig, res), (7.0, 5.5)),
        *extra_figs,
        Figure("creep-speed-error", "Creep-speed tracking error in braking.",
               lambda fig, res=res, sp=spec: plot_evs(fig, res, sp), (7.0, 4.0)),
        linear_check_figure(res.linear, "Linear error system E' = A E + B K E(t-h)."),
        Figure("adhesion", "The plant's adhesion curve with each run's operating points.",
               lambda fig, res=res, sp=spec: plot_adhesion(fig, res, sp), (9.0, 3.8)),
    )
    if res.basin is not None:
        from .antiskid_basin_render import plot_basin, render_basin_result
        sections.insert(3, render_basin_result(res.basin, rail=spec.rail)
                        + "\n![basin]({figdir}/basin.png)\n\nThe (v - v_d, lambda - lambda_d) "
                        "plane of the delay-free cruise loop (see the section's text).\n")
        figs += (Figure("basin", "Certified basin of the cruise law (61), switch states.",
                        lambda fig, b=res.basin.basin: plot_basin(fig, b), (7.0, 5.0)),)
    if res.montecarlo is not None:
        figs += WORDS.figures(res.montecarlo)
    sections.append(
        "## Figures\n\n"
        "![speed]({figdir}/speed.png)\n\nSpeed and wheel speed of every case (a case "
        "that diverges ends where it is declared diverged).\n\n"
        "![creep ratio]({figdir}/creep-ratio.png)\n\nCreep ratio: whole run (top) and the "
        "end of acceleration (bottom), with lambda_opt and lambda_d.\n\n"
        + ("" if spec.comfort is not None else
           "![torque]({figdir}/torque.png)\n\n" + TORQUE_CAPTION + "\n\n")
        + "![creep speed error]({figdir}/creep-speed-error.png)\n\nCreep-speed error "
        "e_vs = v_s - v_s*(t) in braking (Theorem 3, cf. Fig. 4 of the paper).\n\n"
        "![linear checks]({figdir}/linear-checks.png)\n\n|E| of the linear error system with "
        "the finite-margin gain at the multiples of its exact margin h*.\n\n"
        "![adhesion]({figdir}/adhesion.png)\n\nLeft: the plant's adhesion curve mu(lambda) "
        "(eq 6, the plant's own parameters) with the (lambda, mu) each run visits; past the "
        "peak at lambda_opt the wheel loses adhesion (spin in traction, lock in braking). "
        "Right: the same runs in the (v, lambda) plane, from the start (o) to the end (x).")
    sections.append(_numerics_section(res.montecarlo is not None, spec.rail))
    return Rendered(tuple(sections), figs, tuple(anchors))


def _cases_text(spec) -> str:
    rows = [[f"`{c.name}`", "yes" if c.compensate else "no", c.cruise_entry, c.brake_entry,
             c.description] for c in spec.cases]
    return ("Cases (variants of controller 75):\n\n"
            + md_table(["case", "predictor", "cruise entry", "braking entry", "what"], rows,
                       "lllll")
            + "\n\n*cruise entry* `speed`: law (61) from the first sample with v >= v_d, as "
            "printed; `creep`: law (64) with target lambda_d first, law (61) once "
            f"|lambda - lambda_d| <= {fmt(spec.handover_band)}.")


def _results_section(res) -> str:
    keys = [k for k in _LABELS if k not in ("lam_err_at_brake", "t_diverged")]
    return ("## What happens\n\n"
            + case_metric_table([c.case.name for c in res.cases], [c.metrics for c in res.cases],
                                keys, _LABELS,
                                [["diverged", ""] + [_diverged_text(c) for c in res.cases]])
            + "\n\nAll values at dt/2 (see the convergence table). '—': not reached (the run "
            "ended before).")


def _switch_section(res, spec) -> str:
    def at_switch(sw):
        return [fmt(sw.v, 4), fmt(sw.lam, 4), fmt(sw.dmu_dlam, 3),
                *frozen_loop_cells(sw.A_loc, sw.abscissa, sw.margin)]

    def at_brake(m):
        lb, dv = m["lam_at_brake"], m["t_diverged"]
        after = ("diverged at t = " + fmt(dv, 4) + " s" if not math.isnan(dv) else
                 "lambda < 0 after " + fmt(m["t_lam_negative"] - m["t_brake"], 3)
                 + " s; stopped")
        return [fmt(lb, 4), "no (lambda > 0: traction side)" if lb > 0 else "yes", after]

    rows = case_rows([(c.case.name, c.switch) for c in res.cases], at_switch, ["—"] * 6)
    brows = case_rows([(c.case.name, None if math.isnan(c.metrics["lam_at_brake"]) else c.metrics)
                       for c in res.cases], at_brake, ["—", "— (braking not reached)", "—"])
    return (
        "## Phase switches: is the state where the next controller works?\n\n"
        "**Acceleration → cruise.** The LMI certificate of law (61) is local to the cruise "
        "linearisation at (v_d, lambda_d). At the state where law (61) takes over we freeze "
        "the loop, linearising the traction form with the feed-forward part of (61), "
        "x' = A_loc x + A_d x(t - h), A_d = (y3/den) B K, and give its delay-free spectral "
        "abscissa and exact delay margin (Chen-Gu-Nett).\n\n"
        + md_table(["case", "v (m/s)", "lambda", "d mu/d lambda", *FROZEN_HEADS], rows,
                   "lrrr" + FROZEN_ALIGN)
        + "\n\n" + _switch_note(res) + "\n\n"
        "**Cruise → braking.** Law (69) is built on the braking form (eq 15, lambda <= 0). "
        "State at t_brake:\n\n"
        + md_table(["case", "lambda at t_brake", "in the braking form's domain?", "then"],
                   brows, "lrll")
        + "\n\nThe braking law starts on the traction side (lambda = lambda_d > 0), where its "
        "model (the braking form, whose adhesion branch grows like e^{b lambda} for lambda > 0) "
        "does not hold" + _positive_creep_text(spec.profile) + ".\n\n"
        "**omega <= 3 rad/s.** v_s* jumps to 0 (eq 76): the creep-speed error jumps and decays "
        "at rate k_de; the train then coasts on running resistance to v_stop.")


def _positive_creep_text(profile: dict) -> str:
    """When eq (76) asks for a positive creep speed after t_brake: while
    c0 - c1 (t - t_brake) > 0, i.e. for c0 / c1 seconds."""
    c0, c1 = profile["c0"], profile["c1"]
    if not (c0 > 0 and c1 > 0):
        return ""
    return (f"; eq (76) even asks for a *positive* creep speed during the first c0 / c1 = "
            f"{fmt(c0 / c1, 3)} s")


def _switch_note(res) -> str:
    """What the slope at the printed switch means, from the measured d mu/d lambda."""
    paper = next((c.switch for c in res.cases if c.case.name == "paper" and c.switch), None)
    if paper is None:
        return ""
    slope = fmt(paper.dmu_dlam, 3)
    where = ("zero there (the peak of the plant's curve)" if abs(paper.dmu_dlam) < 1e-6 else
             f"{slope} on this plant's curve (the controller's lambda_opt is the nominal "
             "model's peak, not this plant's)")
    stable = ("unstable before any delay is added" if paper.abscissa > 0 else
              "stable without delay")
    return (f"Eq (75) as printed switches to the cruise law at lambda = lambda_opt of the "
            f"controller's model, where the adhesion slope d mu/d lambda is {where}. The "
            "synthesised K (k2 > 0, positive feedback on lambda_e) relies on the restoring "
            "term d2 of the cruise linearisation at lambda_d, which the slope there sets; "
            f"the frozen loop at the switch has delay-free spectral abscissa "
            f"{fmt(paper.abscissa, 3)} 1/s: {stable}.")


def _convergence_section(res, spec) -> str:
    levels = [CaseLevels(c.case.name, c.metrics_coarse, c.metrics,
                         None if c.quarter is None else c.quarter[0],
                         c.converged if c.quarter is None
                         else {k: k not in c.unconverged for k in _LABELS}) for c in res.cases]
    return case_convergence_section(levels, _LABELS, res.dt, spec.conv_rtol, P_MIN)


def _montecarlo_section(design, mc, halving=None) -> str:
    ms = design.spec.montecarlo
    rng = lambda lo_hi, sig=3: f"[{fmt(lo_hi[0], sig)}, {fmt(lo_hi[1], sig)}]"
    rows = [["plant mass / nominal", rng(ms.mass)],
            ["adhesion s (a, b, c = wet + s (dry - wet))", rng(ms.adhesion)
             + f"; wet a, b, c = {fmt(ms.wet['a'])}, {fmt(ms.wet['b'])}, {fmt(ms.wet['c'])}"],
            ["true input delay h (s)", rng(ms.h, 4) + " (the predictor keeps "
             + fmt(design.spec.scenario["h"], 4) + " s)"],
            ["v(0) (m/s)", rng(ms.v0)]] + _perturbation_rows(ms, rng)
    return WORDS.section(
        mc, heading="Monte Carlo robustness (reduced sample)", intro=(
            f"{mc.n} runs of case `{ms.case}` with seed {ms.seed} at dt = "
            f"{fmt(ms.dt or design.spec.dt)} s (the `[montecarlo]` step): a reduced sample of the "
            f"`workbench sweep designs/{design.name}.toml --samples N --seed {ms.seed}` study, "
            f"with the same sampler (run i has the same draws for every N, so these are the first {mc.n} runs of "
            "that study; each run of a batch follows its single-run trajectory). The claims "
            "`mc-*-vs-full` compare "
            "these fractions with the full 1000-run sweep. Draws, uniform and independent; the "
            f"controller keeps the nominal {design.spec.rail}-rail model and the design's h"
            + (":" if ms.perturb is None else ". Perturbations sampled as well (`[montecarlo]`; "
               "each a function of (seed, run index) only, by the counter-based generator of "
               "`workbench/sim/counter_rng.py`):")), draws=rows, summary_note=(
            "Summary statistics (3 significant digits; `lam_max_over_opt` is the max creep "
            "ratio in traction over the sample's own lambda_opt, not given for a run that diverged "
            "in traction (its max is where the divergence test fired); `omega3_after_brake` is "
            "t_brake to omega <= 3 rad/s, the end of the creep-controlled braking (the paper's "
            "'about 350 s'), finite for the runs that get there. The time to v <= v_stop is not "
            "given per run: after omega <= 3 rad/s the train coasts on running resistance, "
            "~46 s per m/s of speed left when the creep is released, and that release, a "
            "transient at dt |J| ~ 40, is not resolved by the fixed step on mismatched plants "
            "(in the halving check dt/2 moved it by up to 13 s); whether a run stops is the "
            "`not stopped` row):"),
        notes=("The rates of the table with their intervals (the claims `mc-*-vs-full` and "
               "`mc-perturbations-raise-divergence` compare these intervals with full sweeps).",
               "By adhesion (s = 0 wet, s = 1 dry):\n\n" + binned_fraction_table(
                   "adhesion s", mc.samples["adhesion"], *ms.adhesion, 4,
                   {"diverged": mc.violations["diverged"],
                    "above lambda_opt": mc.violations["above_lambda_opt"]})),
        halving=halving, samples=ms.samples)


def _perturbation_rows(ms, rng) -> list[list[str]]:
    """Rows of the Monte Carlo table for the sampled perturbations (none when
    the design samples none)."""
    pt = ms.perturb
    if pt is None:
        return []
    src, rows = dict(pt.sources), []
    if pt.noisy:
        rows.append(["measurement noise on v, omega (the controller's inputs; its lambda is "
                     "computed from them; the plant is unaffected)",
                     f"sd {fmt(pt.noise_v)} m/s, {fmt(pt.noise_omega)} rad/s, new values every "
                     f"dt = {fmt(ms.dt)} s (sum of four uniforms, unit variance) — "
                     + "; ".join(src[k] for k in ("noise_v", "noise_omega") if k in src)])
    if pt.gradient is not None:
        rows.append(["gradient profile (per mille, uphill positive; a force m g grade on the "
                     "train in the sympy model's v' and lambda')",
                     f"{rng(pt.gradient)}, uniform per {fmt(pt.segment)} m segment of the "
                     f"distance run — {src['gradient']}"])
    if pt.delay_period is not None:
        rows.append(["true input delay h(t) (s), varying",
                     f"triangle wave over the `h` range {rng(ms.h, 4)}, inside the interval "
                     "[0, h_certified] the cruise synthesis certifies (scenario table); "
                     f"period {rng(pt.delay_period)} s and phase uniform per run (the constant "
                     f"h draw above is not used) — {src['delay_variation']}"])
    return rows


def _numerics_section(with_montecarlo: bool, rail: str) -> str:
    """Appendix: how the runs are integrated. Measurements behind these
    choices are re-run by ``benchmarks/mesh.py`` and ``benchmarks/simulate.py``,
    not typed here."""
    return (
        "## Appendix: numerics\n\n"
        "* Plant: v by explicit Euler; the creep ratio, stiff at low speed "
        "(d lambda'/d lambda ~ -m g r^2 mu'/(J v), time constant ~ v/4000 s), by the "
        "exponential Euler step with the sympy Jacobian, stable for any step; a step that "
        f"would move the creep ratio by more than {fmt(MAX_DLAMBDA)} is halved (up to "
        f"{MAX_HALVINGS} times), since the "
        "adhesion curve is far from linear over such a change.\n"
        "* Delay: exact average of the delayed zero-order-hold input over each step "
        "(`workbench/sim/history.py`).\n"
        "* Predictor (eq 2): the phase's model run from x(t) through the inputs of the last h "
        "seconds ('rollout'). The literal recursive form (summing f of past predictions) has "
        "error dynamics e(t) = ∫ J e(s) ds over [t - h, t], neutral type, with J the stiff "
        "creep-ratio Jacobian; where a design has a case with `predictor = \"recursive\"` "
        "the tables above show what it does.\n"
        "* Sampling: the controller runs every step. A torque held for one step moves the "
        "stiff creep ratio to its quasi-steady value, so the printed law held constant "
        "realises its rate only for dt |J| << 1 (at 3 m/s, |J| ~ 1000/s). Each law is held "
        "as the torque that moves the exponential-Euler creep ratio by dt times the rate "
        "the continuous law asks for; it equals the printed law when dt |J| -> 0 (with the "
        "printed value held, the time to cruise moves with the step).\n"
        "* Model mismatch in the hold: the plant's creep-ratio rate is the model's plus a "
        "mismatch delta (mass, adhesion, true delay). Scaling only the model's rate by "
        "1/phi1(dt J) leaves delta scaled by phi1(dt J) = 1 + dt J/2 + ..., which moves the "
        "loop's fixed points by O(dt) (with a mismatched plant mass, v - v_d at t_brake "
        "then moved with each halving of the step). The hold therefore also realises an estimate of "
        "delta from the last step (the measured lambda against the model's step under the "
        "input the controller believes applied, filtered over `observer_tau`), carried to t + h for "
        "the predictor (delta e^{hJ}); its fixed points are the continuous loop's. It is not "
        "used in braking.\n"
        "* Phase switches use measured states; stops at v <= v_stop. A run ends as diverged "
        f"when |lambda| >= {fmt(ControllerSettings.lam_diverged)} (spin or lock), when a law "
        "commands more than `torque_range` "
        "times the peak adhesion torque mu(lambda_opt) m g r (no drive or brake delivers it; "
        "e.g. law (69) on the traction side, whose e^{b lambda} terms blow up: without this "
        "test the next steps apply torques orders of magnitude beyond any drive or brake and "
        "the creep ratio jumps "
        "to whichever side the overflow throws it, a different side for each step size), "
        f"or when a plant step cannot be resolved (a sub-step of dt/{2 ** MAX_HALVINGS} still "
        f"moves lambda by more than {fmt(MAX_DLAMBDA)}). The extremum of lambda over the phase "
        "a run diverged in is where the test fired, not a property of the run: the tables show '—' for it.\n"
        "* Refined mesh for the cases without the predictor (`mesh_courant`, `mesh_levels` "
        "in `[numerics]`): the step is dt / 2^k, k <= mesh_levels the smallest level with "
        "step x S/v <= mesh_courant, S/v = m g r^2 mu'(0) / (J v) the fastest creep-ratio "
        "rate; dt/2 halves every step of the mesh. Why: without "
        "the predictor the loop at low speed is close to neutral (lambda' ~ J lambda - "
        "(J + k_ac) lambda(t - h): roots decay at only (1/h) ln(|J|/|J + k_ac|) at "
        "low speed), so features of width ~1/|J| set at the start persist for seconds; the "
        "exponential step keeps them stable but does not resolve them, and on the fixed step "
        "such a run's max creep ratio in traction converges only at first order. "
        "With the predictor, plant and rollout share one discretisation and the fixed step "
        "converges: a refined mesh (rollout on the mesh too) gives the same metrics at many "
        "times the cost, while refining the plant but not the rollout is inconsistent "
        "(`benchmarks/mesh.py` re-runs these comparisons and prints them).\n"
        "* Monte Carlo robustness (mass, adhesion between the wet and dry curves, true delay, "
        f"initial speed; the controller keeps the nominal {rail}-rail model) is run by "
        "`workbench sweep DESIGN --samples N --seed S --figure PNG`"
        + (", the runs of a chunk as one batch (arrays) at the `[montecarlo]` step; the "
           "reduced sample above is run with this report, and its first runs again at that "
           "step and its half (the step-size check of the Monte Carlo section)."
           if with_montecarlo else ", outside this report."))
