"""Markdown and figure of the ``delay-benchmark`` study (pure rendering).

Seconds are not printed (they vary run to run); solver calls are.
"""
from __future__ import annotations

import math

import numpy as np

from ..benchmark import AUTO, BenchmarkResult, agreement_bound
from ..benchmark_windows import directed, printed_ratio, show_window
from ..lmi.analysis import RETRY_SETTINGS
from ..printed_grid import quantised
from ..margins import AGREEMENT_RTOL
from ..report.markdown import Figure, Rendered, fmt, latex_matrix, md_table

METHOD_DOC = {
    "delay-independent": "delay-independent LKF (Gu, Kharitonov & Chen 2003)",
    "jensen": "Jensen inequality (Gu 2000)",
    "free-weighting": "free-weighting matrices (He et al. 2004, Theorem 1)",
    "wirtinger": "Wirtinger inequality (Seuret & Gouaisbaut 2013, Theorem 5)",
    "bessel-legendre": "Bessel-Legendre inequality of order N (Seuret & Gouaisbaut 2015)",
    AUTO: "Bessel-Legendre, N raised until the gap to h* is below the tolerance",
}


#: Floor of the gap figure: the resolution of the printed ratio h_N / h*.
GAP_FLOOR = 1e-5


def _truncated(r: float) -> float:
    """r truncated to 5 decimals (never rounds up to 1): the digits printed."""
    return math.floor(r * 1e5) / 1e5


def _ratio(r) -> str:
    return "—" if r is None else f"{_truncated(r):.5f}"


def _label(r) -> str:
    if r.method == "bessel-legendre":
        return f"bessel-legendre N={r.N}"
    if r.method == AUTO:
        return f"{AUTO} (N={r.N})"
    return r.method


def _windows(e) -> str:
    if not e.windows:
        return "none (unstable for every h ≤ h_max)"
    return " ∪ ".join(show_window(a, b, lambda x: fmt(x, 7)) for a, b in e.windows)


def _interval(r) -> str:
    if r.interval is None:
        return "—"
    parts = []
    for lo, hi in r.intervals or (r.interval,):
        cap = " (≥ cap)" if math.isfinite(hi) and r.at_cap and hi >= r.h_certified else ""
        parts.append(f"[{fmt(directed(lo, up=True))}, {fmt(directed(hi, up=False))}]{cap}")
    return " ∪ ".join(parts)


def render(design, res: BenchmarkResult) -> Rendered:
    s = res.settings
    ex_rows = [[f"`{e.example.name}`", e.example.title, len(e.example.A),
                fmt(e.exact.h, 7), fmt(e.exact_sweep.h, 7), "≤ " + fmt(agreement_bound(e.agreement)),
                _windows(e), e.example.source] for e in res.examples]
    intro = ("## Examples\n\nx'(t) = A x(t) + A_d x(t - h), constant delay. Exact margin h* "
             "by two independent methods: Chen-Gu-Nett (Kronecker-sum eigenproblem, "
             "`delay_margin_eig`) and a sweep of the delay phase theta following every "
             "eigenvalue branch of A + A_d e^{-j theta}, with Newton-polished crossings "
             "(`delay_margin_sweep`); they must agree to a relative "
             f"{fmt(AGREEMENT_RTOL)} (claim `exact-methods-agree`). Example files: "
             f"`{s.examples}/` next to this design.\n\n"
             + md_table(["example", "system", "n", "h* eig (s)", "h* sweep (s)",
                         "rel. diff", f"stable windows in [0, {fmt(s.h_max)}] s (exact)",
                         "source"], ex_rows, "llrrrrll")
             + "\n\nThe relative difference is shown as the power of ten it stays below, "
               "floored at 1e-12: below that it is rounding, which differs between CPUs. "
               "h* is the end of the window that starts at 0 (0 when the system is "
               "unstable without delay); the stable windows are the whole exact stability "
               "set up to the search cap, from every crossing delay and its direction "
               "(`stability_windows`).")
    mats = "\n\n".join(f"`{e.example.name}`: $A = {latex_matrix(e.example.A)},\\ "
                       f"A_d = {latex_matrix(e.example.Ad)}$" for e in res.examples)
    names = [e.example.name for e in res.examples]
    labels = [_label(r) for r in res.examples[0].rows]
    table = []
    for i, lab in enumerate(labels):
        row = [AUTO if res.examples[0].rows[i].method == AUTO else lab]
        for e in res.examples:
            r = e.rows[i]
            n_txt = f" [N={r.N}]" if r.method == AUTO else ""
            cap = " (≥ cap)" if s.h_max <= r.h_certified < math.inf else ""
            h = fmt(directed(r.h_certified, up=False, sig=5), 5)   # never rounded up
            row.append(f"{h}{cap} / {_ratio(r.ratio)}{n_txt}")
        table.append(row)
    bounds = ("## Certified bounds\n\nTwo kinds of numbers. A **point** certificate "
              "h: the LMI holds at that one delay, so the system is stable *at h* — nothing "
              "is said about other delays, and h may lie in a later window. An **interval** "
              "certificate [lo, hi]: the system is stable *for every constant delay* in it "
              "(next section). Only an interval from 0 is compared with the exact margin.\n\n"
              "### Point certificates (stable at h)\n\nEach cell: largest delay at which "
              "the criterion certified stability (s, rounded down to 5 digits) / ratio to h* "
              "(truncated to 5 decimals; — when h* is 0 or infinite). Bracketed bisection "
              f"(`bisect_delay`) to a relative bracket width of {fmt(s.rel_tol)}, definiteness "
              f"margin {fmt(s.margin)} (relative to the largest block size), search cap h <= {fmt(s.h_max)} s; "
              "every certified step re-checked with numpy"
              + (" and in exact rational arithmetic (LDL^T)" if s.exact_check else "")
              + ". A solve answered `optimal_inaccurate` is retried with Clarabel's iterative "
              "refinement tightened, then with its tolerances at "
              f"{fmt(RETRY_SETTINGS[1]['tol_feas'])} "
              "(`workbench.lmi.analysis.RETRY_SETTINGS`); a retry can only certify through "
              f"the same numpy re-check. Automatic mode: N = 0, 1, ... until 1 - h_N/h* < "
              f"{fmt(s.gap_tol)} or "
              f"N = {s.N_max}.\n\n"
              + md_table(["method"] + [f"`{n}`" for n in names], table,
                         "l" + "r" * len(names))
              + "\n\nMethods: " + "; ".join(f"**{k}**: {v}" for k, v in METHOD_DOC.items())
              + ".\n\n" + mats)
    ivs = [[_label(e0r)] + [_interval(e.rows[i]) + (
        f" / {printed_ratio(e.rows[i]):.4f}" if e.rows[i].interval_ratio is not None
        and math.isfinite(e.exact.h) else "") for e in res.examples]
        for i, e0r in enumerate(res.examples[0].rows)]
    intervals = ("### Interval certificates (stable for every constant delay in [lo, hi])"
                 "\n\nEach cell: the certified intervals [lo, hi] (s; lo rounded up and hi "
                 "down to 4 digits) / that hi over h* when the first starts at 0 and h* is "
                 "finite (truncated to 4 decimals). How "
                 "(`workbench.lmi.interval`): the criterion's LMIs at both ends of [lo, hi] "
                 "with the same decision variables. Times a positive weight (h or 1), every "
                 "block is affine in h or quadratic with a positive semidefinite h^2 "
                 "coefficient (F'RF, R ≥ 0), hence convex in h: one solution holds at every "
                 "delay in between. From 0 the lower block is the limit h → 0, which also "
                 "proves A + A_d Hurwitz. An interval is extended by links [hi, hi'] with "
                 "fresh variables (at most 32 links; a union of certified intervals is "
                 "certified), so an interval can end below the point bound. The "
                 "free-weighting criterion is a delay-range criterion (a certificate at h "
                 "covers [0, h]). When the system is unstable at h = 0, or has a later "
                 "window, the search starts in the middle of each exact window and grows "
                 "both ends (one interval per window reached). Every certified point lies in an exact stable window and every "
                 "certified interval inside one: "
                 f"**{'yes' if res.sound else 'NO'}** (claim `suite-sound`).\n\n"
                 + md_table(["method"] + [f"`{n}`" for n in names], ivs,
                            "l" + "r" * len(names)))
    solves = [[_label(e0r)] + [e.rows[i].solves for e in res.examples]
              for i, e0r in enumerate(res.examples[0].rows)]
    checks = [[_label(e0r)] + [e.rows[i].exact_check or "—" for e in res.examples]
              for i, e0r in enumerate(res.examples[0].rows)]
    cost = ("## Solver calls and exact re-check\n\nSolves of the point search (the interval "
            "searches' counts depend on the last digits of chained solves, which differ "
            "between CPUs: `--json` gives them as `interval_solves`).\n\n"
            + md_table(["method"] + [f"`{n}`" for n in names], solves, "l" + "r" * len(names))
            + ("\n\nRational re-check of the certificate at each bound (strict definiteness "
               "of every block, exact LDL^T, `workbench.lmi.exact_check`):\n\n"
               + md_table(["method"] + [f"`{n}`" for n in names], checks,
                          "l" + "l" * len(names)) if s.exact_check else "")
            + f"\n\nLargest ratio hi / h* of a certified interval [0, hi] over the suite: "
              f"**{_ratio(res.max_ratio())}** (a sound criterion stays below 1).")
    fig = Figure("bessel-legendre-gap", "Gap 1 - h_N/h* of the Bessel-Legendre hierarchy "
                 "(point certificates, from the ratio as printed, floored at "
                 f"{fmt(GAP_FLOOR)}) against the order N (finite h* only).",
                 lambda f: _draw_gap(f, res))
    sets = [Figure(f"stability-set-{e.example.name}",
                   f"{e.example.name}: spectral abscissa against h (top; exact windows "
                   "shaded) and each method's certified interval (bars) and point (x).",
                   lambda f, e=e: _draw_set(f, e), size=(6.4, 5.6)) for e in res.examples]
    figs = "\n\n".join(f"![{g.name}]({{figdir}}/{g.name}.png)\n\n*{g.caption}*" for g in sets)
    return Rendered((intro, bounds + "\n\n" + intervals, cost,
                     f"## Bessel-Legendre hierarchy\n\n![gap]({{figdir}}/{fig.name}.png)\n\n"
                     f"Figure: {fig.caption}",
                     "## Stability sets\n\nSpectral abscissa (rightmost characteristic root, "
                     "adaptive Chebyshev collocation with Newton polishing, "
                     "`spectral_abscissa`) on a uniform grid; shaded: the exact stable "
                     "windows. Bars: certified intervals; x: the point certificate.\n\n"
                     + figs), (fig, *sets))


def _draw_set(fig, e) -> None:
    ax, bx = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [1, 1.3]})
    hs = np.array([p[0] for p in e.abscissa])
    # drawn at 4 digits of their decade (printed_grid.quantised): the same pixels on every CPU
    al = quantised([p[1] for p in e.abscissa])
    H = float(hs[-1]) if len(hs) else 1.0
    ends = quantised([x for w in e.windows for x in w], scale=H)
    for a, b in zip(ends[::2], ends[1::2]):
        for axis in (ax, bx):
            axis.axvspan(a, min(b, H), color="tab:green", alpha=0.15, lw=0)
    ax.plot(hs, al, "k-", lw=1)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_ylabel("spectral abscissa (1/s)")
    ax.grid(True, alpha=0.3)
    for i, r in enumerate(e.rows):      # the values the tables print (they reproduce)
        if r.interval is not None:
            lo, hi = directed(r.interval[0], up=True), directed(r.interval[1], up=False)
            bx.plot([lo, min(hi, H)], [i, i], "-", color="tab:blue", lw=4,
                    solid_capstyle="butt")
        h = directed(r.h_certified, up=False, sig=5)
        if 0 < h <= H:
            bx.plot([h], [i], "x", color="tab:red", ms=6)
    bx.set_yticks(range(len(e.rows)))
    bx.set_yticklabels([_label(r) for r in e.rows], fontsize=7)
    bx.invert_yaxis()
    bx.set_xlim(0, H)
    bx.set_xlabel("constant delay h (s)")
    bx.grid(True, axis="x", alpha=0.3)
    fig.tight_layout()


def _draw_gap(fig, res: BenchmarkResult) -> None:
    ax = fig.add_subplot(111)
    for e in res.examples:
        if not 0 < e.exact.h < math.inf:
            continue
        rows = [r for r in e.rows if r.method == "bessel-legendre" and r.ratio is not None]
        # from the printed ratio (truncated to 5 decimals: the digits that reproduce)
        gaps = [max(1 - _truncated(r.ratio), GAP_FLOOR) for r in rows]
        ax.semilogy([r.N for r in rows], gaps, "o-", label=e.example.name)
    ax.axhline(res.settings.gap_tol, color="k", ls="--", lw=0.8, label="gap tolerance")
    ax.set_xlabel("order N")
    ax.set_ylabel("1 - h_N / h*")
    ax.set_xticks(np.arange(0, res.settings.orders + 1))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
