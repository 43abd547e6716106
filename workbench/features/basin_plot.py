"""The basin figure of any closed loop: certified and refuted level sets of
V = (x - x*)' P (x - x*) in a plane (a slice through x*), the falsifier's
counterexample, sampled trajectories coloured by fate, and the judged points
(equilibrium starts, switch states) marked by their verdict.

Pure rendering of a :class:`workbench.roa.BasinEstimate`, its
:class:`workbench.roa.check.PointCheck` points and
:class:`workbench.features.basin_trajectory.Trajectory` paths; the look of a
family of figures is a :class:`BasinPlotStyle`; :func:`basin_figure` draws
it on a figure's one axes with the axis labels, limits and legend.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Colour of a trajectory by fate ("leaves the domain" and "diverges" are both escapes).
FATE_COLOR = {"converges": "tab:green", "leaves the domain": "tab:red", "diverges": "tab:red",
              "undecided": "0.6"}
#: Marker of a judged point by verdict.
MARK = {"CERTIFIED": "o", "REFUTED": "X", "INCONCLUSIVE": "s"}


@dataclass(frozen=True)
class BasinPlotStyle:
    """Line widths, marker sizes, labels and clipping of a basin figure.

    Attributes
    ----------
    sampled_lw, sampled_alpha : float
        Sampled trajectories.
    point_lw, point_ms : float
        A judged point's trajectory and marker.
    cx_ms : float
        The counterexample's marker.
    point_label : str
        Legend entry of a judged point ({label}, {outcome}).
    clip : tuple or None
        Per plotted coordinate, (lo, hi) the drawn paths are clipped to, or None.
    legend_loc : str
    """

    sampled_lw: float = 0.8
    sampled_alpha: float = 0.85
    point_lw: float = 1.6
    point_ms: float = 8
    cx_ms: float = 9
    point_label: str = "{label}: {outcome}"
    clip: tuple | None = None
    legend_loc: str = "best"


def ellipse(P, c: float, plane) -> np.ndarray:
    """Points of {e' P_pp e = c} in the plane's coordinates (slice through x*)."""
    Pp = np.asarray(P, float)[np.ix_(plane, plane)]
    T = np.linalg.inv(np.linalg.cholesky(Pp).T)
    th = np.linspace(0, 2 * np.pi, 400)
    return np.sqrt(c) * T @ np.vstack([np.cos(th), np.sin(th)])


def _xy(path, plane, clip):
    i, j = plane
    xs, ys = path[:, i], path[:, j]
    if clip is not None:
        xs = xs if clip[0] is None else np.clip(xs, *clip[0])
        ys = ys if clip[1] is None else np.clip(ys, *clip[1])
    return xs, ys


def plot_basin(ax, est, points, trajectories, plane=(0, 1), style: BasinPlotStyle = BasinPlotStyle()
               ) -> None:
    """Level sets, counterexample, sampled trajectories and judged points on ``ax``.

    Parameters
    ----------
    ax : matplotlib Axes
    est : BasinEstimate
        (``P``, ``x_eq``, ``c_certified``, ``c_refuted``, ``counterexample``).
    points : sequence of PointCheck
        Judged points; ``trajectories[k]`` starts at ``points[k]``.
    trajectories : sequence of Trajectory
        The points' trajectories, then the sampled ones.
    plane : (int, int)
        State indices of the axes.
    style : BasinPlotStyle

    Axis labels, limits, extra lines and the legend are the caller's.
    """
    P, x_eq = np.array(est.P), np.array(est.x_eq)
    i, j = plane
    for c, ls, lab in ((est.c_certified, "-", "certified level c_certified"),
                       (est.c_refuted, "--", "refuted level c_refuted")):
        if 0 < c < np.inf:
            e = ellipse(P, c, [i, j])
            ax.plot(x_eq[i] + e[0], x_eq[j] + e[1], "k" + ls, lw=1.2, label=lab)
    if est.counterexample is not None:
        cx = est.counterexample
        ax.plot(cx[i], cx[j], "k*", ms=style.cx_ms, label="counterexample (V' >= 0)")
    seen = set()
    for tr in trajectories[len(points):]:
        lab = None if tr.fate in seen else f"sampled: {tr.fate}"
        seen.add(tr.fate)
        ax.plot(*_xy(tr.path, plane, style.clip), color=FATE_COLOR[tr.fate], lw=style.sampled_lw,
                alpha=style.sampled_alpha, label=lab)
    for p, tr in zip(points, trajectories):
        name = p.verdict.outcome.name
        ax.plot(*_xy(tr.path, plane, style.clip), color=FATE_COLOR[tr.fate], lw=style.point_lw)
        ax.plot(p.x[i], p.x[j], MARK[name], color="tab:blue", ms=style.point_ms, mec="k",
                label=style.point_label.format(label=p.label, outcome=name))


def basin_figure(fig, est, points, trajectories, plane, style: BasinPlotStyle, labels, *,
                 xlim=None, ylim=None, extra=None):
    """One axes of ``fig`` with :func:`plot_basin` (arguments as there), then
    ``extra(ax)`` (the caller's own marks, e.g. a reference line), the axis
    ``labels`` (x, y), the limits given and the legend; returns the axes."""
    ax = fig.add_subplot(111)
    plot_basin(ax, est, points, trajectories, plane, style)
    if extra is not None:
        extra(ax)
    if xlim is not None:
        ax.set_xlim(*xlim)
    if ylim is not None:
        ax.set_ylim(*ylim)
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.legend(fontsize=6, loc=style.legend_loc, framealpha=0.9)
    return ax
