"""Table columns and the acceleration/jerk figure of
:mod:`workbench.features.comfort` (pure rendering; the study adds its own
columns, wording and event markers)."""
from __future__ import annotations

from ..report.markdown import fmt

__all__ = ["comfort_headers", "comfort_cells", "plot_comfort"]


def comfort_headers(limits, accel_unit: str = "m/s²", jerk_unit: str = "m/s³") -> list[str]:
    """Column headers of :func:`comfort_cells`: peaks and the time above each limit."""
    return [f"max |a| ({accel_unit})", f"time |a| > {fmt(limits.a_max.value)} (s)",
            f"max |jerk| ({jerk_unit})", f"time |jerk| > {fmt(limits.jerk_max.value)} (s)"]


def comfort_cells(c) -> list[str]:
    """The cells of one :class:`~workbench.features.comfort.Comfort` under
    :func:`comfort_headers`."""
    return [fmt(c.a_max_abs, 3), fmt(c.time_above_a, 3), fmt(c.jerk_max_abs, 2),
            fmt(c.time_above_jerk, 2)]


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
