"""The error-grid map of :mod:`workbench.kinds.stop_accuracy.grid_map` on a
toy grid (no design): a panel per speed and third-factor value plus the
colour bar, every cell's signed error printed, infeasible cells marked,
large errors in white."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
from matplotlib.figure import Figure  # noqa: E402

from workbench.kinds.stop_accuracy.grid_map import GridAxis, plot_grid_map  # noqa: E402


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
