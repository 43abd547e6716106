"""Markdown and figure of the ``delay-benchmark`` study (pure rendering).

Seconds are not printed (they vary run to run); solver calls are.
"""
from __future__ import annotations

import math

import numpy as np

from ..benchmark import AUTO, BenchmarkResult, agreement_bound
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


def _ratio(r) -> str:
    if r is None:
        return "—"
    return f"{math.floor(r * 1e5) / 1e5:.5f}"   # truncated: never rounds up to 1


def _label(r) -> str:
    if r.method == "bessel-legendre":
        return f"bessel-legendre N={r.N}"
    if r.method == AUTO:
        return f"{AUTO} (N={r.N})"
    return r.method


def render(design, res: BenchmarkResult) -> Rendered:
    s = res.settings
    ex_rows = [[f"`{e.example.name}`", e.example.title, len(e.example.A),
                fmt(e.exact.h, 7), fmt(e.exact_sweep.h, 7), "≤ " + fmt(agreement_bound(e.agreement)),
                e.example.source] for e in res.examples]
    intro = ("## Examples\n\nx'(t) = A x(t) + A_d x(t - h), constant delay. Exact margin h* "
             "by two independent methods: Chen-Gu-Nett (Kronecker-sum eigenproblem, "
             "`delay_margin_eig`) and a sweep of the delay phase theta following every "
             "eigenvalue branch of A + A_d e^{-j theta}, with Newton-polished crossings "
             "(`delay_margin_sweep`); they must agree to a relative "
             f"{fmt(AGREEMENT_RTOL)} (claim `exact-methods-agree`). Example files: "
             f"`{s.examples}/` next to this design.\n\n"
             + md_table(["example", "system", "n", "h* eig (s)", "h* sweep (s)",
                         "rel. diff", "source"], ex_rows, "llrrrrl")
             + "\n\nThe relative difference is shown as the power of ten it stays below, "
               "floored at 1e-12: below that it is rounding, which differs between CPUs.")
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
            row.append(f"{fmt(r.h_certified, 5)}{cap} / {_ratio(r.ratio)}{n_txt}")
        table.append(row)
    bounds = ("## Certified bounds\n\nEach cell: largest certified delay (s) / ratio to h* "
              "(truncated to 5 decimals; — when h* is infinite). Bracketed bisection "
              f"(`bisect_delay`) to a relative bracket width of {fmt(s.rel_tol)}, definiteness "
              f"margin {fmt(s.margin)} (relative to the largest block size), search cap h <= {fmt(s.h_max)} s; "
              "every certified step re-checked with numpy"
              + (" and in exact rational arithmetic (LDL^T)" if s.exact_check else "")
              + ". A solve answered `optimal_inaccurate` is retried with Clarabel's iterative "
              "refinement tightened, then with its tolerances at 1e-7 "
              "(`workbench.lmi.analysis.RETRY_SETTINGS`); a retry can only certify through "
              f"the same numpy re-check. Automatic mode: N = 0, 1, ... until 1 - h_N/h* < "
              f"{fmt(s.gap_tol)} or "
              f"N = {s.N_max}.\n\n"
              + md_table(["method"] + [f"`{n}`" for n in names], table,
                         "l" + "r" * len(names))
              + "\n\nMethods: " + "; ".join(f"**{k}**: {v}" for k, v in METHOD_DOC.items())
              + ".\n\n" + mats)
    solves = [[_label(e0r)] + [e.rows[i].solves for e in res.examples]
              for i, e0r in enumerate(res.examples[0].rows)]
    checks = [[_label(e0r)] + [e.rows[i].exact_check or "—" for e in res.examples]
              for i, e0r in enumerate(res.examples[0].rows)]
    cost = ("## Solver calls and exact re-check\n\n"
            + md_table(["method"] + [f"`{n}`" for n in names], solves, "l" + "r" * len(names))
            + ("\n\nRational re-check of the certificate at each bound (strict definiteness "
               "of every block, exact LDL^T, `workbench.lmi.exact_check`):\n\n"
               + md_table(["method"] + [f"`{n}`" for n in names], checks,
                          "l" + "l" * len(names)) if s.exact_check else "")
            + f"\n\nLargest ratio h_certified / h* over the suite: "
              f"**{_ratio(res.max_ratio())}** (a sound criterion never exceeds 1).")
    fig = Figure("bessel-legendre-gap", "Gap 1 - h_N/h* of the Bessel-Legendre hierarchy "
                 "against the order N (finite h* only).", lambda f: _draw_gap(f, res))
    return Rendered((intro, bounds, cost,
                     f"## Bessel-Legendre hierarchy\n\n![gap]({{figdir}}/{fig.name}.png)"),
                    (fig,))


def _draw_gap(fig, res: BenchmarkResult) -> None:
    ax = fig.add_subplot(111)
    for e in res.examples:
        if not math.isfinite(e.exact.h):
            continue
        rows = [r for r in e.rows if r.method == "bessel-legendre"]
        gaps = [max(1 - r.h_certified / e.exact.h, 1e-8) for r in rows]
        ax.semilogy([r.N for r in rows], gaps, "o-", label=e.example.name)
    ax.axhline(res.settings.gap_tol, color="k", ls="--", lw=0.8, label="gap tolerance")
    ax.set_xlabel("order N")
    ax.set_ylabel("1 - h_N / h*")
    ax.set_xticks(np.arange(0, res.settings.orders + 1))
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
