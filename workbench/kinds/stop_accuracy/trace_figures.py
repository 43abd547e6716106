"""Figures of recorded stops (pure rendering): the final approach of several
controllers with each stop marked, the speed error against time, and both
speed against position and speed error of stops that track a target, each
curve up to its first standstill (:func:`.render.moving`).

A report passes its own labels; positions are relative to the stopping point
(m), speeds in m/s (drawn in km/h, speed errors in cm/s).
"""
from __future__ import annotations

from .render import moving

__all__ = ["plot_final_approach", "plot_speed_errors", "plot_tracked_stops"]


def plot_final_approach(fig, panels, window: float) -> None:
    """Speed (km/h) against position − stopping point over the last ``window``
    metres, each stop's error a dot on the axis (it carries the legend label);
    a panel per ``(title, [(label, position − D (m), speed (m/s), stop error
    (m)), ...])`` of ``panels``, the speed axis labelled on the first."""
    for i, (title, curves) in enumerate(panels):
        ax = fig.add_subplot(1, len(panels), i + 1)
        for k, (label, dx, v, error) in enumerate(curves):
            keep = (dx > -window) & moving(v)
            ax.plot(dx[keep], 3.6 * v[keep], color=f"C{k}")
            ax.plot([error], [0.0], "o", color=f"C{k}", ms=4, label=label)
        ax.axvline(0, color="k", lw=0.6)
        ax.set_xlabel("position − stopping point (m)")
        if i == 0:
            ax.set_ylabel("speed (km/h)")
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7)


def plot_speed_errors(ax, curves) -> None:
    """The speed error v − v_d (cm/s) against the time from the braking start
    of each ``(label, t (s), v, v_d (m/s))`` of ``curves``, zero marked."""
    for k, (label, t, v, v_d) in enumerate(curves):
        keep = moving(v)
        ax.plot(t[keep], 100 * (v - v_d)[keep], color=f"C{k}", label=label)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_xlabel("time from braking start (s)")
    ax.set_ylabel("speed error v − v_d (cm/s)")
    ax.legend(fontsize=8)


def plot_tracked_stops(fig, curves, target, *, title: str) -> None:
    """Two panels: speed (km/h) against position − stopping point with the
    ``target`` (x_d − D (m), v_d (m/s)) dashed, and the speed error (cm/s)
    against time (panel title ``title``), of each ``(label, t (s), position −
    D (m), v, v_d (m/s))`` of ``curves``."""
    ax1, ax2 = fig.add_subplot(121), fig.add_subplot(122)
    for k, (label, t, dx, v, vd) in enumerate(curves):
        keep = moving(v)
        ax1.plot(dx[keep], v[keep] * 3.6, color=f"C{k}", label=label)
        ax2.plot(t[keep], (v[keep] - vd[keep]) * 100, color=f"C{k}", label=label)
    ax1.plot(target[0], target[1] * 3.6, "k--", lw=0.8, label="target")
    ax1.set_xlabel("position − stopping point (m)")
    ax1.set_ylabel("speed (km/h)")
    ax1.legend()
    ax2.set_xlabel("time from braking start (s)")
    ax2.set_ylabel("speed error (cm/s)")
    ax2.set_title(title)
