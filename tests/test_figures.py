"""Figures that do not depend on the last digits of their data (issue 12):
:func:`workbench.report.figures.snap_figure` before the PNG is written."""
import math

import numpy as np

from workbench.report import figures
from workbench.report.figures import SNAP_CELLS, figure_png
from workbench.report.markdown import Figure

RNG = np.random.default_rng(12)
X = np.linspace(0.0, 3.0, 400)
Y = np.sin(3 * X) * 1e3 + RNG.normal(size=X.size)


def _draw(fig, eps):
    """Every kind of artist the reports draw, the data scaled by 1 + eps."""
    s = 1.0 + eps
    ax, bx = fig.subplots(1, 2)
    ax.plot(X, Y * s, "o-", ms=2)
    ax.step(X, 0.5 * Y * s, where="post")
    ax.axhline(0.0)
    ax.axvline(1.5 * s)
    ax.axvspan(1.0, 2.0 * s, alpha=0.2)
    ax.axhspan(100.0, 200.0 * s, alpha=0.2)
    ax.fill_between(X, Y * s, 0.0, alpha=0.2)
    ax.text(1.5 * s, 200.0, "label")
    bx.semilogy(X, np.exp(5 * X) * s)
    bx.scatter(X[::10], np.exp(X[::10]) * s)
    bx.bar([1.0, 2.0], [10.0 * s, 20.0], 0.3)
    bx.errorbar([1.5], [30.0 * s], yerr=[5.0])
    bx.imshow([[0.0, 1.0], [1.0, 0.0]], extent=(0.2, 0.8 * s, 1.0, 2.0 * s), aspect="auto")


def _png(eps):
    return figure_png(Figure("t", "test", lambda f: _draw(f, eps)))


def test_last_digits_of_the_data_do_not_change_the_png():
    assert _png(0.0) == _png(1e-10) == _png(-3e-9)


def test_a_visible_change_changes_the_png():
    assert _png(0.0) != _png(1e-3)


def test_title_and_resolution():
    import io

    from PIL import Image
    plain = figure_png(Figure("t", "test", lambda f: _draw(f, 0.0)))
    titled = figure_png(Figure("t", "test", lambda f: _draw(f, 0.0), title="design / t"))
    assert titled != plain
    img = Image.open(io.BytesIO(titled))
    assert img.size == (round(6.4 * figures.DPI), round(4.0 * figures.DPI))
    assert figures.DPI >= 150


def test_without_snapping_the_last_digits_change_the_png(monkeypatch):
    # the property above is the snapping's, not the renderer's
    # (at 150 dpi a 1e-10 change happens to land on the same pixels; -3e-9, one of the
    # changes the snapped PNG ignores above, does not)
    monkeypatch.setattr(figures, "snap_figure", lambda fig: None)
    assert _png(0.0) != _png(-3e-9)


def test_grid_is_a_power_of_two_below_span_over_cells():
    import matplotlib.pyplot as plt
    fig = plt.figure()
    try:
        ax = fig.add_subplot(111)
        ax.plot([0.0, 0.3], [1.0, 1e4])
        ax.set_yscale("log")
        xs = figures._AxisGrid(ax.xaxis, ax.get_xlim())
        ys = figures._AxisGrid(ax.yaxis, ax.get_ylim())
        for g, span in ((xs, np.ptp(ax.get_xlim())), (ys, np.ptp(np.log10(ax.get_ylim())))):
            k = np.log2(g.step)
            assert k == np.floor(k) and g.step <= span / SNAP_CELLS < 2 * g.step
        # log axes are drawn as linear axes of log10 (scalar math), rounded there
        out = ys(np.array([1.0, 123.456, np.nan]))
        assert out[0] == 0.0 and abs(out[1] - math.log10(123.456)) <= ys.step / 2
        assert np.isnan(out[2])
    finally:
        plt.close(fig)


def test_axes_coordinates_are_left_alone():
    import matplotlib.pyplot as plt
    fig = plt.figure()
    try:
        ax = fig.add_subplot(111)
        ax.plot([0.1, 0.7], [0.2, 0.9])
        line = ax.axhline(0.123456789)
        figures.snap_figure(fig)
        assert list(line.get_xdata()) == [0, 1]              # axes fraction: untouched
        assert line.get_ydata()[0] != 0.123456789             # data: rounded
        assert not ax.get_autoscalex_on()                     # limits now fixed
    finally:
        plt.close(fig)


def test_png_has_no_metadata_that_changes():
    png = _png(0.0)
    assert png.startswith(b"\x89PNG") and b"Software" not in png and b"Creation" not in png


def _log_png():
    def draw(fig):
        ax, bx = fig.subplots(1, 2)
        t = np.linspace(0.0, 5.0, 500)
        ax.semilogy(t, np.exp(-3 * t) * (1.2 + np.sin(7 * t)))
        bx.plot(t, 300 * np.sin(2 * t) * np.exp(-0.4 * t))
        bx.set_yscale("symlog", linthresh=1.0)
    return figure_png(Figure("t", "log", draw))


def test_log_axes_do_not_depend_on_numpy_log10(monkeypatch):
    """numpy's SIMD log10/power differ by an ulp between CPUs (AVX-512 against
    AVX2); a log or symlog axis is drawn as a linear axis of its scale
    coordinate computed with scalar math, so such a difference moves nothing."""
    before = _log_png()
    for name in ("log10", "power", "log"):
        f = getattr(np, name)
        monkeypatch.setattr(np, name, lambda *a, _f=f, **k: np.nextafter(_f(*a, **k), np.inf))
    assert _log_png() == before


def test_log_axes_keep_log_ticks():
    import matplotlib.pyplot as plt
    fig = plt.figure()
    try:
        ax = fig.add_subplot(111)
        ax.semilogy([0.0, 1.0], [1e-6, 1.0])
        figures.snap_figure(fig)
        assert ax.get_yscale() == "linear"
        labels = [ax.yaxis.get_major_formatter()(v, 0) for v in ax.get_yticks()]
        assert "$\\mathdefault{10^{-6}}$" in labels and "$\\mathdefault{10^{0}}$" in labels
    finally:
        plt.close(fig)
