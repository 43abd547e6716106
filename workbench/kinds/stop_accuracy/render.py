"""Markdown of a ``stop-accuracy`` design (pure rendering).

Stop errors are printed to the millimetre (3 significant digits of a
sub-metre error): a last-bit difference of the simulation (numpy kernels)
cannot reach that digit except on an exact tie.
"""
from __future__ import annotations

from ...report.markdown import Figure, Rendered, fmt, md_table

__all__ = ["cm", "corner_rows", "distribution_table", "error_colours", "mc_cells", "mc_figure",
           "mc_section", "moving", "plot_case_bars", "plot_constant_sweep", "plot_ecdf",
           "plot_mc_panels", "plot_speed_distance", "quantity_table", "ranges_table", "render",
           "sections_table", "tolerance_lines"]


def _mm(x) -> str:
    if x is None or x != x:
        return "no stop"
    return f"{x:+.3f}"


def cm(x_m: float) -> str:
    """Metres as centimetres to the millimetre (a stop error's meaningful
    resolution); a negative zero is written 0.0."""
    s = f"{100 * x_m:.1f}"
    return "0.0" if s == "-0.0" else s


def render(design, res) -> Rendered:
    """The report sections of a ``stop-accuracy`` design (with ``[analysis]``:
    the paper module's, in its wording)."""
    spec = design.spec
    if spec.analysis is not None:
        from . import paper_analysis
        return paper_analysis(spec.analysis).render(design, res)
    sections = [_problem(spec), _stops(spec, res)]
    if spec.grid:
        sections.append(_grid(spec, res))
    if spec.montecarlo is not None:
        sections.append(_montecarlo(spec, res))
    if spec.sections is not None:
        sections.append(_sections(spec, res))
    if spec.convergence:
        sections.append(_convergence(spec, res))
    anchors = ((r"v[0-9.]+\.[A-Za-z0-9_]+\.mc\.", "Monte Carlo"),
               (r"v[0-9.]+\.[A-Za-z0-9_]+\.grid\.", "Error grid"),
               (r"v[0-9.]+\.[A-Za-z0-9_]+\.convergence\.", "Convergence"),
               (r"sections[.\[]", "Sections"),
               (r"v[0-9.]+\.", "Stops"))
    return Rendered(tuple(sections), (), anchors)


def _problem(spec) -> str:
    ctl = [[f"`{c.name}`", "; ".join(f"{k} = `{t}`" for k, t in c.definitions) or "—",
            _law_text(c)] for c in spec.controllers]
    target = (f"D = {fmt(spec.distance, 6)} m" if spec.distance is not None else
              f"D = the nominal stopping distance of the command {fmt(spec.command)} m/s² held")
    out = ("## Problem\n\nA `stop-accuracy` design: each controller brakes the paper-000 "
           "brake plant (`[plant]`, two transmission delays and the electric/air hand-over) "
           f"from {', '.join(fmt(s) for s in spec.speeds_kmh)} km/h to the stopping point; "
           f"{target}.{_reference_text(spec)} Commands clip to [{fmt(-spec.c_min)}, "
           f"{fmt(spec.c_max)}] m/s², act every "
           f"{fmt(spec.dt_ctrl)} s (ZOH); the plant steps at dt = {fmt(spec.dt)} s. Laws are "
           "the design's text, parsed by `workbench/expr.py` (never evaluated) and checked "
           "to be in m/s². Stop error = standstill position − D (+ = overshoot); "
           f"platform tolerance ±{fmt(spec.tolerance)} m.\n\n"
           + quantity_table("parameter", spec.params, 6))
    if spec.constants:
        out += "\n\n" + quantity_table("constant", spec.constants, 6)
    out += "\n\n" + md_table(["controller", "definitions", "brake command (m/s²)"], ctl, "lll")
    if spec.factors:
        rows = [[f"`{f.name}`", f.effect + (" " + ", ".join(f.parameters) if f.parameters
                                            else ""), f.what] for f in spec.factors]
        out += "\n\n" + md_table(["factor", "acts on", "what"], rows, "lll")
    if spec.faults:
        axles = any(f.axles for f in spec.faults)
        rows = [[f"`{f.name}`", ", ".join(f"{k} = {fmt(v)}" for k, v in f.parameters.items())
                 or "—", fmt(f.speed_ratio), ", ".join(
                     f"{k} = {fmt(v)}" for k, v in (f.disturbance or {}).items()) or "—"]
                + ([f.axles or "—"] if axles else []) for f in spec.faults]
        out += "\n\n" + md_table(["fault", "brake parameters", "speed read / true",
                                  "disturbance"] + (["axles"] if axles else []), rows,
                                 "llrl" + ("l" if axles else ""))
        if axles:
            out += ("\n\nAxle states (module `deceleration_loop`): o healthy, s sliding "
                    "(reads slide_ratio × v), f failed (reads 0), h reads high_ratio × v, "
                    "z stuck at its reading when braking started; the train speed is the "
                    "maximum; where every axle is s or f the loop is off (the law alone). "
                    "A controller without the module does not read the axles.")
    return out


def quantity_table(head: str, quantities: dict, digits: int) -> str:
    """The table of ``quantities`` (name -> :class:`~workbench.reader.Quantity`):
    name (column ``head``), value to ``digits`` significant digits, unit, source."""
    rows = [[f"`{k}`", fmt(q.value, digits), q.unit, q.source] for k, q in quantities.items()]
    return md_table([head, "value", "unit", "source"], rows, "lrll")


def _law_text(c) -> str:
    """A controller's law: its expression (with the ``pid`` module) or the
    ``smarc`` module, and its compensation modules."""
    if c.smarc is not None:
        text = "SMARC (module `smarc`, eqs 22, 26-27: " + ", ".join(
            f"{k} = {v}" for k, v in c.smarc.names.items()) + ")"
    else:
        text = f"`{c.law}`" + ("" if c.pid is None else
                               f" + PID(`{c.pid[0]}`; kp = {c.pid[1]}, ki = {c.pid[2]}, "
                               f"kd = {c.pid[3]}" + ("" if c.pid_limited else ", no limit")
                               + ")")
    if c.loop is not None:
        text += " as the target of the " + c.loop.text()
    if c.levels:
        text += (f"; command channel of {c.levels} levels above 0 (rounded to multiples of "
                 f"c_max / {c.levels})")
    mods = [m for m, on in (("predictor", c.predictor), ("terminal", c.terminal)) if on]
    if mods:
        text += " with modules " + " and ".join(f"`{m}`" for m in mods) + (
            "" if c.gain_correction else " (no gain correction)")
    return text


def _reference_text(spec) -> str:
    if spec.reference is None and spec.compensation is None:
        return ""
    out = ""
    r = spec.reference
    if r is not None:
        out += (f" The laws track the ATO target curve (`[reference]`, module `ato-trapezoid`: "
                f"accelerate at {fmt(r.a_acc)} m/s², cruise at {fmt(r.v_max, 6)} m/s, brake "
                f"at {fmt(r.a_dec)} m/s² to stop at D; `x_d`, `v_d`, `a_d`); each run starts "
                "where the target starts braking, x counted from the section's start.")
    cp = spec.compensation
    if cp is not None:
        out += (" Known-delay compensation (`[compensation]`, "
                "`workbench/kinds/stop_accuracy/modules.py`): module `predictor` feeds the law "
                "the state one dead time ahead from the nominal brake model (brake-gain "
                f"correction low-passed over {fmt(cp.gain_tau)} s within "
                f"[{fmt(cp.gain_bounds[0])}, {fmt(cp.gain_bounds[1])}]); module `terminal` holds, "
                f"from {fmt(cp.d_terminal)} m to go, the command the model predicts stops at D.")
    return out


def _stops(spec, res) -> str:
    head = ["speed (km/h)", "D (m)", "controller", "nominal (m)"] + [
        f"{f.name} (m)" for f in spec.faults]
    rows = []
    for s in spec.speeds_kmh:
        for c in spec.controllers:
            rows.append([fmt(s), f"{res.distance[s]:.2f}", f"`{c.name}`",
                         _mm(res.nominal[s, c.name])]
                        + [_mm(res.faults[s, c.name, f.name]) for f in spec.faults])
    return ("## Stops\n\nStop errors (m) of one stop per speed and controller, on the nominal "
            "plant and under each fault (quantities `v<speed>.<controller>.nominal_m`, "
            "`...fault[<f>].error_m`).\n\n" + md_table(head, rows, "rrl" + "r" * (len(head) - 3)))


def _grid(spec, res) -> str:
    n = 1
    for _, v in spec.grid:
        n *= len(v)
    from .quantities import feasible
    rows, fw = [], spec.grid_feasible
    for s in spec.speeds_kmh:
        ok = feasible(res, s) if fw else None
        for c in spec.controllers:
            e = res.grid[s, c.name]
            worst = max(abs(x) for x in e) if all(x == x for x in e) else None
            rows.append([fmt(s), f"`{c.name}`", "no stop" if worst is None else f"{worst:.3f}",
                         f"{sum(not abs(x) <= spec.tolerance for x in e)} of {n}"] + (
                [f"{sum(f and not abs(x) <= spec.tolerance for x, f in zip(e, ok))} of "
                 f"{sum(ok)}"] if fw else []))
    axes = " × ".join(f"{k} {list(v)}" for k, v in spec.grid)
    note = (f" A corner is *feasible* where `{fw}` stops at least {fmt(spec.tolerance)} m short "
            "of D (`[grid] feasible_with`): elsewhere no controller of this brake can stop at "
            "D." if fw else "")
    return ("## Error grid\n\n"
            f"Every corner of {axes} ({n} corners) per speed and controller.{note}\n\n"
            + md_table(["speed (km/h)", "controller", "max |error| (m)",
                        f"outside ±{fmt(spec.tolerance)} m"] + (
                            ["feasible outside"] if fw else []), rows, "rlrr" + ("r" if fw
                                                                              else "")))


def corner_rows(res, order, controllers, ticks) -> list:
    """Per speed and corner of ``[grid]`` (sorted by the factors' values in
    ``order``, their names): the speed, each factor's value (written by the
    function of ``ticks`` at its place), whether the corner is feasible
    (``feasible_with``) and the stop error (m) of each of ``controllers``."""
    from .quantities import feasible
    from .run import grid_corners
    cs, rows = grid_corners(res.spec, order), []
    for s in res.spec.speeds_kmh:
        ok = feasible(res, s)
        rows += [[fmt(s)] + [w(x) for w, x in zip(ticks, cs[k])] + ["yes" if ok[k] else "no"]
                 + [fmt(res.grid[s, c][k], 3) for c in controllers]
                 for k in sorted(range(len(cs)), key=cs.__getitem__)]
    return rows


def _montecarlo(spec, res) -> str:
    m = spec.montecarlo
    dist = [[f"`{k}`", d.describe(), d.source] for k, d in m.distributions.items()]
    rows = []
    for s in spec.speeds_kmh:
        for c in spec.controllers:
            st = res.mc[s, c.name]
            rows.append([fmt(s), f"`{c.name}`", f"{st.k}/{st.n}",
                         f"[{st.lo:.3f}, {st.hi:.3f}]", f"{st.p95:.2f}", f"{st.mean:+.2f}",
                         f"{st.overshoot:.3f}"])
    return ("## Monte Carlo\n\n"
            f"{m.samples} draws (seed {m.seed}); every speed and controller meets the same "
            "draws; factors without a distribution stay nominal.\n\n"
            + md_table(["factor", "distribution", "source"], dist, "lll") + "\n\n"
            + md_table(["speed (km/h)", "controller", f"within ±{fmt(spec.tolerance)} m",
                        "Wilson 95 %", "p95 |error| (m)", "mean (m)", "overshoot share"],
                       rows, "rlrrrrr"))


def design_quantities(spec, res) -> dict:
    from ...features.quantities import values
    from .quantities import TABLE
    return values(TABLE, spec, res)


def _sections(spec, res) -> str:
    rp = spec.sections
    ctl = [c.name for c in spec.controllers if not rp.controllers or c.name in rp.controllers]
    rows = []
    for i, sec in enumerate(rp.sections):
        cells = [res.sections[i, c] for c in ctl]
        rows.append([str(i + 1), sec.name, fmt(sec.length, 6)] + [
            f"{fmt(x.mean_abs, 3)} / {fmt(x.mean, 3)} / {fmt(x.var, 3)}" for x in cells])
    q = design_quantities(spec, res)
    rows.append(["all", "mean over the sections", "—"] + [
        f"**{fmt(q[f'sections.{c}.mean_abs_cm'], 3)}**" for c in ctl])
    rng = ", ".join(f"`{k}` [{fmt(lo)}, {fmt(hi)}]" for k, lo, hi in rp.ranges)
    return ("## Sections\n\n"
            f"Every controller stops {rp.count} times at the end of each section (`[[sections]]`, "
            f"`[repeats]`, seed {rp.seed}, one stream per section), starting where the target "
            f"starts braking, on plants drawn uniformly: {rng}. Stop error (cm, + = overshoot) "
            "over the repeats: mean |error| / signed mean / variance (cm²) "
            "(`workbench/kinds/stop_accuracy/sections.py`).\n\n"
            + md_table(["#", "section", "length (m)"] + [f"`{c}`" for c in ctl], rows,
                       "rlr" + "r" * len(ctl)))


def _convergence(spec, res) -> str:
    rows = []
    for k, lv in res.levels.items():
        chk = res.checks.get(k)
        rows.append([f"`{k}`", *(_mm(x) for x in lv),
                     "—" if chk is None or chk.estimate is None else f"{chk.estimate:.1e}",
                     chk.outcome if chk else "not determined"])
    out = ("## Convergence\n\nEvery stop error at dt, dt/2 and dt/4 (control period fixed), "
           "with the Richardson estimate of the error at dt/4 "
           "(`workbench/sim/convergence.py`).\n\n"
           + md_table(["quantity", "dt", "dt/2", "dt/4", "estimate (m)", "outcome"], rows,
                      "lrrrrl"))
    if res.refinement:
        out += "\n\n" + md_table(["claim", "converged", "note"], [
            [r.claim_id, "yes" if r.converged else "no", r.reason or "—"]
            for r in res.refinement], "lll")
    return out



# -- pieces of the Monte Carlo tables and figures a paper's [analysis] report shares ------------
def distribution_table(spec) -> str:
    """The ``[montecarlo]`` distributions of ``spec`` with each factor's meaning
    and unit (``[disturbances]``)."""
    factor = {f.name: f for f in spec.factors}
    rows = [[f"`{k}`", factor[k].what, d.describe(), factor[k].unit, d.source]
            for k, d in spec.montecarlo.distributions.items()]
    return md_table(["factor", "meaning", "distribution", "unit", "source"], rows, "lllll")


def ranges_table(spec) -> str:
    """The ``[repeats] ranges`` of ``spec`` (uniform draws of the repeats) with
    each factor's meaning and unit (``[disturbances]``)."""
    factor = {f.name: f for f in spec.factors}
    rows = [[f"`{k}`", factor[k].what, f"[{fmt(lo)}, {fmt(hi)}]", factor[k].unit]
            for k, lo, hi in spec.sections.ranges]
    return md_table(["factor", "meaning", "range", "unit"], rows, "llll")


def sections_table(spec, planned) -> str:
    """The ``[[sections]]`` of ``spec`` (number, name, length, source) with the
    ``planned`` braking time (s) of each."""
    rows = [[i + 1, s.name, fmt(s.length, 5), fmt(t, 4), s.source]
            for i, (s, t) in enumerate(zip(spec.sections.sections, planned))]
    return md_table(["#", "section", "length (m)", "planned braking time (s)", "source"], rows,
                    "rlrrl")


def mc_cells(st, error) -> list:
    """Stops within the tolerance, their share, its Wilson 95 % interval, the
    95th percentile of |error|, the mean error (both as ``error(m)`` writes
    them) and the overshoot share (%) of a :class:`StopStatistics` ``st``."""
    return [f"{st.k} / {st.n}", fmt(st.p, 3), f"[{fmt(st.lo, 3)}, {fmt(st.hi, 3)}]",
            error(st.p95), error(st.mean), fmt(100 * st.overshoot, 3)]


def plot_ecdf(ax, errors, **kw) -> None:
    """The empirical distribution of ``errors`` on ``ax`` (a step per error)."""
    import numpy as np
    e = np.sort(np.asarray(errors, float))
    ax.step(e, np.arange(1, len(e) + 1) / len(e), where="post", **kw)


def tolerance_lines(ax, tol: float) -> None:
    """Dashed vertical lines at -tol and +tol on ``ax``."""
    for x in (-tol, tol):
        ax.axvline(x, color="k", ls="--", lw=0.8)


def mc_section(spec, level: str, intro: str, rows, *, heads, align: str, unit: str, error,
               alt: str) -> str:
    """A Monte Carlo section of an ``[analysis]`` report: its heading (``level``:
    ``"##"``, ``"###"``), the draws and ``intro``, the ``[montecarlo]``
    distributions and one row per ``(key cells, StopStatistics)`` of ``rows``
    (columns ``heads`` aligned ``align``, then :func:`mc_cells` with errors
    in ``unit`` written by ``error``), and the figure ``mc-stop-errors``."""
    tol, mc = fmt(spec.tolerance), spec.montecarlo
    return (f"{level} Monte Carlo: P(|e| ≤ {tol} m) over continuous distributions\n\n"
            f"{mc.samples} draws (seed {mc.seed}; `workbench/studies/stopping_mc.py`{intro}\n\n"
            + distribution_table(spec) + "\n\n"
            + md_table(list(heads) + [f"stops within {tol} m", f"P(|e| ≤ {tol} m)",
                                      "Wilson 95 % interval", f"95th percentile of |e| ({unit})",
                                      f"mean e ({unit})", "overshoots (%)"],
                       [list(k) + mc_cells(st, error) for k, st in rows], align + "rrrrrr")
            + f"\n\n![{alt}]({{figdir}}/mc-stop-errors.png)")


def mc_figure(caption: str, panels, tol: float, size, **kw) -> Figure:
    """The figure ``mc-stop-errors`` that :func:`mc_section` shows:
    :func:`plot_mc_panels` of ``panels`` (``kw``: its ``unit``, ``scale``,
    ``linthresh``), ``size`` in inches."""
    return Figure("mc-stop-errors", caption, lambda fig: plot_mc_panels(fig, panels, tol, **kw),
                  size=size)


def plot_mc_panels(fig, panels, tol: float, *, unit: str = "m", scale: float = 1.0,
                   linthresh: float | None = None) -> None:
    """The empirical distributions of Monte Carlo stop errors, one panel per
    ``(title, ((label, errors (m)), ...))`` of ``panels``, side by side on
    shared axes, with the tolerance ``tol`` (m) dashed; errors and tolerance
    drawn times ``scale`` in ``unit`` (symlog axis with ``linthresh``)."""
    import numpy as np
    first = None
    for i, (title, curves) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1, sharex=first, sharey=first)
        first = first or ax
        for k, (label, errors) in enumerate(curves):
            plot_ecdf(ax, scale * np.asarray(errors, float), color=f"C{k}", label=label)
        tolerance_lines(ax, scale * tol)
        if linthresh is not None:
            ax.set_xscale("symlog", linthresh=linthresh)
        ax.set_xlabel(f"stop error ({unit}, + overshoot)")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7, loc="upper left")
    first.set_ylabel("fraction of stops ≤ error")


def plot_speed_distance(fig, panels) -> None:
    """Speed (km/h) against position relative to the stopping point (m), each
    curve up to its first standstill (:func:`moving`), a panel per
    ``(title, [(label, position - D (m), speed (m/s)), ...])`` of ``panels``."""
    for i, (title, curves) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1)
        for k, (label, dx, v) in enumerate(curves):
            keep = moving(v)
            ax.plot(dx[keep], 3.6 * v[keep], color=f"C{k}", label=label)
        ax.axvline(0, color="k", lw=0.6)
        ax.set_xlabel("position − D (m)")
        ax.set_ylabel("speed (km/h)")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7)


def plot_case_bars(ax, cases, series, tol: float, *, linthresh: float) -> None:
    """Horizontal bars of the stop error (m) per case, one bar per series
    (e.g. per speed) side by side, on a symlog axis (linear within
    ``linthresh``), the tolerance band ``tol`` grey.

    Parameters
    ----------
    cases : sequence of str
        The cases' labels, top to bottom.
    series : sequence of (label, errors)
        Per series its legend label and its error of each case.
    """
    import numpy as np
    y = np.arange(len(cases))
    for k, (label, errors) in enumerate(series):
        ax.barh(y + (k - (len(series) - 1) / 2) * 0.35, errors, height=0.35, color=f"C{k}",
                label=label)
    ax.set_xscale("symlog", linthresh=linthresh)
    ax.axvspan(-tol, tol, color="0.9", zorder=0)
    ax.set_yticks(y)
    ax.set_yticklabels(list(cases), fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel(f"stop error (m, + overshoot; grey: ±{fmt(tol)} m)")
    ax.legend(fontsize=8)


def plot_constant_sweep(ax, sweep, speeds, tol: float, *, chosen: float, chosen_label: str,
                        xlabel: str) -> None:
    """The stop error (m) of :func:`.run.constant_sweep` against the constant's
    value, a line per speed of ``speeds`` (km/h), the value ``chosen``
    dotted, the tolerance band ``tol`` grey.

    Parameters
    ----------
    sweep : dict
        (value, speed km/h) -> stop error (m), as :func:`.run.constant_sweep`.
    """
    for k, s in enumerate(speeds):
        pts = sorted((x, e) for (x, sp), e in sweep.items() if sp == s)
        ax.plot([a for a, _ in pts], [b for _, b in pts], "o-", color=f"C{k}",
                label=f"{fmt(s)} km/h")
    ax.axvline(chosen, color="k", lw=0.8, ls=":", label=chosen_label)
    ax.axhspan(-tol, tol, color="0.9", zorder=0, label=f"±{fmt(tol)} m")
    ax.set_xlabel(xlabel)
    ax.set_ylabel("stop error (m, + overshoot)")
    ax.legend(fontsize=8)


def error_colours(tol: float):
    """A threshold colour map of |stop error| for a tolerance ``tol`` (m):
    greens within the tolerance, orange to dark red beyond it (no failing
    cell can look green), and its norm (bounds 0, tol/2, tol, 1.5 tol, 2 tol,
    3 tol; darker above): ``(cmap, norm)`` for ``imshow``."""
    from matplotlib.colors import BoundaryNorm, ListedColormap
    cmap = ListedColormap(["#1a9850", "#a6d96a", "#fdae61", "#f46d43",
                           "#d73027"]).with_extremes(over="#67001f")
    bounds = [0.0, tol / 2, tol, 1.5 * tol, 2 * tol, 3 * tol]
    return cmap, BoundaryNorm(bounds, cmap.N)


def moving(v):
    """Mask of the samples of a speed trace ``v`` up to the first standstill
    (the first sample, then every one with ``v > 0``): where a stop's curve is drawn."""
    import numpy as np
    return np.concatenate(([True], v[1:] > 0))[:len(v)]
