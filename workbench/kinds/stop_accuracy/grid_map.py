"""Map of stop errors over a three-factor error grid (``[grid]``; pure
rendering): a row of panels per speed, a panel per value of the third factor,
the first two factors the rows and columns of each panel's map; a cell shows
its |stop error| coloured against the tolerance (:func:`.render.error_colours`),
its signed error and, where the grid's ``feasible_with`` cannot stop in
time, "infeasible"."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ...report.markdown import fmt
from .render import error_colours

__all__ = ["GridAxis", "plot_grid_map", "result_cell"]


@dataclass(frozen=True)
class GridAxis:
    """One factor of the map: its values, axis label and tick text of a value."""

    values: tuple
    label: str = ""
    tick: Callable = fmt


def plot_grid_map(fig, speeds, rows: GridAxis, cols: GridAxis, panels: GridAxis, cell,
                  tol: float, *, title, suptitle: str, colorbar: str) -> None:
    """Draw the map on ``fig``.

    Parameters
    ----------
    speeds : sequence
        One row of panels each.
    rows, cols, panels : GridAxis
        The factors of a panel's rows and columns, and of the panels.
    cell : callable
        ``cell(speed, row value, column value, panel value) -> (error m, feasible)``.
    tol : float
        The tolerance (m): the colour map's scale, white text beyond twice it.
    title : callable
        ``title(speed, panel value) -> str``: a panel's title.
    suptitle, colorbar : str
        The figure's title and the colour bar's label.
    """
    cmap, norm = error_colours(tol)
    n = len(panels.values)
    gs = fig.add_gridspec(len(speeds), n + 1, width_ratios=[1.0] * n + [0.06])
    for i, s in enumerate(speeds):
        for j, p in enumerate(panels.values):
            ax = fig.add_subplot(gs[i, j])
            M = np.full((len(rows.values), len(cols.values)), np.nan)
            feas = np.ones(M.shape, bool)
            for a, r in enumerate(rows.values):
                for b, c in enumerate(cols.values):
                    M[a, b], feas[a, b] = cell(s, r, c, p)
            im = ax.imshow(np.abs(M), cmap=cmap, norm=norm, origin="lower", aspect="auto")
            for a in range(M.shape[0]):
                for b in range(M.shape[1]):
                    ax.text(b, a, fmt(M[a, b], 2) + ("" if feas[a, b] else "\ninfeasible"),
                            ha="center", va="center", fontsize=7,
                            color="w" if abs(M[a, b]) > 2 * tol else "k")
            ax.set_xticks(range(len(cols.values)))
            ax.set_xticklabels([cols.tick(x) for x in cols.values])
            ax.set_yticks(range(len(rows.values)))
            ax.set_yticklabels([rows.tick(x) for x in rows.values])
            ax.grid(False)
            ax.set_title(title(s, p), fontsize=8)
            if i == len(speeds) - 1:
                ax.set_xlabel(cols.label)
            if j == 0:
                ax.set_ylabel(rows.label)
    fig.suptitle(suptitle)
    fig.colorbar(im, cax=fig.add_subplot(gs[:, n]), extend="max", label=colorbar)


def result_cell(res, controller: str, order):
    """The ``cell`` of :func:`plot_grid_map` of ``controller`` in a kind's
    result ``res`` (its ``grid`` and ``feasible_with``), the map's factors
    being the grid's factors in ``order`` (their names)."""
    from .quantities import feasible
    from .run import grid_corners
    cs = grid_corners(res.spec, order)

    def cell(s, *values):
        k = cs.index(values)
        return res.grid[s, controller][k], feasible(res, s)[k]
    return cell
