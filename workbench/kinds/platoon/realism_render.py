"""Markdown and figures of the realistic platoon (pure rendering of
:class:`~workbench.kinds.platoon.realism.Realism`)."""
from __future__ import annotations

import numpy as np

from ...features.reproducible import window
from ...report.markdown import Figure, fmt, latex_matrix, md_table
from .realism import CASES

__all__ = ["figures", "gap_section", "linear_law_math", "margin_body", "margin_section",
           "scenario_section"]

WORDS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six"}
CASE_LABEL = {"constant": "constant delay", "random": "random delay + loss"}
ENVELOPE = r"""$$
d_\mathrm{safe} = s_0 + v_f\,\tau_r + \max\!\Big(0,\ \frac{v_f^2}{2b} - \frac{v_p^2}{2b}\Big)
$$"""


def _q(q, digits: int = 4) -> str:
    return f"{fmt(q.value, digits)} {q.unit}"


def _labels(spec) -> dict:
    return {x.name: x.label for x in spec.laws}


def scenario_section(spec, rz, preface: str = "") -> str:
    L, A, E = spec.link, spec.actuator, spec.emergency
    rows = [["V2V packet period", _q(L.period), L.period.source],
            ["V2V delay (constant case; floor of the random case)", _q(L.delay), L.delay.source],
            ["random part per packet (random case)",
             f"{L.jitter}, scale {_q(L.jitter_scale)}", L.jitter_scale.source],
            ["packet loss (random case)", f"{fmt(L.loss * 100)} %, Bernoulli, seed {L.seed}",
             L.loss_source],
            ["follower's own position and speed", L.own_state,
             "measured now (\"stamped\": at the packet's time stamp)"],
            ["actuator lag (first order, every train)", _q(A.lag), A.lag.source],
            ["traction limit (force / nominal mass)", _q(A.traction), A.traction.source],
            ["brake limit (force / nominal mass)", _q(A.brake), A.brake.source],
            ["leader's emergency brake from", _q(E.time), E.time.source],
            ["envelope: reaction time τ_r", _q(E.reaction), E.reaction.source],
            ["envelope: standstill margin s₀", _q(E.margin), E.margin.source]]
    st = rz.links
    ages = "; ".join(f"{CASE_LABEL[c]}: mean {fmt(st[c].mean_age, 3)} s, largest "
                     f"{fmt(st[c].max_age, 3)} s, {fmt(st[c].lost * 100, 3)} % of packets lost"
                     for c in CASES)
    return (
        "## Realistic scenario: V2V link, actuator, emergency braking\n\n"
        + preface + "Here every follower knows its "
        "predecessor only through a train-to-train (V2V) link: the predecessor sends its "
        "position, speed and last measured acceleration every packet period; a packet arrives "
        "after its delay (rounded up to whole steps) or is lost, and the follower holds the "
        "newest packet it has (older late packets are ignored). Every train's command passes "
        "a first-order lag with traction and brake force limits (the true masses differ "
        f"by up to ±{fmt(spec.mass_spread * 100)} %, so the limits give slightly different "
        "decelerations). The leader runs its normal profile and, at the emergency time, "
        "commands its full brake to standstill. All randomness is seeded (the link's delays "
        "and losses on their own streams): the same design gives the same numbers.\n\n"
        + md_table(["parameter", "value", "source"], rows, "lll")
        + f"\n\nAge of the predecessor data the followers hold — {ages}. With the own state "
        "measured now, a follower regulates the gap to where its predecessor *was*: in "
        "cruise the true gap exceeds D by about v × age (≈ "
        f"{fmt(spec.v_cruise.value * st['constant'].mean_age, 2)} m at "
        f"{fmt(spec.v_cruise.value * 3.6, 3)} km/h), for every law alike.\n\n"
        "The gap is judged against the safe braking-distance envelope of virtual coupling "
        "(relative braking distance: the follower's reaction distance plus its braking "
        "distance minus the predecessor's, plus a standstill margin), with b the brake "
        "limit:\n\n" + ENVELOPE)


def _on_steps(t: float, T: float) -> str:
    """A time on the step grid T, printed to the step: 2.85 s, not 2.8 or 2.9
    by the last bit of 2.85 (a sample time at a rounding boundary)."""
    return fmt(round(t / T) * T, 6)


def gap_section(spec, rz) -> str:
    LABEL, CONTROLLERS = _labels(spec), rz.laws
    rows = []
    for law in CONTROLLERS:
        row = [LABEL[law]]
        for case in CASES:
            e = rz.emergency[case, law]
            row += [f"**{e.min_gap:.1f}**", f"{e.min_margin:.1f}",
                    f"{_on_steps(e.t_min_margin - rz.t_emergency, spec.T)} s, train {e.train_min_margin}"]
        row.append(" / ".join(fmt(rz.emergency[c, law].cruise_abs_e, 3) for c in CASES))
        rows.append(row)
    head = ["law"]
    for case in CASES:
        head += [f"{CASE_LABEL[case]}: min gap (m)", "min (gap − d_safe) (m)", "where"]
    head.append("cruise max |e| before (m), constant / random")
    stopped = all(e.stopped for e in rz.emergency.values())
    worst = {law: min((rz.emergency[c, law] for c in CASES), key=lambda e: e.min_gap)
             for law in CONTROLLERS}
    low = min((rz.emergency[c, law] for c in CASES for law in CONTROLLERS),
              key=lambda e: e.min_margin)
    low_law = next(law for (c, law), e in rz.emergency.items() if e is low)
    verdict = ("every gap stays above d_safe" if low.min_margin >= 0 else
               "**the envelope is violated**")
    summary = ("**Minimum gap under the emergency brake with V2V delay (worse of the two link "
               "cases): " + ", ".join(f"{LABEL[law]} {e.min_gap:.1f} m"
                                      for law, e in worst.items())
               + f"**; {verdict} (smallest gap − d_safe: {low.min_margin:.1f} m, "
               f"{LABEL[low_law]}).")
    return (
        "### Minimum gap under the leader's emergency brake with V2V delay\n\n"
        + summary + "\n\n"
        f"From t = {fmt(rz.t_emergency)} s (leader at {fmt(spec.v_cruise.value * 3.6, 3)} "
        f"km/h, nominal gap D = {fmt(spec.D.value)} m) to {fmt(rz.horizon, 4)} s; "
        + ("every train is at rest at the end. " if stopped else
           "**not every train is at rest at the end.** ")
        + "Smallest over the followers and over the time after the emergency brake; "
        "\"where\": time after the brake and follower of the smallest gap − d_safe. The "
        "random case is one seeded realisation of the link, shared by the "
        f"{WORDS.get(len(CONTROLLERS), len(CONTROLLERS))} laws.\n\n"
        + md_table(head, rows, "lrrlrrlr")
        + "\n\n![emergency braking]({figdir}/emergency-gaps.png)")


def margin_body(spec, rz) -> str:
    """Where the delay enters, the exact margins, and the sweep (the general part
    of the delay-margin section)."""
    m = rz.margin
    LABEL = _labels(spec)
    chatters = {r.law for r in spec.runs if r.chatters}
    agree, diff = m.agreement
    rows = [["Chen-Gu-Nett eigenvalues (`delay_margin_eig`)", fmt(m.eig.h, 4),
             fmt(m.eig.omega, 4), m.eig.reason],
            ["python-control crossovers (`delay_margin_siso`)", fmt(m.siso.h, 4),
             fmt(m.siso.omega, 4), m.siso.reason],
            ["own state current (the simulated arrangement; A_d = 0)", fmt(m.current.h),
             fmt(m.current.omega), m.current.reason]]
    srows = []
    for r in m.sweep:
        srows.append([LABEL[r.law], "design's V2V delay" if r.factor is None else fmt(r.factor),
                      fmt(r.h, 3), fmt(r.h / m.eig.h, 3), fmt(r.amp_first, 3),
                      fmt(r.amp_worst, 2 if r.law in chatters else 3),
                      fmt(r.saturated * 100, 3)])
    lag = spec.actuator.lag.value
    state = "(e, ė, a_f)" if lag > 0 else "(e, ė)"
    return (
        "**Where the V2V delay enters.** With the follower's own position and speed measured "
        "now (the simulated arrangement), the delay acts only on the predecessor's data: the "
        "follower's own loop has no delayed term, the platoon is a cascade of delay-free "
        "loops, and the margin is infinite — the delay postpones the response to the "
        "leader (which the emergency runs above measure) but cannot destabilise. If the "
        "follower takes its gap and relative speed at the packet's time stamp (own state "
        "\"stamped\", which removes the v × age offset), the whole law acts on data h old. "
        f"With the {fmt(lag)} s actuator lag, a_f' = (c(t − h) − a_f)/τ, ë = −a_f, state "
        f"x = {state}:\n\n"
        f"$$\nA = {latex_matrix(m.A)},\\quad B = {latex_matrix(m.B)},\\quad "
        f"K = {latex_matrix(m.K)},\\qquad x' = A x + B K x(t - h)\n$$\n\n"
        + md_table(["exact method", "h* (s)", "ω at h* (rad/s)", "reason"], rows, "lrrl")
        + f"\n\nThe two methods {agree.value}"
        + (f" (relative difference below 1e-9)" if diff is not None and diff < 1e-9 else
           f" (relative difference {fmt(diff, 2)})")
        + f". **h\\* = {fmt(m.eig.h, 4)} s** against the design's V2V delay of "
        f"{fmt(rz.delay)} s.\n\n"
        "**Simulated behaviour with the delay in the loop** (own state stamped, a packet every "
        "step, no loss, the design's actuator with its limits; the zero-order hold adds about "
        f"T/2 = {fmt(spec.T / 2)} s). Largest |e| from {fmt(m.window[0], 3)} to "
        f"{fmt(m.window[1], 3)} s of the normal run (cruise):\n\n"
        + md_table(["law", "asked h / h*", "simulated h (s)", "h / h*",
                    "first follower max |e| (m)", "any follower max |e| (m)",
                    "first follower saturated (% of steps)"], srows, "llrrrrr"))


def linear_law_math(m, k_e_form: str = "", k_d_form: str = "") -> str:
    """The display equation of the linear law of a delay margin ``m`` (its
    gains k_e, k_d), each gain after its symbolic form (e.g. ``"\\beta(j + k) = "``)."""
    return ("$$\n(u - u_1)/m = \\dot v_{i-1} + k_e e + k_d \\dot e, \\qquad k_e = "
            f"{k_e_form}{fmt(m.k_e, 4)}\\ \\mathrm{{s^{{-2}}}},\\quad k_d = {k_d_form}"
            f"{fmt(m.k_d, 4)}\\ \\mathrm{{s^{{-1}}}}\n$$")


def margin_section(spec, rz) -> str:
    """The general delay-margin section: the linear law's gains, then :func:`margin_body`."""
    m = rz.margin
    return (
        "## Delay margin\n\n"
        f"The exact margin is computed on the linear law '{_labels(spec)[m.law]}':\n\n"
        + linear_law_math(m) + "\n\n" + margin_body(spec, rz)
        + "\n\n![delay sweep]({figdir}/delay-sweep.png)")


# No tight_layout in the drawing functions: laid out before the data are snapped
# (workbench.report.figures), the axes positions keep last-bit differences of the
# unsnapped limits, and every line moves by a fraction of a subpixel; figure_png
# lays out after snapping.
def figures(spec, rz) -> tuple[Figure, ...]:
    figs = (Figure("emergency-gaps", "Gaps and the safe braking-distance envelope under the "
                   "leader's emergency brake.", lambda fig: _plot_gaps(fig, spec, rz),
                   (8.0, 7.5)),)
    if rz.margin is None:
        return figs
    return figs + (Figure("delay-sweep", "First follower's spacing error with the delay in the "
                          "loop.", lambda fig: _plot_sweep(fig, spec, rz), (7.0, 5.0)),)


def _plot_gaps(fig, spec, rz):
    LABEL, CONTROLLERS = _labels(spec), rz.laws
    axes = fig.subplots(len(CONTROLLERS), len(CASES), sharex=True, sharey=True, squeeze=False)
    t0 = rz.t_emergency
    for j, case in enumerate(CASES):
        for i, law in enumerate(CONTROLLERS):
            ax = axes[i, j]
            e = rz.emergency[case, law]
            r = e.run
            keep = window(r.t, t0 - 5.0, t0 + 35.0)   # ends on sample times
            for f in range(r.gap.shape[1]):
                ax.plot(r.t[keep] - t0, r.gap[keep, f], color=f"C{f}", lw=1.2,
                        label=f"gap, train {f + 2}")
                ax.plot(r.t[keep] - t0, e.envelope[keep, f], color=f"C{f}", lw=0.9, ls="--",
                        label=f"d_safe, train {f + 2}")
            ax.axhline(0.0, color="k", lw=0.5)
            ax.set_title(f"{LABEL[law]}, {CASE_LABEL[case]}: min gap {e.min_gap:.1f} m",
                         fontsize=8)
            if j == 0:
                ax.set_ylabel("gap (m)")
            if i == len(CONTROLLERS) - 1:
                ax.set_xlabel("time after the emergency brake (s)")
    axes[0, 0].legend(fontsize=6, ncol=2, loc="center right")


def _plot_sweep(fig, spec, rz):
    LABEL = _labels(spec)
    m = rz.margin
    laws = sorted({r.law for r in m.sweep}, key=lambda x: (x != m.law, spec.margin.sweep.index(x)))
    axes = fig.subplots(len(laws), 1, sharex=True)
    for ax, law in zip(np.atleast_1d(axes), laws):
        for r in (r for r in m.sweep if r.law == law):
            ax.plot(r.trace[:, 0], r.trace[:, 1] * 1000.0, lw=0.8,
                    label=f"h = {r.h:.3g} s ({r.h / m.eig.h:.2f} h*)")
        ax.set_ylabel("e, first follower (mm)")
        ax.set_title(f"{LABEL[law]}, delay in the loop; h* = {m.eig.h:.4g} s ({spec.margin.short})",
                     fontsize=9)
        ax.legend(fontsize=7, ncol=2)
    np.atleast_1d(axes)[-1].set_xlabel("time (s)")
