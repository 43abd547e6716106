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
       "font.size": 9, "axes.grid": True, "grid.alpha": 0.3, "path.simplify": False}

#: Grid cells per axis span of :func:`snap_figure` (the grid step is the
#: largest power of two not above span / SNAP_CELLS).
SNAP_CELLS = 4096


class _AxisGrid:
    """Rounding of one axis' data coordinates, in its scale's space.

    A linear axis keeps its data unit. A log or symlog axis is *re-drawn as a
    linear axis of its scale coordinate* (``log_b x``, or the symlog
    coordinate), computed here with Python's scalar ``math`` functions:
    matplotlib's own log transforms run numpy's SIMD loops, whose last bits
    differ between CPUs (AVX-512 against AVX2), and a 1-ulp move of a snapped
    point can move an antialiased pixel. Its ticks and labels are placed by
    :func:`_log_ticks` at the same positions a log axis would show.
    """

    def __init__(self, axis, lim):
        scale = axis.get_scale()
        self.kind = scale if scale in ("log", "symlog") else "linear"
        tr = axis.get_transform()
        self.base = float(getattr(tr, "base", 10.0))
        self.linthresh = float(getattr(tr, "linthresh", 1.0))
        linscale = float(getattr(tr, "linscale", 1.0))
        self.linscale_adj = linscale / (1.0 - 1.0 / self.base)
        lo, hi = self.forward(np.asarray(lim, float))
        self.lim = (lo, hi)
        span = abs(hi - lo)
        ok = math.isfinite(span) and span > 0
        self.step = 2.0 ** math.floor(math.log2(span / SNAP_CELLS)) if ok else 0.0

    def _scalar(self, v: float) -> float:
        if not math.isfinite(v):
            return v
        if self.kind == "log":
            return math.log(v) / math.log(self.base) if self.base != 10.0 else (
                math.log10(v) if v > 0 else -math.inf)
        a = abs(v)
        if a <= self.linthresh:
            return v * self.linscale_adj
        y = self.linthresh * (self.linscale_adj + math.log10(a / self.linthresh)
                              / math.log10(self.base))
        return math.copysign(y, v)

    def forward(self, x):
        """Data -> the axis' (linear) drawing coordinate."""
        x = np.asarray(x, float)
        if self.kind == "linear" or x.size == 0:
            return x
        flat = [self._scalar(float(v)) for v in x.reshape(-1)]
        return np.array(flat, float).reshape(x.shape)

    def __call__(self, x):
        x = np.asarray(x, float)
        s = self.forward(x)
        if self.step == 0.0 or x.size == 0:
            return s
        fin = np.isfinite(s)
        out = np.where(fin, np.round(np.where(fin, s, 0.0) / self.step) * self.step, s)
        if self.kind != "linear":      # log of a non-positive value: far below the axis
            low = min(self.lim) - 16 * abs(self.lim[1] - self.lim[0])
            out = np.where(np.isneginf(out), math.floor(low / self.step) * self.step, out)
        return out


def _log_ticks(ax, which: str, grid: _AxisGrid, lim) -> None:
    """Ticks and labels of a log / symlog axis re-drawn as linear
    (:class:`_AxisGrid`): decades ``base**k`` labelled as powers (minor ticks
    at their multiples), or, within less than a decade, a few round values."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, MaxNLocator, NullLocator
    axis = ax.xaxis if which == "x" else ax.yaxis
    lo, hi = sorted(float(v) for v in lim)
    major, labels, minor = [], {}, []
    b = grid.base
    bname = f"{b:g}"

    def power(k):
        return f"$\\mathdefault{{{bname}^{{{k}}}}}$"

    if grid.kind == "log":
        k0, k1 = math.floor(lo), math.ceil(hi)
        if hi - lo >= 1.0:
            stride = max(1, math.ceil((k1 - k0) / 8))
            for k in range(k0, k1 + 1):
                if k % stride == 0:
                    major.append(float(k))
                    labels[float(k)] = power(k)
                if stride == 1 and b == 10.0:
                    minor += [k + math.log10(m) for m in range(2, 10)]
        else:                          # within about a decade: round values
            vals = MaxNLocator(5).tick_values(b ** lo, b ** hi)
            for v in vals:
                if v > 0:
                    pos = grid._scalar(float(v))
                    major.append(pos)
                    labels[pos] = f"{float(v):g}"
    else:                              # symlog: 0, ±linthresh * base**k
        t = grid.linthresh
        cand = [0.0] + [s * t * b ** k for k in range(0, 40) for s in (1, -1)]
        for v in cand:
            pos = grid._scalar(v)
            if lo <= pos <= hi:
                major.append(pos)
                labels[pos] = f"{v:g}"
        if len(major) > 9:
            keep = major[::math.ceil(len(major) / 9)]
            labels = {p: labels[p] for p in keep}
            major = keep
    axis.set_major_locator(FixedLocator(sorted(major)))
    axis.set_major_formatter(FuncFormatter(lambda v, _pos: labels.get(v, "")))
    if minor:
        axis.set_minor_locator(FixedLocator([m for m in minor if lo <= m <= hi]))
    else:
        axis.set_minor_locator(NullLocator())


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


def snap_axes(ax, grids=None) -> None:
    """Round the data coordinates of ``ax``'s lines, collections, patches,
    images and texts, and its autoscaled limits (module docstring).
    ``grids``: the axes' ``(xlim, ylim, gx, gy)`` taken before any axes of the
    figure was changed (shared axes change together)."""
    xlim, ylim, gx, gy = grids or _axes_grids(ax)
    for which, g in (("x", gx), ("y", gy)):
        if g.kind != "linear":         # drawn as a linear axis of the scale coordinate
            getattr(ax, f"set_{which}scale")("linear")
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
    auto = ax.get_autoscalex_on(), ax.get_autoscaley_on()
    for which, g, lim, a in (("x", gx, xlim, auto[0]), ("y", gy, ylim, auto[1])):
        if g.kind != "linear":
            snapped = g(lim)
            getattr(ax, f"set_{which}lim")(*snapped)
            _log_ticks(ax, which, g, snapped)
        elif a:
            getattr(ax, f"set_{which}lim")(*g(lim))


def _axes_grids(ax):
    xlim, ylim = ax.get_xlim(), ax.get_ylim()     # autoscales now, from the drawn data
    return xlim, ylim, _AxisGrid(ax.xaxis, xlim), _AxisGrid(ax.yaxis, ylim)


def snap_figure(fig) -> None:
    """:func:`snap_axes` on every axes of ``fig`` (module docstring); every
    axes' grids are taken first, since shared axes change scale together."""
    axes = [ax for ax in fig.axes if ax.name == "rectilinear"]
    grids = [_axes_grids(ax) for ax in axes]
    for ax, g in zip(axes, grids):
        snap_axes(ax, g)


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
