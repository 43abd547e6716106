"""The free-weighting synthesis swept over eps, shown as a table and three
figures (any single-input loop x' = A x + B u(t - h)).

The sweep itself is :func:`workbench.synthesis.synthesize_delay_bound`
(one :class:`~workbench.synthesis.SynthesisRow` per eps). This module adds
what a report shows of it:

* :func:`eps_sweep_table` and :func:`eps_sweep_notes`: per eps the certified
  and refuted bounds, the canonical gain, what that gain certifies, the exact
  margin by two methods and the ratio, with what each column means;
* :func:`abscissa_vs_h`: the spectral abscissa of the loop closed with the
  best row's gain over delays around its bound (computed, exact side);
* :func:`eps_sweep_figures`: bound against eps (with printed rows, if any),
  the loop's Bode and Nyquist plots, and the abscissa against h.

A ``delay-feedback`` design turns it on with an ``[eps_sweep]`` table
(:mod:`workbench.kinds.delay_feedback`). :func:`read_eps` and
:func:`read_settings` read the sweep's keys of a ``[synthesis]`` table,
:func:`read_grid` the grid of an automatic eps search.
"""
from __future__ import annotations

import math

import numpy as np

from ..report.markdown import Figure, fmt, md_table
from ..report.synthesis_text import exact_margin_text, gain_text

__all__ = ["abscissa_vs_h", "all_infinite", "eps_sweep_figures", "eps_sweep_notes",
           "eps_sweep_table", "infinite_note", "read_eps", "read_grid", "read_settings"]

#: eps values a synthesis may try (1e-300 left the robust bisection solving for minutes).
EPS_RANGE = (1e-6, 1e6)


def read_eps(t) -> tuple[float, ...]:
    """The distinct values ``eps`` of a ``[synthesis]`` table (its
    :class:`~workbench.reader.Reader` ``t``)."""
    eps = t.numbers("eps", positive=True, what="eps values", lo=EPS_RANGE[0], hi=EPS_RANGE[1])
    if len(set(eps)) != len(eps):
        raise t.fail("eps", list(eps), "distinct eps values")
    return eps


def read_grid(t) -> tuple[float, ...]:
    """The log grid ``grid`` of an automatic eps search (distinct, increasing;
    default 0.01 ... 100) of a table ``t``."""
    grid = t.numbers("grid", default=(0.01, 0.1, 1.0, 10.0, 100.0), positive=True,
                     min_len=2, what="eps values", lo=EPS_RANGE[0], hi=EPS_RANGE[1])
    if list(grid) != sorted(set(grid)):
        raise t.fail("grid", list(grid), "distinct eps values in increasing order")
    return grid


def read_settings(t, *, rel_tol: float = 1e-4, h_max: float = 100.0):
    """The :class:`~workbench.synthesis.SynthesisSettings` of a ``[synthesis]``
    table ``t`` (LMI margin, bisection tolerance, delay search cap in s,
    canonical gain's fraction and digits), with these defaults."""
    from ..lmi.core import DEFAULT_MARGIN
    from ..lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION
    from ..synthesis import H_MAX_RANGE, SynthesisSettings
    return SynthesisSettings(
        margin=t.number("margin", default=DEFAULT_MARGIN, positive=True, hi=1e-2),
        rel_tol=t.number("rel_tol", default=rel_tol, positive=True, hi=0.1),
        h_max=t.number("h_max", default=h_max, lo=H_MAX_RANGE[0], hi=H_MAX_RANGE[1],
                       what="number (s)"),
        gain_fraction=t.number("gain_fraction", default=DEFAULT_FRACTION, positive=True,
                               hi=1.0, what="fraction of h_certified"),
        gain_digits=int(t.number("gain_digits", default=DEFAULT_DIGITS, integer=True,
                                 lo=2, hi=8)))


def _best(rows):
    return max((r for r in rows if r.K is not None), key=lambda r: r.h_certified, default=None)


def abscissa_vs_h(A, B, rows) -> tuple:
    """Spectral abscissa of the loop with the best row's canonical gain on a
    log grid of delays from 1/100 to 100 times its certified bound (the exact
    side: :func:`workbench.margins.spectral_abscissa`; a delay where the
    adaptive collocation does not converge is left out, never guessed)."""
    from ..margins import SpectrumNotConverged, spectral_abscissa
    best = _best(rows)
    if best is None or not best.h_certified > 0:
        return ()
    Ad = B @ np.array([best.K])
    out = []
    for h in np.geomspace(best.h_certified / 100, best.h_certified * 100, 25):
        try:
            out.append((float(h), float(spectral_abscissa(A, Ad, h))))
        except SpectrumNotConverged:
            continue
    return tuple(out)


def all_infinite(rows) -> bool:
    """Every row's exact margin is infinite."""
    return all(r.exact is not None and math.isinf(r.exact.h) for r in rows)


def eps_sweep_table(rows, settings) -> str:
    """One line per eps (see the module docstring)."""
    body = [[fmt(r.eps), fmt(r.h_certified, 5), fmt(r.h_refuted, 5),
             gain_text(r.K, settings.gain_digits), fmt(r.h_gain, 4),
             exact_margin_text(r.exact), exact_margin_text(r.exact_siso), fmt(r.ratio, 3),
             r.status.value] for r in rows]
    return md_table(["eps", "h_certified (s)", "h_refuted (s)", "K (canonical)",
                     "h certified by K (s)", "exact margin h* (s), eigenvalue",
                     "h*, python-control", "ratio h/h*", "status"], body, "rrrlrrrrl")


def eps_sweep_notes(st) -> str:
    """What the columns of :func:`eps_sweep_table` mean (``st``: the settings)."""
    return (
        "*h_certified*: the largest delay at which the LMI was solved to optimality **and** "
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
        "methods.")


def infinite_note(rows) -> str:
    """What the exact margins say about the LMI bounds."""
    if all_infinite(rows):
        return ("**Every exact margin is infinite**: with each synthesised gain the "
                "characteristic equation det(sI − A − BK e^{−sh}) = 0 has no root on the "
                "imaginary axis for any h (no crossover: |K(jωI − A)⁻¹B| < 1 at all ω), so the "
                "closed loop is stable for every constant delay. The LMI bounds above are therefore not delay limits of "
                "the loop: they are where this particular Lyapunov-Krasovskii criterion stops "
                "being able to prove stability. A delay larger than h_certified is not shown "
                "dangerous by this table.")
    return ("Rows with a finite h* are real delay limits of the loop with that gain; the ratio "
            "h_certified / h* measures the conservatism of the criterion.")


def eps_sweep_figures(rows, published, A, B, abscissa, title: str) -> tuple[tuple, str]:
    """(figures, markdown) of the sweep: bound vs eps (``published``: the
    :class:`~workbench.features.published_rows.PublishedCheck` of printed
    rows, drawn as crosses), the loop with the best gain (when a row has one)
    and the spectral abscissa against h (``abscissa``: :func:`abscissa_vs_h`);
    ``title`` heads the first figure."""
    best = _best(rows)
    inf = all_infinite(rows)
    figs = (Figure("delay-bound-vs-eps",
                   "Certified bound and refuted bound against eps; printed values for comparison.",
                   lambda fig: _plot_bounds(fig, rows, published, title)),)
    if best is not None:     # no row certified a gain (fuzz run 32: a = 2): no loop to draw
        figs += (Figure("loop", "Loop L(s) = -K (sI - A)^-1 B: Bode and Nyquist.",
                        lambda fig: _plot_loop(fig, best, A, B), (9.0, 3.6)),)
    text = ("![Certified bound vs eps](" + "{figdir}/delay-bound-vs-eps.png)\n\n"
            "Certified bound (filled) and refuted bound (open) per eps, with the printed "
            "values (crosses). " + ("The exact margin is infinite for every row, so it "
                                   "does not appear on the axis." if inf else ""))
    if best is not None:
        text += ("\n\n![Loop](" + "{figdir}/loop.png)\n\n"
                 f"Bode and Nyquist plots of L(s) = -K (sI - A)⁻¹ B with the canonical gain of "
                 f"eps = {fmt(best.eps)} (K = {gain_text(best.K)}): a delay e^(-sh) only rotates "
                 "L(jω) by -ωh, so the loop can lose stability only at a frequency where "
                 "|L(jω)| = 1; "
                 + _gain_crossing_text(A, B, np.array([best.K]),
                                       best.exact is not None and math.isinf(best.exact.h)))
    if abscissa:
        figs += (Figure("abscissa-vs-h", "Rightmost characteristic root against the delay.",
                        lambda fig: _plot_abscissa(fig, abscissa, best)),)
        worst = max(a for _, a in abscissa)
        text += ("\n\n![Spectral abscissa vs h](" + "{figdir}/abscissa-vs-h.png)\n\n"
                 "Spectral abscissa (real part of the rightmost root) of x' = A x + B K "
                 f"x(t − h) with the same gain, for h from {fmt(abscissa[0][0], 3)} to "
                 f"{fmt(abscissa[-1][0], 3)} s; largest value {fmt(worst, 3)} 1/s. "
                 + ("It stays negative: the loop is stable for every delay shown, as the "
                    "infinite exact margin says (no root ever reaches the imaginary axis)."
                    if worst < 0 and inf else
                    "A positive value is a delay at which the loop is unstable."))
    return figs, text


def _plot_bounds(fig, rows, published, title):
    ax = fig.add_subplot(111)
    e = [r.eps for r in rows]
    ax.plot(e, [r.h_certified for r in rows], "o-", color="C0", label="h_certified")
    ax.plot(e, [r.h_refuted if math.isfinite(r.h_refuted) else np.nan for r in rows],
            "o", mfc="none", color="C1", label="h_refuted")
    fin = [(r.eps, r.exact.h) for r in rows if r.exact and math.isfinite(r.exact.h)]
    if fin:
        ax.plot(*zip(*fin), "s--", color="C2", label="exact margin h*")
    if published:
        ax.plot([c.row.eps for c in published], [c.row.h_m for c in published], "x",
                color="C3", ms=8, label="printed h_m")
    if all_infinite(rows):
        ax.text(0.98, 0.04, "exact margin h* = ∞ for every row", transform=ax.transAxes,
                ha="right", va="bottom", color="C2")
    ax.set_xlabel("eps (R = eps L)")
    ax.set_ylabel("delay bound (s)")
    ax.set_title(title)
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


def _plot_loop(fig, best, A, B):
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


def _plot_abscissa(fig, abscissa, best):
    h, a = zip(*abscissa)
    ax = fig.add_subplot(111)
    ax.semilogx(h, a, "o-", ms=3, color="C0", label="spectral abscissa")
    ax.axhline(0.0, color="k", lw=0.8)
    ax.axvline(best.h_certified, color="C1", ls="--", label="h certified (LMI)")
    ax.set_xlabel("constant delay h (s)")
    ax.set_ylabel("max Re s (1/s)")
    ax.legend(fontsize=8)
