"""Deterministic figure files: Agg backend, fixed metadata, fixed rcParams,
and plotted coordinates that do not depend on the last digits of the data.

A figure's data come from solvers and linear algebra whose last digits move
with the CPU's BLAS kernels (issue 12). The Markdown prints only the digits
that hold; a figure draws every digit, and the autoscaled axis limits follow
the data, so a difference of 1e-9 can move a curve, a tick or the whole plot
area by a fraction of a pixel and change the PNG. :func:`snap_figure`
therefore rounds, after drawing, every data coordinate of every axes and its
autoscaled limits to a grid of ``2**k`` (in the axis' scale: log axes in
log10 space) with ``2**k <= span / SNAP_CELLS``: about a tenth of a pixel on
a 600-pixel axes, below what the eye sees, and far above the kernels'
differences (a coordinate changes only when it lies within such a
difference of a rounding boundary).

:func:`figure_png` is the PNG of a figure as bytes; :func:`save_figure`
writes it, and ``workbench report --check`` compares it with the committed
file byte for byte.
"""
from __future__ import annotations

import io
import math
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import Collection  # noqa: E402
from matplotlib.image import AxesImage  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Polygon, Rectangle  # noqa: E402
from matplotlib.text import Text  # noqa: E402

from .files import atomic_write  # noqa: E402
from .markdown import Figure  # noqa: E402

#: Export resolution (issue 33, item 7: at least 150 dpi for a review pack).
DPI = 150
_RC = {"svg.hashsalt": "workbench", "figure.dpi": DPI, "savefig.dpi": DPI,
       "font.size": 9, "axes.grid": True, "grid.alpha": 0.3}

#: Grid cells per axis span of :func:`snap_figure` (the grid step is the
#: largest power of two not above span / SNAP_CELLS).
SNAP_CELLS = 4096


class _AxisGrid:
    """Rounding of one axis' data coordinates (in its scale's space)."""

    def __init__(self, axis, lim):
        self.tr = axis.get_transform()                      # the scale (identity, log10, ...)
        lo, hi = self.tr.transform(np.asarray(lim, float))
        span = abs(hi - lo)
        ok = math.isfinite(span) and span > 0
        self.step = 2.0 ** math.floor(math.log2(span / SNAP_CELLS)) if ok else 0.0

    def __call__(self, x):
        x = np.asarray(x, float)
        if self.step == 0.0 or x.size == 0:
            return x
        s = self.tr.transform(x.reshape(-1)).reshape(x.shape)
        fin = np.isfinite(s)
        s = np.where(fin, np.round(np.where(fin, s, 0.0) / self.step) * self.step, s)
        back = self.tr.inverted().transform(s.reshape(-1)).reshape(x.shape)
        return np.where(np.isfinite(x) & fin, back, x)


def _data_dims(ax, transform):
    """(x in data, y in data) for an artist drawn with ``transform``."""
    if transform == ax.transData:
        return True, True
    if transform == ax.get_xaxis_transform():
        return True, False
    if transform == ax.get_yaxis_transform():
        return False, True
    return False, False


def _snap_xy(xy, gx, gy, dims):
    xy = np.array(xy, float, copy=True).reshape(-1, 2)
    if dims[0]:
        xy[:, 0] = gx(xy[:, 0])
    if dims[1]:
        xy[:, 1] = gy(xy[:, 1])
    return xy


def snap_axes(ax) -> None:
    """Round the data coordinates of ``ax``'s lines, collections, patches,
    images and texts, and its autoscaled limits (module docstring)."""
    xlim, ylim = ax.get_xlim(), ax.get_ylim()     # autoscales now, from the drawn data
    gx, gy = _AxisGrid(ax.xaxis, xlim), _AxisGrid(ax.yaxis, ylim)
    for a in ax.get_children():
        if isinstance(a, Line2D):
            dims = _data_dims(ax, a.get_transform())
            if dims[0]:
                a.set_xdata(gx(a.get_xdata(orig=False)))
            if dims[1]:
                a.set_ydata(gy(a.get_ydata(orig=False)))
        elif isinstance(a, Collection):
            odims = _data_dims(ax, a.get_offset_transform())
            offs = np.asarray(a.get_offsets(), float)
            if offs.size and any(odims):
                a.set_offsets(_snap_xy(offs, gx, gy, odims))
            pdims = _data_dims(ax, a.get_transform())
            if any(pdims):
                for p in a.get_paths():
                    if len(p.vertices):
                        p.vertices = _snap_xy(p.vertices, gx, gy, pdims)
        elif isinstance(a, Rectangle):
            dims = _data_dims(ax, a.get_data_transform())
            (x0, y0), (x1, y1) = a.get_xy(), (a.get_x() + a.get_width(),
                                              a.get_y() + a.get_height())
            if dims[0]:
                x0, x1 = gx([x0, x1])
                a.set_x(x0)
                a.set_width(x1 - x0)
            if dims[1]:
                y0, y1 = gy([y0, y1])
                a.set_y(y0)
                a.set_height(y1 - y0)
        elif isinstance(a, Polygon):
            dims = _data_dims(ax, a.get_data_transform())
            if any(dims):
                a.set_xy(_snap_xy(a.get_xy(), gx, gy, dims))
        elif isinstance(a, AxesImage):
            x0, x1, y0, y1 = a.get_extent()
            a.set_extent((*gx([x0, x1]), *gy([y0, y1])))
        elif isinstance(a, Text) and a.axes is ax:
            dims = _data_dims(ax, a.get_transform())
            if any(dims):
                a.set_position(tuple(_snap_xy(a.get_position(), gx, gy, dims)[0]))
    if ax.get_autoscalex_on():
        ax.set_xlim(*gx(xlim))
    if ax.get_autoscaley_on():
        ax.set_ylim(*gy(ylim))


def snap_figure(fig) -> None:
    """:func:`snap_axes` on every axes of ``fig`` (module docstring)."""
    for ax in fig.axes:
        if ax.name == "rectilinear":
            snap_axes(ax)


def figure_png(fig_spec: Figure) -> bytes:
    """The PNG of ``fig_spec``: drawn, snapped (:func:`snap_figure`),
    titled (``fig_spec.title``), laid out at :data:`DPI`, with no timestamp
    or version metadata."""
    with matplotlib.rc_context(_RC):
        fig = plt.figure(figsize=fig_spec.size)
        try:
            fig_spec.draw(fig)
            snap_figure(fig)
            if fig_spec.title:
                width = max(40, int(fig_spec.size[0] * 17))   # characters of 7 pt per line
                lines = [w for line in fig_spec.title.split("\n")
                         for w in textwrap.wrap(line, width) or [""]]
                fig.suptitle("\n".join(lines), fontsize=7, x=0.01, ha="left")
            fig.tight_layout()
            buf = io.BytesIO()
            fig.savefig(buf, format="png", metadata={"Software": None})
            return buf.getvalue()
        finally:
            plt.close(fig)


def save_figure(fig_spec: Figure, path: Path) -> None:
    """Write :func:`figure_png` of ``fig_spec`` to ``path`` (atomically)."""
    atomic_write(path, figure_png(fig_spec))
