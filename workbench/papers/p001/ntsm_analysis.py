"""Paper 001's NTSM platoon: what its design (kind ``platoon``,
``designs/platoon-ntsm-001.toml``, ``[analysis] module = "p001.ntsm_analysis"``)
cannot express in its tables.

The laws (eq 13, the PD baselines, the NTSM's linear member), the leader's
manoeuvre, the link, actuator and emergency, and the reaching check against
eq 22 are all written in the design file and run by the general kind
(:mod:`workbench.kinds.platoon`). What stays here, and why:

* the conditions of eqs 10-12 on the gains (a, b, alpha, xi positive odd,
  1 < b/a < 2, 0 < alpha/xi < 1): a property of the NTSM family, not of an
  expression (:meth:`workbench.controllers.ntsm.NTSMGains.problems`);
* why eq 13 has no linearisation at e = e' = 0 (its smallest power, the jump of
  its switching term, its only linear "spring"): an argument about the law's
  structure, with the quantities ``delay_margin.linearisable``,
  ``delay_margin.lowest_power`` and ``delay_margin.spring``;
* the report's wording about the paper: eq 13 and eq 22 typeset, the fair
  baseline comparison of issue 20, the NTSM's delay-margin discussion.

References
----------
.. [001] Fan L., "Virtual formation train tracking control strategy based on
   sliding mode control", Urban Mass Transit 2024(10), eqs 7-22.
"""
from __future__ import annotations

from ...controllers.ntsm import NTSMGains
from ...errors import DesignError
from ...features.quantities import Declared
from ...report.display_math import display_math
from ...report.markdown import fmt

__all__ = ["PLATOON_ANALYSIS", "NTSMAnalysis"]

#: The [constants] that hold eq 13's gains.
GAINS = ("beta", "a", "b", "j", "k", "alpha", "xi")

LAW = display_math([
    r"""e_i = x_{i-1} - x_i - D, \qquad s_i = e_i + \tfrac{1}{\beta}\,\dot e_i^{\,b/a}
\qquad \text{(eqs 7, 10)}""",
    r"""u_i = \underbrace{c_0 + c_1 v_i + c_2 v_i^2 + m g \sin\varphi}_{u_1}
+ \underbrace{\tfrac{\beta a m}{b}\,\dot e_i^{\,2-b/a}}_{u_2}
+ \underbrace{\tfrac{\beta a m}{b}\,(j s_i + k s_i^{\alpha/\xi})}_{u_3}
+ \underbrace{(G_w + G_d)\operatorname{sign}(s_i) + m\dot v_{i-1}}_{u_4}
\qquad \text{(eq 13)}""",
    r"""t_f - t_e = \frac{b}{b-a}\,\beta^{-a/b}\,|e_i(t_e)|^{1-a/b} \qquad \text{(eq 22)}""",
])


def _c(spec, name: str) -> float:
    return spec.constants[name].value


def _lowest_power(g: NTSMGains) -> float:
    """The smallest power of eq 13 near e = e' = 0 (below 1: no linearisation)."""
    return min(2.0 - g.b / g.a, g.alpha / g.xi)


def _spring(g: NTSMGains) -> float:
    """The only linear term of eq 13: e'' = -(beta a j / b) e (1/s^2)."""
    return g.beta * g.a * g.j / g.b


class NTSMAnalysis:
    """Paper 001's part of a ``platoon`` design (see the module docstring)."""

    def load(self, root, spec) -> NTSMGains:
        g = NTSMGains(*spec.constant_values(GAINS + ("kp", "kd", "kp_ff", "kd_ff"), (
            "eq 13's gains and the PD gains as [constants] (p001.ntsm_analysis)"))[:len(GAINS)])
        bad = g.problems()
        if bad:
            name, value, expected = bad[0]
            raise DesignError(spec.path, f"constants.{name}.value", value, expected)
        return g

    #: Eq 13's delay-margin argument as claimable quantities (read by the
    #: platoon kind from its result ``r``, which holds the spec).
    QUANTITIES = (
        Declared("delay_margin.linearisable", "", lambda r: "yes" if _lowest_power(
            r.spec.analysis_spec) >= 1.0 and r.spec.G_w + r.spec.G_d == 0.0 else "no"),
        Declared("delay_margin.lowest_power", "1", lambda r: _lowest_power(r.spec.analysis_spec)),
        Declared("delay_margin.spring", "1/s^2", lambda r: _spring(r.spec.analysis_spec)),
    )

    # -- the report's paper wording (hooks of workbench.kinds.platoon.render) --------
    def problem_note(self, spec, res) -> str:
        from ...kinds.platoon.render import spread
        g = spec.analysis_spec
        return ("**Ours, not the paper's** (paper 001 gives none of them): true trains differ "
                + spread(spec) + " NTSM: "
                f"β = {fmt(g.beta)}, a = {g.a}, b = {g.b}, j = {fmt(g.j)}, k = {fmt(g.k)}, "
                f"α = {g.alpha}, ξ = {g.xi}. PD: kp = {fmt(_c(spec, 'kp'))} 1/s², kd = "
                f"{fmt(_c(spec, 'kd'))} 1/s.")

    def law_section(self, spec, res) -> str:
        return (
            "## Control law\n\n" + LAW
            + "\n\nFractional powers of odd ratios are the real odd roots: sign-preserving "
            "sig(x)^r = sign(x)|x|^r for b/a, 2 − b/a and α/ξ (odd numerators), and "
            "|ė|^(b/a−1) ≥ 0 for b/a − 1 = (b − a)/a (even numerator), as the paper's proof "
            "uses. The predecessor acceleration in u4 is the one measured at the previous step "
            "(as communicated). The **PD baseline** is u = u1 + m(kp e + kd ė): constant "
            "spacing, resistance feed-forward, but no predecessor acceleration. The **fair "
            "baseline**, PD + feed-forward, is u = u1 + m(kp e + kd ė + v̇_{i−1}) with the same "
            f"communicated acceleration as u4 (kp = {fmt(_c(spec, 'kp_ff'))} 1/s², kd = "
            f"{fmt(_c(spec, 'kd_ff'))} 1/s): the NTSM's information without its nonlinear "
            "feedback and switching.")

    #: Fixed texts of three hooks (a hook may be a ``str``).
    chatter_note = ("The NTSM's spacing error at exact spacing is drawn as its worst |e| per "
                    "follower, not as a trace: sampled at T the sliding mode chatters, and the "
                    "sub-millimetre trace moves by about 1 % when the inputs move by 3 ulp (the "
                    "last-bit perturbation test), so only its maximum is a result.\n\n")
    bound_note = "eq 6 assumes it stays below G_w + G_d"
    realism_preface = "Paper 001 has no communication, actuator or emergency. "

    def comparison(self, spec, res) -> str:
        q = {k: max(res.metrics[k].max_abs_e) for k in ("ntsm", "pd", "pd_ff")}
        return (
            "### The fair baseline\n\nWorst spacing error over the run, paper's set-up: NTSM "
            f"{fmt(q['ntsm'], 3)} m, PD {fmt(q['pd'], 3)} m, PD + feed-forward "
            f"{fmt(q['pd_ff'], 3)} m. The NTSM beats the PD {fmt(q['pd'] / q['ntsm'], 5)} "
            "times, but feeding the predecessor's acceleration forward alone cuts the PD's "
            f"error {fmt(q['pd'] / q['pd_ff'], 3)} times: against the fair baseline the NTSM's "
            f"advantage is {fmt(q['pd_ff'] / q['ntsm'], 3)} times. Under the realistic link "
            "and the leader's emergency brake (below) the ranking of NTSM and PD + "
            "feed-forward depends on the link.")

    def reaching_text(self, spec, res) -> tuple[str, str]:
        rc = spec.reaching
        e0 = spec.run_spec(rc.run).initial_errors
        return (
            "NTSM run started with spacing errors "
            f"{', '.join(fmt(x) for x in e0)} m (gaps too large; trains at rest). "
            f"t_e: first |s| ≤ {fmt(rc.reach_band)} m. Eq 22 gives the sliding time to e = 0; "
            f"integrating the same sliding law only down to the band |e| = "
            f"{fmt(rc.converge_band)} m gives the time the measurement can be compared with; "
            "measured: from t_e until |e| stays inside the band.",
            "Sampled at T, the sliding mode is a quasi-sliding one: after t_e, |s| "
            "chatters in a band of about a centimetre (lower panel of the figure) instead of "
            "staying at 0, yet e follows the sliding law of eq 21 closely enough for eq 22's "
            "time to be met.")

    def margin_section(self, spec, res) -> str:
        from ...kinds.platoon.realism_render import linear_law_math, margin_body
        rz = res.realism
        m, g = rz.margin, spec.analysis_spec
        f = m.factors
        return (
            "## Delay margin of the NTSM\n\n"
            "**Eq 13 has no linearisation at e = ė = 0.** Its powers 2 − b/a = "
            f"{fmt(2 - g.b / g.a, 3)} and α/ξ = {fmt(g.alpha / g.xi, 3)} are below 1, so "
            "ė^(2−b/a) and s^(α/ξ) have infinite slope at 0, and (G_w + G_d) sign(s) jumps "
            f"by {fmt(2 * (spec.G_w + spec.G_d))} N there; only e enters s to first order "
            "(ė^(b/a) has zero slope). The Lipschitz part linearises to "
            f"ë = −(βaj/b) e = −{fmt(_spring(g), 4)} e: a spring without "
            "damping, not asymptotically stable, so it has no delay margin at all. The "
            "surrogate taken here is the NTSM family's **linear member**: b = a and α = ξ "
            "(every power 1), without the switching term, i.e. the linear sliding-mode law on "
            "s = e + ė/β with ṡ = −(j + k) s:\n\n"
            + linear_law_math(m, "\\beta(j + k) = ", "\\beta + j + k = ") + "\n\n"
            + margin_body(spec, rz)
            + "\n\nThe linear member loses stability where the exact margin says (its first "
            f"follower's oscillation jumps between {fmt(f[1])} h* and "
            f"{fmt(f[2])} h*; the actuator limits then "
            "bound it). The NTSM has no threshold: its gain at ė = 0 is infinite, so with any "
            "delay in the loop it settles into an oscillation whose size grows with the delay. "
            "Followers further back oscillate more (their predecessor's oscillating "
            "acceleration is fed forward). The NTSM's \"any follower\" column has 2 digits: "
            "that chattering oscillation moves in its fourth digit when the inputs move by a "
            "few ulp.\n\n![delay sweep]({figdir}/delay-sweep.png)")


PLATOON_ANALYSIS = NTSMAnalysis()
