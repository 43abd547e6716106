"""The general case tables, delay cross-check and case figures
(:mod:`workbench.report.case_tables`, :mod:`workbench.report.delay_cross_check`,
:mod:`workbench.report.case_figures`) on a toy system that names no paper:
x' = -a x by explicit Euler (two cases, three step sizes) and the scalar
delay loop x' = -k x(t - h), whose exact delay margin is pi / (2 k)."""
from __future__ import annotations

import math
from types import SimpleNamespace

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from workbench.report.case_figures import (Palette, plot_cases, plot_on_curve,  # noqa: E402
                                           plot_phase_plane, snapped, time_window)
from workbench.report.case_tables import (CaseLevels, case_convergence_section,  # noqa: E402
                                          case_convergence_table, case_metric_table, case_rows,
                                          event_cell, fmt_finite)
from workbench.report.delay_cross_check import (delay_cross_check, envelope_verdict,  # noqa: E402
                                                plot_envelopes)

LABELS = {"t_half": ("time to x <= 1/2", "s", 3), "x_end": ("x at t = 2", "-", 3),
          "t_tenth": ("time to x <= 1/10", "s", 3)}


def _decay(a: float, dt: float) -> dict:
    """Metrics of x' = -a x, x(0) = 1, explicit Euler to t = 2 (NaN: not reached)."""
    n = int(round(2.0 / dt))
    x = (1.0 - a * dt) ** np.arange(n + 1)
    t = dt * np.arange(n + 1)
    out = {"x_end": float(x[-1])}
    for key, level in (("t_half", 0.5), ("t_tenth", 0.1)):
        k = np.flatnonzero(x <= level)
        out[key] = math.nan if k.size == 0 else float(
            t[k[0]] - dt * (level - x[k[0]]) / (x[k[0] - 1] - x[k[0]]))
    return out


CASES = {"slow": 0.5, "fast": 2.0}


def test_metric_table_one_column_per_case_and_dash_for_not_reached():
    metrics = [_decay(a, 0.01) for a in CASES.values()]
    md = case_metric_table(list(CASES), metrics, ("t_half", "t_tenth"), LABELS,
                           [["decays", ""] + ["yes", "yes"]])
    lines = md.splitlines()
    assert lines[0].split("|")[3:5] == [" `slow` ", " `fast` "]
    half = next(x for x in lines if x.startswith("| time to x <= 1/2"))
    cells = [float(c) for c in half.strip(" |").split(" | ")[2:]]
    assert cells == pytest.approx([math.log(2) / a for a in CASES.values()], rel=2e-2)
    assert all(len(c.replace(".", "").lstrip("0")) == 3 for c in half.strip(" |").split(" | ")[2:])
    tenth = next(x for x in lines if x.startswith("| time to x <= 1/10"))
    assert tenth.count("—") == 1                         # the slow case never gets there
    assert lines[-1].startswith("| decays")


def _levels(name, a, dt, tol, quarter: bool) -> CaseLevels:
    q1, q2 = _decay(a, dt), _decay(a, dt / 2)
    q4 = _decay(a, dt / 4) if quarter else None
    ok = {}
    for k in LABELS:
        # agreement of dt and dt/2, or of the Richardson estimate of the error in q4
        ok[k] = (abs(q1[k] - q2[k]) <= tol if q4 is None else
                 abs(q2[k] - q4[k]) <= tol)
    return CaseLevels(name, q1, q2, q4, ok)


def test_convergence_table_verdicts_and_rows_left_out():
    md = case_convergence_table([_levels("slow", 0.5, 0.1, 1e-2, False),
                                 _levels("fast", 2.0, 0.1, 1e-3, True)], LABELS)
    rows = [r for r in md.splitlines()[2:]]
    slow = [r for r in rows if "`slow`" in r]
    fast = [r for r in rows if "`fast`" in r]
    assert len(slow) == 2                        # t_tenth is NaN at every level: left out
    assert all("(dt, dt/2 " in r and r.rstrip(" |").endswith(("agree)", "differ)"))
               for r in slow)
    assert len(fast) == 3 and all("—" not in r for r in fast)
    assert any(r.endswith("| **no** |") for r in fast)   # first order: 1e-3 not met at dt = 0.1
    tight = case_convergence_table([_levels("fast", 2.0, 1e-4, 1e-3, True)], LABELS)
    assert "**no**" not in tight and tight.count("| yes |") == 3
    sec = case_convergence_section([_levels("fast", 2.0, 1e-4, 1e-3, True)], LABELS, 0.1,
                                   1e-3, 0.5)
    assert sec.startswith("## Convergence in the step size\n\nEvery metric computed at "
                          "dt = 0.1 s and dt/2 = 0.05 s") and sec.endswith(tight)
    assert "at order 0.5)" in sec and "rtol = 0.001 of" in sec


def test_case_rows_placeholder_for_missing_item():
    rows = case_rows([("a", 1.5), ("b", None)], lambda x: [x, 2 * x], ["—", "— (none)"])
    assert rows == [["`a`", 1.5, 3.0], ["`b`", "—", "— (none)"]]
    assert fmt_finite(math.inf, 3) == "—" and fmt_finite(2.0 / 3, 3) == "0.667"


def _delay_loop(k: float, h: float, dt: float, t_end: float):
    """x' = -k x(t - h), x = 1 on [-h, 0], explicit Euler with h = N dt."""
    n_h, n = int(round(h / dt)), int(round(t_end / dt))
    x = np.ones(n + n_h + 1)
    for i in range(n_h, n_h + n):
        x[i + 1] = x[i] - dt * k * x[i - n_h]
    return SimpleNamespace(t=dt * np.arange(n + 1), x=x[n_h:][None, :])


def _envelope_ratio(run) -> float:
    w = len(run.t) // 5
    e = np.abs(run.x[0])
    return float(e[-w:].max() / e[w:2 * w].max())


def test_delay_cross_check_of_a_scalar_delay_loop():
    k = 1.0
    h_star = math.pi / (2 * k)                   # exact margin of x' = -k x(t - h)
    facs = (0.5, 2.0)
    runs = [_delay_loop(k, f * h_star, h_star / 200, 60.0) for f in facs]
    ratios = [(f, f * h_star, _envelope_ratio(r)) for f, r in zip(facs, runs)]
    assert [envelope_verdict(r) for _, _, r in ratios] == ["decays", "grows"]
    halving = [SimpleNamespace(dt=0.1, error=2e-2, order=math.nan),
               SimpleNamespace(dt=0.05, error=1e-2, order=1.0)]
    md = delay_cross_check(
        linearisation="the toy loop", test_problem=(k, 0.7, 10.0), halving=halving,
        K_finite=[k], finite_margin=SimpleNamespace(h=h_star, omega=k), ratios_finite=ratios,
        K_synth=[0.1], synth_margin=SimpleNamespace(h=math.inf),
        ratios_synth=[(1.0, 0.5)], closing=".")
    assert "on the toy loop," in md and "x' = -x(t - 0.7)" in md
    assert "h* = 1.571 s at omega = 1 rad/s" in md
    assert "| 0.5 | 0.7854 |" in md and md.count("| grows |") == 1
    assert "∞ (no crossing" in md and md.endswith("stable.")
    fig = plt.figure()
    plot_envelopes(fig, facs, runs)
    assert [ln.get_label() for ln in fig.axes[0].get_lines()] == ["h = 0.5 h*", "h = 2 h*"]
    plt.close(fig)


def test_case_figure_colours_snapped_data_and_grid_ends():
    color_of = Palette({"slow": "tab:blue"}, default="tab:green")
    t = np.linspace(0.0, 2.0, 201)
    y = {n: np.exp(-a * t) for n, a in CASES.items()}
    fig = plt.figure()
    ax = fig.add_subplot(111)
    plot_cases(ax, [(n, t, y[n], n) for n in CASES], color_of, 1.0, ls=":")
    a, b = ax.get_lines()
    assert (a.get_color(), b.get_color()) == ("tab:blue", "tab:green")
    assert a.get_linestyle() == ":" and b.get_label() == "fast"
    moved = y["slow"] * (1 + 3 * np.finfo(float).eps)       # a 3-ulp move of the data
    assert np.array_equal(a.get_ydata(), snapped(moved, 1.0))
    assert not np.array_equal(moved, y["slow"])
    plt.close(fig)
    assert time_window(12.3, 1.0, 4.0) == (11, 15.0)
    fig = plt.figure()
    ax = fig.add_subplot(111)
    plot_phase_plane(ax, [(n, t, y[n]) for n in CASES], color_of, lw=0.8)
    path, start, end = ax.get_lines()[:3]                    # the slow case: path, o, x
    assert path.get_label() == "slow" and path.get_linewidth() == 0.8
    assert (start.get_marker(), end.get_marker()) == ("o", "x")
    assert end.get_xydata().tolist() == [[2.0, y["slow"][-1]]]
    assert {ln.get_color() for ln in ax.get_lines()[3:]} == {"tab:green"}
    plt.close(fig)
    # where on a saturation y = tanh(x) each toy case operated
    fig = plt.figure()
    ax = fig.add_subplot(111)
    grid = np.linspace(-2.0, 2.0, 41)
    plot_on_curve(ax, grid, np.tanh, [(n, y[n]) for n in CASES], color_of, "tanh")
    curve, slow, fast = ax.get_lines()
    assert curve.get_label() == "tanh" and curve.get_color() == "k"
    assert np.array_equal(curve.get_ydata(), np.tanh(grid))
    assert (slow.get_label(), slow.get_marker(), slow.get_color()) == ("slow", ".", "tab:blue")
    assert np.array_equal(fast.get_xydata(), np.column_stack([y["fast"], np.tanh(y["fast"])]))
    plt.close(fig)


def test_binned_fractions_last_bin_closed_and_empty_bin_dashed():
    from workbench.report.binned_fractions import binned_fraction_rows, binned_fraction_table
    gain = np.array([0.0, 0.1, 0.3, 0.6, 1.0, 1.0])         # a sampled toy gain
    unstable = gain < 0.2                                   # a flag per run
    rows = binned_fraction_rows(gain, 0.0, 1.0, 4, [unstable, ~unstable])
    assert [r[0] for r in rows] == ["[0, 0.25)", "[0.25, 0.5)", "[0.5, 0.75)", "[0.75, 1]"]
    assert [r[1] for r in rows] == [2, 1, 1, 2]             # 1.0 falls in the closed last bin
    assert rows[0][2:] == ["1", "0"] and rows[3][2:] == ["0", "1"]
    empty = binned_fraction_rows(gain, 0.0, 2.0, 4, [unstable])
    assert empty[3][1:] == [0, "—"] and sum(r[1] for r in empty) == len(gain)
    table = binned_fraction_table("gain", gain, 0.0, 1.0, 4, {"unstable": unstable}).splitlines()
    assert table[:2] == ["| gain | runs | fraction unstable |", "| :--- | ---: | ---: |"]
    assert table[2] == "| [0, 0.25) | 2 | 1 |" and len(table) == 2 + 4


def test_event_cell_says_whether_and_when():
    """report.case_tables.event_cell on the toy decay: x <= 1/10 by t = 2
    for the fast case only; ``where`` is not evaluated for the slow one."""
    slow, fast = (_decay(a, 0.01)["t_tenth"] for a in CASES.values())

    def boom():
        raise AssertionError("where() evaluated for an event that did not happen")
    assert event_cell(slow, boom) == "no"
    assert event_cell(fast, lambda: "fast", 3) == f"yes, t = {fmt_finite(fast, 3)} s (fast)"
