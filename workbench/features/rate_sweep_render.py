"""Tables, text and figure panels of a rate sweep
(:mod:`workbench.features.rate_sweep`; pure rendering). The caller gives the
words of its system: what its input is (:func:`variant_label`), the cells of
a rate's row, the metrics drawn, why a rate fails. Test on a system of no
paper: ``tests/test_rate_sweep.py``."""
from __future__ import annotations

import math

import numpy as np

from ..printed_grid import printed_digits
from ..report.markdown import fmt, md_table
from ..sim.convergence import P_MAX, P_MIN

__all__ = ["bound", "printed", "variant_label", "variant_sources", "summary_lines", "outcome",
           "missed", "rate_tables", "mark_requirement",
           "mesh_table", "mesh_text", "three_level_text", "replay_table", "replay_text", "plot_rate_metric",
           "plot_rate_panels", "plot_traces"]


def variant_label(v, input_name: str, unit: str) -> str:
    """What a variant of :func:`workbench.features.rate_sweep.variants` is,
    in words (``input_name``: the quantised command, ``unit``: its unit)."""
    if v.name == "zoh":
        return f"ZOH (exact samples, unquantised {input_name})"
    parts = [f"{input_name} quantised to {fmt(v.q)} {unit}" if v.q else "",
             f"measurement delay {fmt(1e3 * v.tau)} ms" if v.tau else ""]
    return "ZOH, " + ", ".join(p for p in parts if p)


def variant_sources(quantisation, measurement_delay, unit: str) -> str:
    """`` Quantisation: <q> <unit> (<source>). Measurement delay: <ms> ms
    (<source>).`` for the given :class:`workbench.reader.Quantity` (None:
    not given)."""
    out = ""
    if quantisation is not None:
        out += f" Quantisation: {fmt(quantisation.value)} {unit} ({quantisation.source})."
    if measurement_delay is not None:
        out += (f" Measurement delay: {fmt(1e3 * measurement_delay.value)} ms "
                f"({measurement_delay.source}).")
    return out


def summary_lines(variants, label, why=None, *, requirement: str = "both requirements",
                  short: str = "both") -> list[str]:
    """One line per variant: the lowest passing rate and its bisection
    bracket; ``why(v, row)``: which requirement the row of the highest
    failing rate misses (appended after "; at <f> Hz it fails in"), None for
    nothing; ``requirement``/``short``: what a passing rate meets, in words."""
    out = []
    for v in variants:
        if v.min_rate is None:
            out.append(f"- **{label(v)}**: no rate of the grid meets {requirement} "
                       f"from {fmt(v.bracket[0])} Hz up.")
            continue
        lo, hi = v.bracket
        if lo is None:
            refine = (f"every rate of the grid meets {short}; the grid does not go below "
                      f"{fmt(v.min_rate)} Hz")
        else:
            row = next(r for r in v.rows + v.probes if r.rate == lo)
            miss = "" if why is None else f"; at {fmt(lo)} Hz it fails in " + why(v, row)
            refine = (f"bisection between the grid rates ({len(v.probes)} steps on log f_c, "
                      f"whole Hz, assuming one crossing): fails at {fmt(lo)} Hz, meets at "
                      f"{fmt(hi)} Hz" + miss)
        out.append(f"- **{label(v)}**: lowest rate of the grid meeting {requirement} "
                   f"(and every higher grid rate) **{fmt(v.min_rate)} Hz**; " + refine + ".")
    return out


def outcome(m: dict, which: str, fails: str) -> str:
    """Requirement ``which`` at a rate, in words, from the rate's metrics
    ``<which>_diverged`` (a time, NaN: no divergence) and ``<which>_ok``:
    ``diverged, t = <t> s``, ``meets``, else ``fails`` (why it misses)."""
    t = m[f"{which}_diverged"]
    if not math.isnan(t):
        return f"diverged, t = {fmt(t, 4)} s"
    return "meets" if m[f"{which}_ok"] == "yes" else fails


def missed(m: dict, requirements: tuple, outcome_of) -> str:
    """The requirements of ``requirements`` a rate misses (its metric
    ``<r>_ok`` is "no"), each with ``outcome_of(m, r)`` in brackets, joined
    by "and": the ``why`` of :func:`summary_lines`."""
    return " and ".join(f"{r} ({outcome_of(m, r)})" for r in requirements
                        if m[f"{r}_ok"] == "no")


def bound(x: float) -> str:
    """A small non-negative difference as the next power of ten above it
    ("< 1e-6"; "0" for none): its leading digit moves with the CPU's
    floating-point contractions, its size does not."""
    if x == 0:
        return "0"
    if not x > 0:
        return fmt(x)
    return "< " + fmt(10.0 ** (math.floor(math.log10(x)) + 1))


def printed(x: float, sig: int) -> str:
    """``x`` with the digits :func:`~workbench.printed_grid.printed_digits`
    gives for ``sig`` (one more where ``x`` lies near a rounding tie), "—"
    for NaN."""
    return fmt(None if math.isnan(x) else x, printed_digits(x, sig))


def _level(x) -> str:
    return x if isinstance(x, str) else printed(x, 5)


def _rows(v) -> list:
    """The grid's rows and the bisection's of a variant, by rate."""
    return sorted(v.rows + v.probes, key=lambda r: r.rate)


def rate_tables(variants, label, head: list, cells, first: list | None = None) -> list[str]:
    """One Markdown table per variant: ``**label(v)**`` and a row per rate
    of the grid and of the bisection (``cells(rate label, metrics)``: the
    row), after ``first`` (a row, say a reference's) when given."""
    out = []
    for v in variants:
        rows = [] if first is None else [first]
        rows += [cells(fmt(r.rate) + (" (bisection)" if r.probe else ""), r.metrics)
                 for r in _rows(v)]
        out.append(f"**{label(v)}**\n\n" + md_table(head, rows, "l" + "r" * (len(head) - 1)))
    return out


def mesh_table(variants, label, atol: dict) -> str:
    """The mesh check (two levels): per variant and rate, whether step and
    step / 2 agree and the largest difference of each metric of ``atol``."""
    rows = [[label(v), fmt(rate), "yes" if agree else "**no**"] + [bound(d[k]) for k in atol]
            for v in variants for rate, agree, d in v.mesh]
    return md_table(["variant", "f_c (Hz)", "agree"] + list(atol), rows,
                    "lrl" + "r" * len(atol))


def mesh_text(variants, label, atol: dict, *, max_rate: float, step: float) -> str:
    """*Mesh, two levels*: the words and the table (:func:`mesh_table`) of
    the mesh check of grid rates up to ``max_rate`` at ``step`` / 2 (s)."""
    tol = ", ".join(f"{k} {fmt(t)}" for k, t in atol.items())
    return (f"*Mesh, two levels*: every grid rate up to {fmt(max_rate)} Hz again with "
            f"sub-steps of at most {fmt(1e3 * step / 2)} ms; largest differences of the "
            f"metrics (tolerances: {tol}; the outcomes must agree):\n\n"
            + mesh_table(variants, label, atol))


def three_level_text(variants, label, *, max_rate: float, step: float, scenarios: str,
                     not_covered: str) -> str:
    """*Mesh, three levels*: the claimed rate metrics at plant_step, /2, /4
    (:class:`~workbench.features.rate_sweep.ThreeLevel`); ``step``: the
    plant step (s); ``scenarios``: what "the scenario the metric needs" can
    be, in words; ``not_covered``: what claims compare that neither mesh
    check covers."""
    rows = []
    for v in variants:
        for t in v.three_level:
            est = "—" if t.estimate is None else bound(t.estimate)
            out = "converged" if t.converged else f"**{t.reason()}**"
            rows.append([label(v), fmt(t.rate), f"`{t.metric}`",
                         *(_level(x) for x in t.values), est,
                         "equal" if t.tolerance is None else fmt(t.tolerance), out])
    text = (
        f"*Mesh, three levels*: every rate metric a claim of the design compares, at a grid "
        f"rate up to {fmt(max_rate)} Hz, at plant_step = {fmt(1e3 * step)} ms (the grid's "
        "run), plant_step/2 (the screen's run) and plant_step/4 (run for this check, only the "
        f"scenario the metric needs: {scenarios}). Richardson estimate of the error "
        "of the plant_step/4 value from the observed order p = log2(|q1 − q2| / |q2 − q4|), "
        f"p clipped to [{fmt(P_MIN)}, {fmt(P_MAX)}]; levels whose differences change sign are "
        f"estimated from the larger difference at order {fmt(P_MIN)}. A metric has converged "
        "when its estimate is within "
        "the screen's tolerance (0, rounding only, for a metric without one), an outcome "
        "when it is the same at the three levels; a variant's mesh claim holds when both "
        "checks do, and is INCONCLUSIVE (not converged) otherwise. Estimates are printed as "
        "the next power of ten above them. Not covered by either mesh check: " + not_covered
        + ".")
    if not rows:
        return text + " No claim compares a rate metric at such a rate."
    return text + "\n\n" + md_table(
        ["variant", "f_c (Hz)", "metric", "plant_step", "/2", "/4", "estimate", "tolerance",
         "outcome"], rows, "lrlrrrrrl")


def replay_table(checks, head: list, differences) -> str:
    """The windows replayed against Radau
    (:class:`workbench.features.mesh_replay.WindowCheck`): per window its
    key, name, times, state range and input pieces, then each of
    ``differences`` (check -> a difference, printed by :func:`bound`);
    ``head``: the headings of these columns."""
    rows = [[fmt(c.key), c.name, f"{fmt(c.t0, 5)}–{fmt(c.t1, 5)}",
             f"{fmt(c.lo, 2)}–{fmt(c.hi, 2)}", str(c.pieces)] + [bound(d(c)) for d in differences]
            for c in checks]
    return md_table(head, rows, "lllrr" + "r" * len(differences))


def replay_text(table: str, *, input_name: str, receiver: str, samples: int, variant: str,
                rtol: float, model: str) -> str:
    """*Radau*: the words of the replay check
    (:mod:`workbench.features.mesh_replay`) before its ``table``
    (:func:`replay_table`): the ``input_name`` the ``receiver`` received in
    a window of ``samples`` samples of ``variant``, ``rtol``, ``model``: the
    right-hand side Radau integrates, in words."""
    return (f"*Radau*: the {input_name} {receiver} received in a window of {samples} samples "
            f"({variant}) replayed into scipy's `solve_ivp(method=\"Radau\")` (rtol "
            f"{fmt(rtol)}), restarted from its own state at every change of the {input_name}, "
            f"against the mesh at each of its points ({model}):\n\n" + table)


def plot_rate_metric(ax, variants, key: str, failed: str, color, label, *,
                     shift: float = 0.0, reference: float | None = None,
                     reference_label: str = "") -> None:
    """One panel: metric ``key`` (minus ``shift``) against the rate (log
    axis), a line per variant (grid and bisection); a cross at the top of
    the panel where the metric ``failed`` (a time, NaN: no failure) is set;
    ``reference``: a dashed black line (not drawn when NaN or None)."""
    for v in variants:
        rows = _rows(v)
        f = np.array([r.rate for r in rows])
        y = np.array([r.metrics[key] for r in rows])
        c = color(v)
        ax.plot(f, y - shift, "o-", color=c, ms=3, label=label(v))
        bad = [r.rate for r in rows if not math.isnan(r.metrics[failed])]
        if bad:
            ax.plot(bad, [0.97] * len(bad), "x", color=c, ms=7,
                    transform=ax.get_xaxis_transform())
    if reference is not None and not math.isnan(reference):
        ax.axhline(reference - shift, color="k", ls="--", lw=0.8, label=reference_label)
    ax.set_xscale("log")


def plot_rate_panels(fig, variants, panels, color, label, reference: dict,
                     reference_label: str, shifts: dict | None = None, cols: int = 2):
    """Panels of :func:`plot_rate_metric` on a shared rate axis, ``cols`` a
    row: ``panels`` ((metric, y label, failed), ...); ``reference``: metric
    -> the reference's value; ``shifts``: metric -> its shift. Returns the
    axes (flat)."""
    axes = fig.subplots(-(-len(panels) // cols), cols, sharex=True).ravel()
    for ax, (key, ylabel, failed) in zip(axes, panels):
        plot_rate_metric(ax, variants, key, failed, color, label,
                         shift=(shifts or {}).get(key, 0.0), reference=reference[key],
                         reference_label=reference_label)
        ax.set_ylabel(ylabel)
    for ax in axes[-cols:]:
        ax.set_xlabel("control rate f_c (Hz)")
    return axes


def mark_requirement(ax, requirement: float, label: str | None = None,
                     base_label: str | None = None) -> None:
    """A solid grey line at 0 (``base_label``) and a dotted one at
    ``requirement`` (``label``): a metric drawn as its excess over a base,
    which it must keep below ``requirement``."""
    ax.axhline(0.0, color="grey", lw=0.8, label=base_label)
    ax.axhline(requirement, color="dimgrey", ls=":", lw=1.0, label=label)


def plot_traces(ax, traces, y: str, color, label, styles: dict) -> None:
    """Time traces on one axis: per trace (``.variant``, ``.rate``, ``.t``
    and the values in attribute ``y``) a line of ``color(trace)``, labelled
    ``label(trace)``, dashed as ``styles`` says of its rate (dotted for a
    rate not in it)."""
    for tr in traces:
        ax.plot(tr.t, getattr(tr, y), color=color(tr), lw=0.8, ls=styles.get(tr.rate, ":"),
                label=label(tr))
