"""The general figures of the stop-accuracy kind on toy data (no design): the
error-grid map (:mod:`workbench.kinds.stop_accuracy.grid_map`: a panel per
speed and third-factor value plus the colour bar, every cell's signed error
printed, infeasible cells marked, large errors in white), the bars of the
stop error per case (:func:`workbench.kinds.stop_accuracy.render.plot_case_bars`),
the speed-distance curves up to standstill
(:func:`workbench.kinds.stop_accuracy.render.plot_speed_distance`), the sweep of a
constant (:func:`~workbench.kinds.stop_accuracy.render.plot_constant_sweep`), the
samples of stop errors (:mod:`workbench.kinds.stop_accuracy.error_samples`) and the
``ANALYSIS`` object built from a toy table (:mod:`workbench.kinds.stop_accuracy.analysis`),
the final approach and speed errors of recorded stops
(:mod:`workbench.kinds.stop_accuracy.trace_figures`), the table rows of every grid corner
(:func:`~workbench.kinds.stop_accuracy.render.corner_rows`), the per-section tables of
the repeats (:mod:`workbench.kinds.stop_accuracy.error_samples`), the map cell of a result
(:func:`~workbench.kinds.stop_accuracy.grid_map.result_cell`), the Monte Carlo figure
(:func:`~workbench.kinds.stop_accuracy.render.mc_figure`), and the tables of the sections and
of the repeats' ranges (:func:`~workbench.kinds.stop_accuracy.render.sections_table`,
:func:`~workbench.kinds.stop_accuracy.render.ranges_table`)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure  # noqa: E402

from workbench.kinds.stop_accuracy.grid_map import GridAxis, plot_grid_map  # noqa: E402
import numpy as np  # noqa: E402

from workbench.kinds.stop_accuracy.render import (plot_case_bars,  # noqa: E402
                                                  plot_speed_distance)


def test_toy_grid_map():
    fig = Figure()
    # error = row + column + panel value; infeasible where the row value is 2
    cell = lambda s, r, c, p: (s * (r + c + p), r != 2)
    plot_grid_map(fig, [1.0, -1.0], GridAxis((0, 2), "row"), GridAxis((0.1, 0.2, 0.3), "col"),
                  GridAxis((0.0, 1.0)), cell, 0.5, title=lambda s, p: f"{s} {p}",
                  suptitle="toy", colorbar="|e|")
    assert len(fig.axes) == 2 * 2 + 1                                  # 4 panels + colour bar
    ax = fig.axes[1]                                                   # speed 1, panel 1.0
    texts = {t.get_text(): t.get_color() for t in ax.texts}
    assert set(texts) == {"1.1", "1.2", "1.3", "3.1\ninfeasible", "3.2\ninfeasible",
                          "3.3\ninfeasible"}
    assert texts["1.1"] == "w" and texts["3.1\ninfeasible"] == "w"     # |e| > 2 tol = 1
    assert fig.axes[0].texts[0].get_text() == "0.1" and fig.axes[0].texts[0].get_color() == "k"
    assert ax.get_title() == "1.0 1.0" and fig.axes[2].get_xlabel() == "col"
    assert fig.axes[0].get_ylabel() == "row" and ax.get_ylabel() == ""
    assert [t.get_text() for t in fig.axes[3].texts][0] == "-1.1"       # speed -1, panel 1.0


def test_toy_case_bars():
    ax = Figure().add_subplot(111)
    plot_case_bars(ax, ["a", "b", "c"], [("one", [0.1, -2.0, 30.0]), ("two", [0.0, 1.0, -5.0])],
                   0.3, linthresh=0.3)
    bars = ax.patches[:6]
    assert [b.get_width() for b in bars] == [0.1, -2.0, 30.0, 0.0, 1.0, -5.0]
    assert [round(b.get_y() + b.get_height() / 2, 3) for b in bars] == [
        -0.175, 0.825, 1.825, 0.175, 1.175, 2.175]                 # side by side per case
    assert [t.get_text() for t in ax.get_yticklabels()] == ["a", "b", "c"]
    assert ax.get_xscale() == "symlog" and ax.yaxis_inverted()
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["one", "two"]


def test_toy_speed_distance_stops_at_standstill():
    fig = Figure()
    dx = np.array([-10.0, -5.0, -1.0, 0.5, 0.5])
    v = np.array([5.0, 3.0, 1.0, 0.0, 0.0])                    # m/s, stands still from the 4th
    plot_speed_distance(fig, [("A", [("x", dx, v), ("y", dx - 1, v)]), ("B", [("z", dx, v)])])
    a, b = fig.axes
    line = a.get_lines()[0]
    assert list(line.get_xdata()) == [-10.0, -5.0, -1.0]        # up to the first standstill
    assert list(line.get_ydata()) == [18.0, 10.8, 3.6]          # km/h
    assert [t.get_text() for t in a.get_legend().get_texts()] == ["x", "y"]
    assert (a.get_title(), b.get_title()) == ("A", "B") and len(b.get_lines()) == 2  # + D line


def test_toy_constant_sweep_one_line_per_speed():
    from workbench.kinds.stop_accuracy.render import plot_constant_sweep
    ax = Figure().add_subplot(111)
    sweep = {(2.0, 50.0): 0.4, (1.0, 50.0): -0.1, (1.0, 80.0): 0.2, (2.0, 80.0): 0.9}
    plot_constant_sweep(ax, sweep, [50.0, 80.0], 0.3, chosen=1.5, chosen_label="chosen",
                        xlabel="k (s)")
    a, b = ax.get_lines()[:2]
    assert list(a.get_xdata()) == [1.0, 2.0] and list(a.get_ydata()) == [-0.1, 0.4]  # sorted
    assert list(b.get_ydata()) == [0.2, 0.9]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["50 km/h", "80 km/h", "chosen", "±0.3 m"] and ax.get_xlabel() == "k (s)"


def test_toy_error_samples():
    from workbench.kinds.stop_accuracy.error_samples import (plot_abs_ecdf, plot_grouped_boxes,
                                                             within_rows)
    e = [-5.0, 1.0, 2.0, 40.0]
    (row,) = within_rows([("toy", e)], 30.0)
    assert row[:3] == ["toy", "3 / 4", "0.75"] and row[3].startswith("[")
    assert row[4] == "34.7"                                          # 95th pct of |e|, 3 digits
    ax = Figure().add_subplot(111)
    plot_abs_ecdf(ax, [("a", e), ("b", [0.0])], 30.0, window_label="w", unit="cm", linthresh=1.0)
    assert list(ax.get_lines()[0].get_xdata()) == [1.0, 2.0, 5.0, 40.0]     # |e|, sorted
    assert ax.get_xscale() == "symlog" and ax.get_xlabel() == "|stop error| (cm)"
    ax = Figure().add_subplot(111)
    plot_grouped_boxes(ax, [("a", [[1.0, 2.0], [3.0, 4.0], [0.0, 1.0]]), ("b", [[0.0]] * 3)],
                       xlabel="group", ylabel="e")
    assert [t.get_text() for t in ax.get_xticklabels()] == ["1", "2", "3"]
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["a", "b"]
    assert len(ax.patches) == 6                                    # a box per series and group


def test_toy_analysis_object():
    from types import SimpleNamespace

    from workbench.features.quantities import Declared
    from workbench.kinds.stop_accuracy.analysis import Analysis
    table = (Declared("toy.{k}", "m", lambda r, k: r.x[k], over=lambda spec: [
        {"k": k} for k in spec.keys]),)
    a = Analysis(table, lambda root, spec: "read", lambda spec: SimpleNamespace(
        spec=spec, x={k: len(k) for k in spec.keys}), lambda design, res: "rendered")
    spec = SimpleNamespace(keys=("a", "bb"))
    assert a.quantity_names(spec) == {"toy.a", "toy.bb"}
    assert a.quantity_units(spec) == {"toy.a": "m", "toy.bb": "m"}
    assert a.quantities(a.run(spec)) == {"toy.a": 1, "toy.bb": 2}
    assert a.load(None, spec) == "read" and a.render(None, None) == "rendered"


def test_toy_trace_figures():
    from workbench.kinds.stop_accuracy.render import cm
    from workbench.kinds.stop_accuracy.trace_figures import (plot_final_approach,
                                                             plot_speed_errors,
                                                             plot_tracked_stops)
    assert cm(0.1234) == "12.3" and cm(-0.0001) == "0.0"          # no negative zero
    fig = Figure()
    dx = np.array([-50.0, -30.0, -1.0, 0.2, 0.2])
    v = np.array([8.0, 6.0, 1.0, 0.0, 0.0])
    plot_final_approach(fig, [("A", [("a", dx, v, 0.2), ("b", dx - 0.5, v, -0.3)]),
                              ("B", [("c", dx, v, 0.2)])], window=40)
    a, b = fig.axes
    assert list(a.get_lines()[0].get_xdata()) == [-30.0, -1.0]    # last 40 m, while moving
    assert [t.get_text() for t in a.get_legend().get_texts()] == ["a", "b"]  # on the stop dots
    assert list(a.get_lines()[1].get_xdata()) == [0.2] and b.get_ylabel() == ""
    ax = Figure().add_subplot(111)
    t = np.arange(5.0)
    plot_speed_errors(ax, [("x", t, v, v - 0.01)])
    assert list(ax.get_lines()[0].get_xdata()) == [0.0, 1.0, 2.0]
    assert np.allclose(ax.get_lines()[0].get_ydata(), 1.0)             # cm/s
    fig = Figure()
    plot_tracked_stops(fig, [("x", t, dx, v, v - 0.02)], (dx, v), title="T")
    a, b = fig.axes
    assert [t.get_text() for t in a.get_legend().get_texts()] == ["x", "target"]
    assert np.allclose(b.get_lines()[0].get_ydata(), 2.0) and b.get_title() == "T"


def test_toy_corner_rows_and_grid_cell():
    from types import SimpleNamespace

    from workbench.kinds.stop_accuracy.render import corner_rows
    spec = SimpleNamespace(grid=(("b", (2.0, 1.0)), ("a", (0.5,))), speeds_kmh=(50.0,),
                           tolerance=0.3, grid_feasible="full")
    res = SimpleNamespace(spec=spec, grid={(50.0, "full"): (-1.0, 0.1),     # corners (2,.5), (1,.5)
                                           (50.0, "x"): (0.25, -0.125)})
    rows = corner_rows(res, ("a", "b"), ["x"], (str, lambda b: f"b{b:g}"))
    assert rows == [["50", "0.5", "b1", "no", "-0.125"], ["50", "0.5", "b2", "yes", "0.25"]]
    from workbench.kinds.stop_accuracy.grid_map import result_cell
    cell = result_cell(res, "x", ("a", "b"))
    assert cell(50.0, 0.5, 1.0) == (-0.125, False) and cell(50.0, 0.5, 2.0) == (0.25, True)


def test_toy_mc_figure():
    from workbench.kinds.stop_accuracy.render import mc_figure
    f = mc_figure("cap", [("A", [("a", [0.1, -0.2])])], 0.3, (4.0, 3.0), unit="cm", scale=100)
    assert (f.name, f.caption, f.size) == ("mc-stop-errors", "cap", (4.0, 3.0))
    fig = Figure()
    f.draw(fig)
    assert fig.axes[0].get_xlabel() == "stop error (cm, + overshoot)"


def test_toy_section_and_ride_tables():
    from workbench.kinds.stop_accuracy.error_samples import ride_table, section_table
    from workbench.kinds.stop_accuracy.sections import CellStats
    cell = lambda m, j: CellStats(m, -m, 2 * m, m, j, 2 * j, 10.0 + m, 0.5, ())
    series = [("A", [cell(1.0, 0.1), cell(3.0, 0.3)]), ("B", [cell(2.0, 0.2), cell(2.0, 0.4)])]
    lines = section_table(series).splitlines()
    assert lines[0].startswith("| # | A mean abs | A mean | A var | B mean abs |")
    assert lines[2].startswith("| 1 | 1 | -1 | 2 | 2 |")
    assert lines[-1].startswith("| all | **2** |  |  | **2** |")           # mean over sections
    rows = ride_table(series, 12.0).splitlines()
    assert rows[2] == "| A | 0.2 | 0.6 | 0.5 | 12 | 12 |"          # mean, max jerk; run time


def test_toy_sections_and_ranges_tables():
    from types import SimpleNamespace

    from workbench.kinds.stop_accuracy.render import ranges_table, sections_table
    sec = lambda n, L: SimpleNamespace(name=n, length=L, source="toy")
    spec = SimpleNamespace(
        sections=SimpleNamespace(sections=(sec("A", 1000.0), sec("B", 1500.0)),
                                 ranges=(("mass", 0.9, 1.1),)),
        factors=(SimpleNamespace(name="mass", what="mass ratio", unit="1"),))
    rows = sections_table(spec, (30.0, 31.5)).splitlines()
    assert rows[2].startswith("| 1 | A | 1000 | 30 | toy |") and rows[3].startswith("| 2 | B |")
    assert ranges_table(spec).splitlines()[2].startswith("| `mass` | mass ratio | [0.9, 1.1] | 1 |")
