"""Scenario figures of the delay-feedback kind: plotted definitions and
reference lines (issue 33, item 7: the wheel-slip plot shows the creep ratio,
the spacing plot the safe-gap line)."""
from __future__ import annotations

from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

from workbench.design import load_design  # noqa: E402
from workbench.kinds.delay_feedback.render import _plot_run  # noqa: E402
from workbench.report.markdown import Figure  # noqa: E402
from workbench.report.figures import figure_png  # noqa: E402

from tests.test_delay_feedback import _cli_error, write  # noqa: E402

DEFS = '''
[definitions]
s = "sin(x)"
'''
SCEN = '''
[[scenarios]]
name = "kick"
x0 = {{ x = 0.7 }}
t_end = 1.0
dt = 0.01
{keys}
'''
GOOD = 'plot = ["s"]\nlines = { s = { value = 0.5, label = "half" }, x = { value = 0.6, label = "x line" } }'


def _design(tmp_path, keys=GOOD):
    return write(tmp_path, extra=SCEN.format(keys=keys),
                 replace={"[equations]": DEFS + "\n[equations]"})


def test_plot_and_lines_are_read_and_drawn(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = load_design(_design(tmp_path)).spec
    sc = spec.scenarios[0]
    assert sc.plot == ("s",) and sc.lines == {"s": (0.5, "half"), "x": (0.6, "x line")}
    t = np.linspace(0.0, 1.0, 11)
    x = 0.5 + 0.2 * np.exp(-t)
    run = SimpleNamespace(t=t, x=x[None, :], u=np.zeros((1, t.size)), dt=0.1)
    r = SimpleNamespace(run=run, scenario=sc)
    import matplotlib.pyplot as plt
    fig = plt.figure()
    _plot_run(fig, r, spec.plant)
    axes = fig.axes
    assert [a.get_ylabel() for a in axes] == ["x (rad)", "s", "u (rad/s)"]
    # the definition's panel is sin(x) of the run, each panel with its line
    np.testing.assert_allclose(axes[1].lines[0].get_ydata(), np.sin(x), rtol=1e-15)
    assert axes[1].lines[1].get_ydata()[0] == 0.5 and axes[0].lines[1].get_ydata()[0] == 0.6
    assert len(axes[2].lines) == 1
    plt.close(fig)
    png = figure_png(Figure("f", "c", lambda f: _plot_run(f, r, spec.plant)))
    assert png.startswith(b"\x89PNG")


@pytest.mark.parametrize("keys, words", [
    ('plot = ["nope"]', ["scenarios[0].plot", "names of [definitions]: s"]),
    ('plot = ["s", "s"]', ["scenarios[0].plot", "distinct"]),
    ('lines = { u = { value = 1.0, label = "l" } }', ["scenarios[0].lines.u", "a state or"]),
    ('plot = ["s"]\nlines = { s = { value = 1.0 } }', ["scenarios[0].lines.s.label"]),
    ('lines = { x = { value = 1.0, label = "l", colour = "red" } }', ["lines.x.colour"]),
    ('plot = ["s"]\nparameters = { a = [[0.0, 2.0], [0.5, 3.0]] }',
     ["scenarios[0].plot", "parameter schedule"]),
])
def test_bad_figure_keys_exit_2_with_one_line(tmp_path, monkeypatch, capsys, keys, words):
    monkeypatch.chdir(tmp_path)
    line = _cli_error(_design(tmp_path, keys), capsys)
    for w in words:
        assert w in line, line
