"""Table columns and the per-case table (:func:`comfort_table`), the
stretches above the jerk limit with the events near them (:func:`jerk_text`),
and the acceleration/jerk figure of :mod:`workbench.features.comfort` (pure
rendering; the study adds its own columns, wording and event markers).
Events of a phase-scheduled run are its phase switches
(:func:`phase_switches`). Test on a toy: ``tests/test_comfort.py``."""
from __future__ import annotations

import math

import numpy as np

from ..report.markdown import fmt, md_table
from ..sim.convergence import P_MIN
from .comfort import COMFORT_RTOL, peaks_converged

__all__ = ["limits_text", "window_text", "comfort_headers", "comfort_cells", "comfort_table", "converged_head",
           "converged_cell", "converged_text", "jerk_text", "phase_switches", "windows_text",
           "plot_comfort"]


def limits_text(limits, accel_unit: str = "m/s²", jerk_unit: str = "m/s³") -> str:
    """"|a| <= <a_max> m/s² (<source>) and |jerk| <= <jerk_max> m/s³
    (<source>)": the comfort limits with their sources, in words."""
    a, j = limits.a_max, limits.jerk_max
    return (f"|a| <= {fmt(a.value)} {accel_unit} ({a.source}) and |jerk| <= "
            f"{fmt(j.value)} {jerk_unit} ({j.source})")


def window_text(limits) -> str:
    """"averaged over a <window> s window (<source>)": how a and jerk are smoothed."""
    return f"averaged over a {fmt(limits.window.value)} s window ({limits.window.source})"


def comfort_headers(limits, accel_unit: str = "m/s²", jerk_unit: str = "m/s³") -> list[str]:
    """Column headers of :func:`comfort_cells`: peaks and the time above each limit."""
    return [f"max |a| ({accel_unit})", f"time |a| > {fmt(limits.a_max.value)} (s)",
            f"max |jerk| ({jerk_unit})", f"time |jerk| > {fmt(limits.jerk_max.value)} (s)"]


def comfort_cells(c) -> list[str]:
    """The cells of one :class:`~workbench.features.comfort.Comfort` under
    :func:`comfort_headers`."""
    return [fmt(c.a_max_abs, 3), fmt(c.time_above_a, 3), fmt(c.jerk_max_abs, 2),
            fmt(c.time_above_jerk, 2)]


def converged_head(rtol: float = COMFORT_RTOL) -> str:
    """Header of the column of :func:`converged_cell`."""
    return f"converged, dt to dt/4 ({fmt(100 * rtol)} %)"


def converged_cell(levels, rtol: float = COMFORT_RTOL) -> str:
    """Whether the peaks of three :class:`~workbench.features.comfort.Comfort`
    results (at dt, dt/2, dt/4) converged
    (:func:`~workbench.features.comfort.peaks_converged`): "yes" or
    "**not converged**"; "—" for ``levels`` None (no dt/4 run)."""
    return "—" if levels is None else peaks_converged(levels, rtol) or "**not converged**"


def converged_text(rtol: float = COMFORT_RTOL) -> str:
    """What :func:`converged_cell` means, in words (a sentence without its end)."""
    return ("Converged: the |a| and |jerk| peaks at dt, dt/2 and dt/4 have a Richardson "
            f"error estimate within {fmt(100 * rtol)} % of the peak (levels whose "
            f"differences change sign: the larger difference at order {fmt(P_MIN)}); — : no "
            "dt/4 run")


def comfort_table(cases, limits, extra_heads=()) -> str:
    """One row per case (name, Comfort, levels, extra cells): the name in
    code font, :func:`comfort_cells`, the study's extra cells under
    ``extra_heads``, then :func:`converged_cell` of ``levels`` (three
    Comfort results at dt, dt/2, dt/4, or None)."""
    rows = [[f"`{name}`", *comfort_cells(c), *extra, converged_cell(levels)]
            for name, c, levels, extra in cases]
    return md_table(["case", *comfort_headers(limits), *extra_heads, converged_head()], rows,
                    "l" + "r" * (4 + len(extra_heads)) + "l")


def phase_switches(t, phase, names, pinned=None) -> list[tuple[float, str]]:
    """(time, "a → b") of each change of a recorded phase.

    Parameters
    ----------
    t : array of float
        Record times (s).
    phase : array of int
        The phase at each record time, an index into ``names``.
    names : sequence of str
        Phase names.
    pinned : (group, t0, tol) or None
        A switch from a phase outside ``group`` (phase names) into it, at a
        record time within ``tol`` (s) of ``t0``, is given at ``t0``: a
        switch due at a known time first shows at a record sample that can
        depend on the last bit of the accumulated time. Not used when ``t0``
        is not finite.
    """
    ph = np.asarray(phase)

    def at(i):
        if pinned is not None:
            group, t0, tol = pinned
            if (names[ph[i]] in group and names[ph[i - 1]] not in group
                    and math.isfinite(t0) and abs(t[i] - t0) <= tol):
                return t0
        return float(t[i])

    return [(float(at(i)), f"{names[ph[i - 1]]} → {names[ph[i]]}")
            for i in np.flatnonzero(ph[1:] != ph[:-1]) + 1]


def windows_text(windows, events, window: float, jerk_unit: str = "m/s³") -> str:
    """The stretches (start, end, peak |jerk|) of ``windows`` (s; e.g.
    :attr:`~workbench.features.comfort.Comfort.jerk_windows`), each with the
    events (time, what) within ``window`` seconds of it."""
    parts = []
    for t0, t1, peak in windows:
        near = [f"{what} at {fmt(ts, 4)} s" for ts, what in events
                if t0 - window <= ts <= t1 + window]
        parts.append(f"{fmt(t0, 4)}-{fmt(t1, 4)} s (peak {fmt(peak, 2)} {jerk_unit}; "
                     + ("; ".join(near) if near else "no phase switch within the window")
                     + ")")
    return "; ".join(parts)


def jerk_text(name: str, c, events, limits, jerk_unit: str = "m/s³") -> str:
    """"`name`: |jerk| > limit at" the stretches of ``c.jerk_windows`` with
    the events near them (:func:`windows_text`), or "no time"."""
    return (f"`{name}`: |jerk| > {fmt(limits.jerk_max.value)} {jerk_unit} at "
            + (windows_text(c.jerk_windows, events, limits.window.value, jerk_unit)
               or "no time") + ".")


def plot_comfort(fig, traces, limits, events=(), accel_unit: str = "m/s²",
                 jerk_unit: str = "m/s³") -> None:
    """Acceleration (top) and jerk (bottom) against time, the limits dashed.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    traces : iterable of (label, colour, Comfort)
    limits : ComfortLimits
        a_max, jerk_max and window, all given.
    events : iterable of float
        Times (s) marked by dotted vertical lines (e.g. phase switches).
    """
    ax_a, ax_j = fig.subplots(2, 1, sharex=True)
    for label, colour, m in traces:
        ax_a.plot(m.t_a, m.a, color=colour, lw=0.8, label=label)
        ax_j.plot(m.t_j, m.j, color=colour, lw=0.8, label=label)
    for ax, lim in ((ax_a, limits.a_max.value), (ax_j, limits.jerk_max.value)):
        for s in (lim, -lim):
            ax.axhline(s, color="k", ls="--", lw=0.8)
    for ts in events:
        for ax in (ax_a, ax_j):
            ax.axvline(ts, color="gray", ls=":", lw=0.6)
    ax_a.set_ylabel(f"a ({accel_unit})")
    ax_j.set_ylabel(f"jerk ({jerk_unit})")
    ax_j.set_xlabel("t (s)")
    ax_a.legend(fontsize=7, ncol=4, loc="upper right")
    ax_a.set_title(f"averaged over {fmt(limits.window.value)} s; limits "
                   f"±{fmt(limits.a_max.value)} {accel_unit}, "
                   f"±{fmt(limits.jerk_max.value)} {jerk_unit}", fontsize=8)
