"""Figures of several cases of one run on shared axes, a colour per case.

Each case keeps one colour in every figure of a report (:class:`Palette`).
Plotted data are snapped to a grid (:func:`snapped`) and axis ends are set
on a grid (:func:`~workbench.printed_grid.axis_end`, :func:`time_window`), so
that a few-ulp change of the inputs does not move a pixel: a data-derived
axis end moves every pixel of a figure.

Used by the ``antiskid-run`` study (paper 003); ``tests/test_case_tables.py``
draws a toy.
"""
from __future__ import annotations

import math
from typing import Iterable, Mapping

from ..printed_grid import quantised

#: Plotted values are snapped to 1e-5 of their decade (a step far below a
#: pixel, far above last-bit noise of ~1e-13 relative).
PLOT_DIGITS = 6


class Palette:
    """The colour of a case in every figure: ``colors[name]``, else ``default``."""

    def __init__(self, colors: Mapping[str, str], default: str = "tab:green"):
        self.colors, self.default = dict(colors), default

    def __call__(self, name: str) -> str:
        return self.colors.get(name, self.default)


def snapped(values, scale: float, digits: int = PLOT_DIGITS):
    """``values`` on the grid of 10^(1 - digits) of the decade of ``scale``
    (:func:`~workbench.printed_grid.quantised`)."""
    return quantised(values, digits, scale=scale)


def plot_cases(ax, traces: Iterable[tuple], color_of, scale: float, **style) -> None:
    """One line per trace (case name, t, y, legend label), in the case's
    colour, y snapped on the grid of ``scale`` (:func:`snapped`); ``style``
    passes to ``ax.plot``."""
    for name, t, y, label in traces:
        ax.plot(t, snapped(y, scale), color=color_of(name), label=label, **style)


def plot_phase_plane(ax, traces: Iterable[tuple], color_of, **style) -> None:
    """One path per trace (case name, x, y) in the case's colour, labelled
    with the name, its start marked ``o`` and its end ``x``; the data as
    given (snap them, :func:`snapped`, where a few ulp could move a pixel);
    ``style`` passes to the path's ``ax.plot``."""
    for name, x, y in traces:
        ax.plot(x, y, color=color_of(name), label=name, **style)
        ax.plot(x[0], y[0], "o", color=color_of(name), ms=4)
        ax.plot(x[-1], y[-1], "x", color=color_of(name), ms=6)


def plot_on_curve(ax, grid, f, traces: Iterable[tuple], color_of, label: str) -> None:
    """A static curve y = ``f(x)`` over ``grid`` in black (legend ``label``),
    then each trace's (case name, x) points on it, (x, f(x)), as dots in the
    case's colour labelled with the name: where on a nonlinearity each case
    operated."""
    ax.plot(grid, f(grid), color="k", lw=1.0, label=label)
    for name, x in traces:
        ax.plot(x, f(x), ".", ms=2, color=color_of(name), label=name)


def plot_against_limits(ax, traces: Iterable[tuple], color_of, limits: Iterable[tuple],
                        **style) -> None:
    """One line per trace (case name, t, y) in the case's colour, labelled
    with the name, the data as given; then each of ``limits`` (value, line
    style, legend label) as black lines at +value and -value (the label on
    +value), all + lines first. ``style`` passes to the traces' ``ax.plot``."""
    for name, t, y in traces:
        ax.plot(t, y, color=color_of(name), label=name, **style)
    limits = list(limits)
    for s in (1, -1):
        for value, ls, label in limits:
            ax.axhline(s * value, color="k", ls=ls, lw=0.8, label=label if s > 0 else None)


def time_window(t_event: float, before: float, width: float) -> tuple[float, float]:
    """An x range of ``width`` seconds from the whole second at or below
    ``t_event - before``: ends on a grid, not on the data."""
    t0 = math.floor(t_event - before)
    return t0, t0 + width
