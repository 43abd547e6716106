"""Markdown and figures of the ``antiskid-cruise`` study (pure rendering)."""
from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ...plants.adhesion import adhesion_model
from ...report.markdown import Figure, Rendered, fmt, latex_matrix, md_table
from ...report.synthesis_text import (capped_text, closed_loop_eigs_text, exact_margin_text,
                                      recheck_table)


def _model_section() -> str:
    m = adhesion_model()
    y1, y2, y3 = m.traction
    z1, z2, z3 = m.braking
    lam = sp.Symbol(r"\lambda")
    ren = lambda e: sp.latex(e.subs(m.lam, lam))
    eqs = [
        r"\lambda = \frac{v_w - v}{\max(v_w, v)}, \quad v_w = \omega r \qquad \text{(eqs 4-5)}",
        r"\mu(\lambda) = " + ren(m.mu_traction) + r"\ (\lambda \ge 0), \qquad "
        r"\mu(\lambda) = " + ren(m.mu_braking) + r"\ (\lambda < 0) \qquad \text{(eq 6)}",
        r"m\dot v = \mu m g - f_r(v),\quad J\dot\omega = u(t-h) - \mu m g r - \zeta\omega,"
        r"\quad f_r = " + ren(m.f_r) + r" \qquad \text{(eqs 7, 9)}",
        r"\text{traction (eq 13): } \dot v = y_1,\ \dot\lambda = y_2 + y_3 u(t-h)",
        r"y_1 = " + ren(y1), r"y_2 = " + ren(y2), r"y_3 = " + ren(y3),
        r"\text{braking (eq 16): } \dot v = z_1,\ \dot\lambda = z_2 + z_3 u(t-h)",
        r"z_2 = " + ren(z2), r"z_3 = " + ren(z3),
    ]
    body = "\n\n".join(f"$$\n{e}\n$$" for e in eqs)
    return ("## Model (paper 003, eqs 4-16)\n\nRendered from the workbench's sympy model "
            "(`workbench/plants/adhesion.py`), the single source of every numeric function "
            "and Jacobian below.\n\n" + body)


def render(design, res) -> Rendered:
    spec = design.spec
    sections = []
    # -- problem --------------------------------------------------------------
    prow = [[f"`{k}`", fmt(q.value, 6), q.unit, _doc(k), q.source]
            for k, q in spec.params.items()]
    prow.append(["`v_d`", fmt(spec.v_d.value, 6), spec.v_d.unit, "cruise speed", spec.v_d.source])
    if spec.lambda_d_pinned:
        q = spec.lambda_d_pinned
        prow.append(["`lambda_d` (pinned)", fmt(q.value, 6), q.unit, "cruise creep ratio", q.source])
    sections.append(f"## Problem\n\nRail: **{spec.rail}**. Delay-bound synthesis for the cruise "
                    "error system of paper 003 (Theorem 1 with Remark 3, problem (60)).\n\n"
                    + md_table(["parameter", "value", "unit", "meaning", "source"], prow,
                               "lrlll"))
    sections.append(_model_section())
    # -- operating point ------------------------------------------------------
    lin = res.lin
    ev = np.linalg.eigvals(lin.A)
    op = md_table(["quantity", "value", "how"], [
        ["lambda_opt", fmt(res.lambda_opt, 5), "argmax mu (d mu/d lambda = 0)"],
        ["lambda_d (solved)", fmt(res.lambda_d_solved, 5), "root of y1(v_d, lambda) = 0 in (0, lambda_opt)"],
        ["lambda_d (used)", fmt(res.lambda_d_used, 5),
         "pinned by the design" if spec.lambda_d_pinned else "the solved value"],
        ["y1(v_d, lambda_d used)", (fmt(lin.y1_residual, 3) if abs(lin.y1_residual) > 1e-12
                                    else "0 (below 1e-12)") + " m/s²",
         "eq (25) holds exactly only when this is 0"],
    ], "lrl")
    co = md_table(["coefficient", "value"],
                  [[k, fmt(v, 5)] for k, v in lin.coefficients.items()], "lr")
    sections.append(
        "## Operating point and linearisation (eqs 17-32)\n\n" + op +
        "\n\nError system $\\dot E = A E + B\\,\\tilde u(t-h)$, $E = [v - v_d,\\ \\lambda - \\lambda_d]^T$:"
        f"\n\n$$\nA = {latex_matrix(lin.A, 5)}, \\qquad B = {latex_matrix(lin.B)}\n$$\n\n"
        f"Eigenvalues of $A$: {', '.join(fmt(complex(e).real, 4) for e in ev)} "
        "(the open loop is already stable).\n\n<details><summary>Taylor coefficients "
        "(eqs 18, 23)</summary>\n\n" + co + "\n\n</details>")
    # -- synthesis --------------------------------------------------------------
    rows = []
    st = spec.settings
    for r in res.rows:
        rows.append([fmt(r.eps), fmt(r.h_certified, 5), fmt(r.h_refuted, 5),
                     _gain(r.K, st.gain_digits), fmt(r.h_gain, 4),
                     exact_margin_text(r.exact), exact_margin_text(r.exact_siso), fmt(r.ratio, 3),
                     r.status.value])
    sections.append(
        "## Certified delay bounds (problem 60, cf. Table 3)\n\n"
        + md_table(["eps", "h_certified (s)", "h_refuted (s)", "K (canonical)",
                    "h certified by K (s)", "exact margin h* (s), eigenvalue",
                    "h*, python-control", "ratio h/h*", "status"], rows, "rrrlrrrrl")
        + "\n\n*h_certified*: the largest delay at which the LMI was solved to optimality **and** "
        "every block passed an independent numpy eigenvalue re-check with relative margin "
        f"{fmt(st.margin)} (smallest definiteness over the largest block size); *h_refuted*: the "
        "smallest delay at which the solver proved that no point of the criterion has that "
        "margin. The true LMI bound lies in between "
        f"(relative bracket width {fmt(st.rel_tol)}). Each certificate proves stability for "
        "every constant delay in [0, h] (the free-weighting LMI is affine in h with a "
        "positive semidefinite slope).\n\n"
        "*K (canonical)*: at the optimum the gain K = V L⁻¹ is not unique (L tends to a "
        "singular matrix and a whole face of points is optimal), so the gain a solver returns "
        "there depends on the machine. The gain reported, simulated and claimed is instead the "
        "one of the **minimum-norm certificate** at "
        f"{fmt(st.gain_fraction)} × h_certified (a projection onto a convex set: one solution), "
        f"rounded to {st.gain_digits} significant digits; *h certified by K* is what that "
        "rounded gain certifies on its own under the same LMI with V = K L fixed. *h\\**: the "
        "exact delay margin of x' = A x + B K x(t-h) with that gain, from two independent "
        "methods.\n\n"
        + _inf_note(res) + "\n\n" + recheck_table(res))
    # -- published comparison -----------------------------------------------------
    if res.published:
        prow = []
        for c in res.published:
            p = c.row
            prow.append([fmt(p.eps), fmt(p.h_m, 4), fmt(c.h_ours, 4),
                         "[" + ", ".join(fmt(k, 5) for k in p.K) + "]",
                         f"{fmt(c.h_paper_K, 4)}", fmt(c.eps_matching, 3),
                         exact_margin_text(c.exact_paper_K), p.source])
        sections.append(
            "## Comparison with the printed table\n\n"
            + md_table(["eps", "printed h_m (s)", "ours h_certified (s)", "printed K",
                        "printed K certifies (same LMI, s)", "eps giving printed h_m",
                        "h* with printed K (s)", "source"], prow, "rrrlrrrl")
            + "\n\nFor each printed row: the bound our certified bisection finds at the same "
            "eps; what the **printed gain** certifies under the very same criterion (V = K L "
            "fixed); the eps at which our bound would equal the printed value; and the exact "
            "margin of the loop closed with the printed gain. A printed bound below what its "
            "own gain certifies, or matched only at another eps, is evidence of a slip in the "
            "printed row, not of a looser criterion.")
    if res.tight:
        sections.append(_tight_section(res.tight, res.lin.A, res.lin.B))
    if res.other_gains:
        sections.append(other_gains_section(res.other_gains, spec, res.lin.A, res.lin.B))
    best = max((r for r in res.rows if r.K is not None), key=lambda r: r.h_certified,
               default=None)
    figs = (Figure("delay-bound-vs-eps",
                   "Certified bound and refuted bound against eps; printed values for comparison.",
                   lambda fig, res=res: _plot_bounds(fig, res)),)
    if best is not None:     # no row certified a gain (fuzz run 32: a = 2): no loop to draw
        figs += (Figure("loop", "Loop L(s) = -K (sI - A)^-1 B: Bode and Nyquist.",
                        lambda fig, res=res: _plot_loop(fig, res), (9.0, 3.6)),)
    text = ("## Figures\n\n![Certified bound vs eps](" + "{figdir}/delay-bound-vs-eps.png)\n\n"
            "Certified bound (filled) and refuted bound (open) per eps, with the printed "
            "values (crosses). " + ("The exact margin is infinite for every row, so it "
                                   "does not appear on the axis." if _all_inf(res) else ""))
    if best is not None:
        text += ("\n\n![Loop](" + "{figdir}/loop.png)\n\n"
                 f"Bode and Nyquist plots of L(s) = -K (sI - A)⁻¹ B with the canonical gain of "
                 f"eps = {fmt(best.eps)} (K = {_gain(best.K)}): a delay e^(-sh) only rotates "
                 "L(jω) by -ωh, so the loop can lose stability only at a frequency where "
                 "|L(jω)| = 1; "
                 + _gain_crossing_text(res.lin.A, res.lin.B, np.array([best.K]),
                                       best.exact is not None and math.isinf(best.exact.h)))
    if res.abscissa_vs_h:
        figs += (Figure("abscissa-vs-h", "Rightmost characteristic root against the delay.",
                        lambda fig, res=res: _plot_abscissa(fig, res)),)
        worst = max(a for _, a in res.abscissa_vs_h)
        text += ("\n\n![Spectral abscissa vs h](" + "{figdir}/abscissa-vs-h.png)\n\n"
                 "Spectral abscissa (real part of the rightmost root) of x' = A x + B K "
                 f"x(t − h) with the same gain, for h from {fmt(res.abscissa_vs_h[0][0], 3)} to "
                 f"{fmt(res.abscissa_vs_h[-1][0], 3)} s; largest value {fmt(worst, 3)} 1/s. "
                 + ("It stays negative: the loop is stable for every delay shown, as the "
                    "infinite exact margin says (no root ever reaches the imaginary axis)."
                    if worst < 0 and _all_inf(res) else
                    "A positive value is a delay at which the loop is unstable."))
    sections.append(text)
    return Rendered(tuple(sections), figs, ((OTHER_GAINS_QUANTITY, OTHER_GAINS_HEADING),))


OTHER_GAINS_HEADING = "Gains designed elsewhere, on this loop"
OTHER_GAINS_QUANTITY = "other_gains"


def other_gains_section(checks, spec, A, B) -> str:
    """``## Gains designed elsewhere, on this loop``: the ``[[other_gains]]``
    of a design (:mod:`workbench.papers.p003.antiskid_cruise_gains`) closed
    around this design's A, B."""
    k2_max = -(A[0, 0] + A[1, 1])     # with B = [0, 1]^T, trace(A + B K) < 0 is necessary
    above = sum(c.gain.K[1] >= k2_max for c in checks)
    trace = ("With B = [0, 1]ᵀ the gain adds to the second row of A, so stability needs "
             "trace(A + B K) = a11 + a22 + k2 < 0, i.e. k2 < "
             f"{fmt(k2_max, 3)} on this loop; {above} of the {len(checks)} gains have a "
             "larger k2. " if np.array_equal(np.ravel(B), [0.0, 1.0]) else "")
    rows = [[f"`{c.gain.name}`", _gain(c.gain.K, 5), c.gain.source,
             ", ".join(_eig_text(e) for e in c.eigenvalues if e.imag >= 0), fmt(c.abscissa, 3),
             "yes" if c.stable else "**no**", exact_margin_text(c.exact)] for c in checks]
    n_bad = sum(not c.stable for c in checks)
    verdict = (f"**{n_bad} of {len(checks)} gains leave this loop unstable even without "
               "delay**" if n_bad else f"All {len(checks)} gains stabilise this loop at h = 0")
    return (f"## {OTHER_GAINS_HEADING}\n\nGains designed for another loop (their source says "
            f"where), closed around this design's linearisation ({spec.rail} rail, v_d = "
            f"{fmt(spec.v_d.value)} m/s): eigenvalues of A + B K (the loop at h = 0) and the "
            "exact delay margin of x' = A x + B K x(t - h), computed without any LMI. "
            + verdict + ".\n\n"
            + md_table(["gain", "K", "source", "eigenvalues of A + B K (1/s)",
                        "rightmost real part (1/s)", "stable at h = 0", "exact margin h* (s)"],
                       rows, "lllllll")
            + "\n\n" + trace + "A gain with a positive rightmost root is no design for this loop: the error grows "
            "like e^(t Re s) from the moment the cruise law takes over, whatever the delay, so "
            "no delay bound of any criterion applies to it.")


def _eig_text(e: complex) -> str:
    if abs(e.imag) < 1e-9 * max(1.0, abs(e.real)):
        return fmt(e.real, 3)
    return f"{fmt(e.real, 3)} ± {fmt(abs(e.imag), 3)}j"


def _doc(k):
    from .antiskid_cruise import PARAM_DOC
    return PARAM_DOC.get(k, "")


def _all_inf(res) -> bool:
    return all(r.exact is not None and math.isinf(r.exact.h) for r in res.rows)


def _inf_note(res) -> str:
    if _all_inf(res):
        return ("**Every exact margin is infinite**: with each synthesised gain the characteristic "
                "equation det(sI − A − BK e^{−sh}) = 0 has no root on the imaginary axis for any "
                "h (no crossover: |K(jωI − A)⁻¹B| < 1 at all ω), so the closed loop is stable for "
                "every constant delay. The LMI bounds above are therefore not delay limits of "
                "the loop: they are where this particular Lyapunov-Krasovskii criterion stops "
                "being able to prove stability. A delay larger than h_certified is not shown "
                "dangerous by this table.")
    return ("Rows with a finite h* are real delay limits of the loop with that gain; the ratio "
            "h_certified / h* measures the conservatism of the criterion.")


def _plot_bounds(fig, res):
    ax = fig.add_subplot(111)
    e = [r.eps for r in res.rows]
    ax.plot(e, [r.h_certified for r in res.rows], "o-", color="C0", label="h_certified")
    ax.plot(e, [r.h_refuted if math.isfinite(r.h_refuted) else np.nan for r in res.rows],
            "o", mfc="none", color="C1", label="h_refuted")
    fin = [(r.eps, r.exact.h) for r in res.rows if r.exact and math.isfinite(r.exact.h)]
    if fin:
        ax.plot(*zip(*fin), "s--", color="C2", label="exact margin h*")
    if res.published:
        ax.plot([c.row.eps for c in res.published], [c.row.h_m for c in res.published], "x",
                color="C3", ms=8, label="printed h_m")
    if _all_inf(res):
        ax.text(0.98, 0.04, "exact margin h* = ∞ for every row", transform=ax.transAxes,
                ha="right", va="bottom", color="C2")
    ax.set_xlabel("eps (R = eps L)")
    ax.set_ylabel("delay bound (s)")
    ax.set_title("Problem (60): certified delay bound vs eps")
    ax.legend()


def _loop_response(A, B, K, w):
    """L(jω) = -K (jωI - A)^-1 B at the frequencies ``w`` (single input)."""
    n = A.shape[0]
    return np.array([-(np.atleast_2d(K) @ np.linalg.solve(1j * x * np.eye(n) - A, B))[0, 0]
                     for x in w])


def _gain_crossing_text(A, B, K, infinite: bool) -> str:
    """The largest |L(jω)| on the plotted grid (ω = 0 and 1e-4..1e3 rad/s)."""
    w = np.concatenate([[0.0], np.geomspace(1e-4, 1e3, 600)])
    peak = float(np.max(np.abs(_loop_response(A, B, K, w))))
    text = f"on the plotted frequencies max |L(jω)| = {fmt(peak, 3)}"
    if peak < 1 and infinite:
        return text + (", below 1, as the infinite exact margin (no gain crossing at all, "
                       "computed without this grid) requires.")
    return text + "."


def _plot_loop(fig, res):
    best = max((r for r in res.rows if r.K is not None), key=lambda r: r.h_certified)
    A, B = res.lin.A, res.lin.B
    w = np.geomspace(1e-4, 1e3, 600)
    L = _loop_response(A, B, np.array([best.K]), w)
    ax_m, ax_p, ax_n = fig.subplots(1, 3)
    ax_m.loglog(w, np.abs(L), color="C0")
    ax_m.axhline(1.0, color="k", lw=0.8, ls="--")
    ax_m.set_xlabel("ω (rad/s)")
    ax_m.set_ylabel("|L(jω)|")
    ax_p.semilogx(w, np.degrees(np.unwrap(np.angle(L))), color="C0")
    ax_p.set_xlabel("ω (rad/s)")
    ax_p.set_ylabel("arg L(jω) (deg)")
    ax_n.plot(L.real, L.imag, color="C0", label="ω > 0")
    ax_n.plot(L.real, -L.imag, color="C0", ls=":", label="ω < 0")
    ax_n.plot([-1], [0], "rx", label="-1")
    ax_n.set_xlabel("Re L")
    ax_n.set_ylabel("Im L")
    ax_n.legend(fontsize=7)
    fig.suptitle(f"Loop with the canonical gain of eps = {fmt(best.eps)}", fontsize=9)


def _plot_abscissa(fig, res):
    h, a = zip(*res.abscissa_vs_h)
    ax = fig.add_subplot(111)
    ax.semilogx(h, a, "o-", ms=3, color="C0", label="spectral abscissa")
    ax.axhline(0.0, color="k", lw=0.8)
    best = max((r for r in res.rows if r.K is not None), key=lambda r: r.h_certified)
    ax.axvline(best.h_certified, color="C1", ls="--", label="h certified (LMI)")
    ax.set_xlabel("constant delay h (s)")
    ax.set_ylabel("max Re s (1/s)")
    ax.legend(fontsize=8)


def _gain(K, digits: int = 4) -> str:
    return "—" if K is None else "[" + ", ".join(fmt(float(k), digits) for k in np.ravel(K)) + "]"


def _tight_section(t, A, B) -> str:
    """``## Tight synthesis beyond the paper`` (the ``[tight]`` table of a design)."""
    s, cap = t.synthesis, t.synthesis.h_max
    N = t.check.N if t.check else None
    rows = []

    def bl(c):
        return capped_text(c.h_certified, cap) if c else "—"

    def em(c):
        return exact_margin_text(c.exact) if c else "—"
    if t.published:
        p = t.published
        rows.append([f"paper, printed ({p.source})", fmt(p.eps), _gain(p.K),
                     fmt(p.h_m, 4) + " (printed)", bl(t.published_check), em(t.published_check),
                     closed_loop_eigs_text(A, B, p.K)])
    r = t.reference
    rows.append(["ours: problem (60), free weighting, eps fixed", fmt(r.eps), _gain(r.K),
                 fmt(r.h_gain, 4), bl(t.reference_check), em(t.reference_check),
                 closed_loop_eigs_text(A, B, r.K)])
    rows.append(["tight: Wirtinger synthesis, eps searched", fmt(s.eps, 3), _gain(s.K),
                 capped_text(s.gain.h_certified if s.gain else None, cap), bl(t.check), em(t.check),
                 closed_loop_eigs_text(A, B, s.K)])
    table = md_table(["design", "eps", "K", "certified h with this K, own LMI (s)",
                      f"certified h, Bessel-Legendre N = {N} analysis with this K (s)",
                      "exact margin h* (s)", "eigenvalues of A + BK (1/s)"], rows, "lrlrrrl")
    tried = md_table(["eps", "certified h (s)"],
                     [[fmt(e, 4), capped_text(h, cap)] for e, h in s.eps_tried], "rr")
    notes = [
        "The tight synthesis is the Wirtinger-based criterion of Seuret & Gouaisbaut (2013) with "
        "Fridman's descriptor slack P3 = eps P2, made linear by the congruence Y = P2⁻¹, V = K Y "
        "(`workbench/lmi/tight_synthesis.py`); eps is searched automatically (log grid, then "
        "golden section, stopping once the cap is reached), and each eps is a certified, "
        f"re-checked bisection on h (best bound {capped_text(s.h_certified, cap)} s). Its gain is the "
        "canonical one, as above (minimum-norm certificate at the chosen fraction of that "
        "bound, rounded), and the third column is what that gain certifies with K fixed. Every "
        "gain is then re-certified by the Bessel-Legendre *analysis* LMI (independent of the "
        "synthesis LMI) and by the exact delay margin.",
    ]
    if t.check is not None and s.at_cap and math.isinf(t.check.exact.h):
        notes.append(
            f"**The tight bound is the search cap, not a limit.** The synthesis certifies the "
            f"cap h_max = {fmt(cap, 4)} s and the exact margin with its gain is infinite, so the "
            "largest certifiable delay is bounded only by h_max: raising the cap raises the "
            "number. It says *at least* h_max, nothing more.")
    if t.open_loop_hurwitz:
        notes.append(
            "**Why the tight gain is so small.** A is already Hurwitz (see the eigenvalues "
            "above), so K = 0 is stable for every delay; maximising the certified delay alone "
            "is therefore a degenerate objective on this plant, and the synthesis returns a "
            "gain close to zero. The comparison that matters is the Bessel-Legendre column: "
            "the *same* gains judged by a tighter analysis criterion. A meaningful tight design "
            "needs an objective besides the delay (a decay rate or a bandwidth like the "
            "paper's gain), which this section does not impose.")
    if t.published_check is not None:
        c = t.published_check
        reach = (f"up to the search cap ({fmt(cap, 4)} s)" if c.h_certified >= cap
                 else f"up to {fmt(c.h_certified, 4)} s")
        notes.append(
            f"The printed gain's bound {fmt(t.published.h_m, 4)} s is the free-weighting "
            f"criterion's conservatism: the Bessel-Legendre analysis certifies that very gain "
            f"{reach}, and its exact margin is {em(c)}.")
    notes.append("The last column is the delay-free closed loop A + BK, to compare with the "
                 "open-loop eigenvalues of A above.")
    return ("## Tight synthesis beyond the paper\n\n" + table + "\n\n"
            + "\n\n".join(notes)
            + "\n\n<details><summary>eps search of the tight synthesis</summary>\n\n"
            + tried + "\n\n</details>")
