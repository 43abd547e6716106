"""The general switch-state feature (workbench.features.basin_points and its
tables, the escape event and the time-varying fate of basin_trajectory) on toy
loops that belong to no paper: z' = -g0 z + g1 z^3, whose basin is
|z| < sqrt(g0 / g1), and x' = +-x."""
import math

import numpy as np
import pytest
import sympy as sp

from workbench.errors import DesignError, ModelError
from workbench.features import basin_points as BP
from workbench.features.basin_points_render import gain_edge_text, gain_sweep_table, points_table
from workbench.features.basin_trajectory import limit_event, time_varying_fate
from workbench.outcome import Outcome
from workbench.reader import Reader
from workbench.features.basin_loop import at_gain, derivatives, modal_problem
from workbench.roa.check import largest_level_in_box

Z = sp.symbols("z", real=True)


def _loop(gain):
    return [-sp.Float(gain[0]) * Z + sp.Float(gain[1]) * Z**3]


G = sp.symbols("g0 g1", real=True)
F_G = [-G[0] * Z + G[1] * Z**3]                 # the loop with its gain as symbols
D_G = derivatives(F_G, (Z,))


def _make(gain):
    """candidate p -> (problem with V = (p / (2 g0)) z^2 (modal P), level of the box
    |z| <= 3), the loop's derivatives taken once with the gain symbolic."""
    f, derivs = at_gain(F_G, D_G, G, gain)

    def make(p, xs):
        return modal_problem(f, (Z,), (0.0,), [[-gain[0]]], [p], derivs=derivs, names=("z",),
                             points=xs, domain=((-3.0,), (3.0,)), c_search=math.inf)
    return make


def test_gain_loop_and_its_modal_problem():
    f, (J, H) = at_gain(F_G, D_G, G, (2.0, 0.5))
    direct = derivatives(_loop((2.0, 0.5)), (Z,))
    assert sp.simplify(f[0] - _loop((2.0, 0.5))[0]) == 0
    assert sp.simplify(J[0][0] - direct[0][0][0]) == 0 and sp.simplify(H[0][0][0] - 3.0 * Z) == 0
    prob, c = _make((2.0, 0.5))(1.0, [(0.5,)])
    assert prob.P_source == "optimised" and prob.P[0][0] > 0
    assert c == largest_level_in_box(prob.P, np.zeros(1), (-3.0,), (3.0,))


def _unstable(p, xs):
    raise ModelError("no Hurwitz linearisation")


def _judge(gain, x=(0.5,)):
    fn = sp.lambdify((Z,), _loop(gain), "math")
    return BP.point_in_basin((1.0, 2.0), _make(gain), x, fn, 20.0,
                             events=[limit_event(0, 3.0)])


def test_point_in_basin_and_fate():
    inside, outside = _judge((1.0, 1.0)), _judge((1.0, 1.0), (1.5,))
    assert (inside.outcome, inside.w, inside.hurwitz, inside.fate) == (
        Outcome.CERTIFIED, 1.0, True, "converges")
    assert (outside.outcome, outside.fate) == (Outcome.REFUTED, "diverges")
    # z' = +z + z^3 has no Hurwitz linearisation: no candidate gives a problem
    fn = sp.lambdify((Z,), [Z + Z**3], "math")
    v = BP.point_in_basin((1.0,), _unstable, (0.5,), fn, 5.0, events=[limit_event(0, 3.0)])
    assert (v.outcome, v.w, v.hurwitz, v.fate) == (Outcome.REFUTED, None, False, "diverges")


def test_check_points_and_their_table():
    pts = [("in", (0.5,)), ("out", (1.5,))]
    q, prob, chk = BP.check_points((1.0, 2.0), _make((1.0, 1.0)), pts, loop="toy", seed=0)
    assert q in (1.0, 2.0) and prob.P[0][0] == q and chk.loop == "toy"
    assert [p.verdict.outcome for p in chk.points] == [Outcome.CERTIFIED, Outcome.REFUTED]
    text = points_table(chk, ["converges", "diverges", "extra"], ["state", "z + 10", "V",
                                                                   "verdict", "fate"],
                        shift=(10.0,))
    lines = text.splitlines()
    assert lines[1] == "| :--- | ---: | ---: | :--- | :--- |" and len(lines) == 4
    assert lines[2].startswith("| `in` | 10.5 | ") and lines[2].endswith("| CERTIFIED | converges |")
    assert lines[3].startswith("| `out` | 11.5 | ") and "REFUTED | diverges" in lines[3]
    assert BP.check_points((1.0, 2.0), _unstable, pts, loop="toy") is None


def test_sampled_starts_box():
    st = BP.sampled_starts([(1.0, -0.5), (-2.0, 0.1)], 50, seed=3, scale=(2, 1.5),
                           pad=(1.0, 0.02), default=(2, 0.1))
    assert st[:2] == [(1.0, -0.5), (-2.0, 0.1)] and len(st) == 52
    arr = np.array(st[2:])
    assert np.all(np.abs(arr[:, 0]) <= 5.0) and np.all(np.abs(arr[:, 1]) <= 0.77)
    assert st == BP.sampled_starts([(1.0, -0.5), (-2.0, 0.1)], 50, seed=3, scale=(2, 1.5),
                                   pad=(1.0, 0.02), default=(2, 0.1))
    none = np.array(BP.sampled_starts([], 20, seed=0, scale=(1,), pad=(0,), default=(0.5,)))
    assert none.shape == (20, 1) and np.all(np.abs(none) <= 0.5)


def test_gain_entry_sweep_brackets_the_true_edge_and_its_table():
    """z = 0.5 is in the basin iff g1 < 4 g0: with g0 = 1 the edge is g1 = 4."""
    sw = BP.sweep_gain_entry(_judge, (0.5,), (1.0, 99.0), 1, [8.0, 0.5, 2.0], bisect=3,
                             compare=[("half", (0.5, 1.0)), ("double", (2.0, 1.0))])
    lo, hi = sw.edge
    assert 2.0 <= lo < 4.0 < hi and hi - lo == pytest.approx(6.0 / 8)
    assert sw.certified_below_edge and sw.grid_min == 0.5 and sw.gain == (1.0, 99.0)
    assert [r.gain[1] for r in sw.rows] == sorted(r.gain[1] for r in sw.rows)
    assert all(r.gain[0] == 1.0 for r in sw.rows) and sum(r.source == "edge" for r in sw.rows) == 3
    # g1 / g0 = 2 (certified), 0.5 (certified): the comparison rows keep their own g0
    assert [(r.source, r.verdict.outcome) for r in sw.compared] == [
        ("half", Outcome.CERTIFIED), ("double", Outcome.CERTIFIED)]
    text = gain_sweep_table(sw, ["g0", "g1", "row", "verdict", "p", "fate"], digits=(3, 5))
    lines = text.splitlines()
    assert lines[1] == "| ---: | ---: | :--- | :--- | ---: | :--- |"
    assert len(lines) == 2 + len(sw.rows) + 2
    assert "| 1 | 8 | grid | REFUTED |" in text and lines[-1].startswith("| 2 | 1 | double |")
    rule = gain_edge_text(sw, "g1", "z = 0.5", kept="With g0 = 1, ")
    assert rule.startswith(f"With g0 = 1, z = 0.5 lands in a certified basin for g1 <= {lo:.4g} "
                           "(every grid value from 0.5 up to it is certified), and not for g1 >= ")
    assert rule.endswith(f"[{lo:.4g}, {hi:.4g}] (bisected).")
    none = BP.GainSweep((0.5,), (1.0, 1.0), 1, sw.rows, (), None, 0.5, False)
    assert gain_edge_text(none, "g1", "z").startswith("No edge between certified")


def test_read_gain_sweep_of_a_toy_table():
    b = Reader("toy.toml", {"g_grid": [3.0, 1.0], "compare_gains": [[1.0, 2.0, 3]],
                            "bisect": 2}, "basin")
    s = BP.read_gain_sweep(b, "g_grid", 3)
    b.finish()
    assert s == BP.GainSweepSettings((1.0, 3.0), (("row 1", (1.0, 2.0, 3.0)),), "—", 2)
    bad = Reader("toy.toml", {"g_grid": [1.0, 2.0], "compare_gains": [[1.0, math.inf, 3.0]]},
                 "basin")
    with pytest.raises(DesignError, match=r"basin\.compare_gains\[0\]"):
        BP.read_gain_sweep(bad, "g_grid", 3)
    labels = Reader("toy.toml", {"g_grid": [1.0, 2.0], "compare_gains": [[1.0]],
                                 "compare_labels": ["a", "b"]}, "basin")
    with pytest.raises(DesignError, match=r"basin\.compare_labels"):
        BP.read_gain_sweep(labels, "g_grid", 1)



def test_load_gain_sweep_of_a_toy_design():
    top = lambda basin: Reader("toy.toml", {"basin": basin})
    s = BP.load_gain_sweep(top({"g_grid": [2.0, 1.0], "seed": 3}), "g_grid", 1)
    assert s == BP.GainSweepSettings((1.0, 2.0), (), "—", 4, 3)
    assert BP.load_gain_sweep(top({"g_grid": [2.0, 1.0], "enabled": False}), "g_grid", 1) is None
    assert BP.load_gain_sweep(Reader("toy.toml", {}), "g_grid", 1) is None
    with pytest.raises(DesignError, match=r"basin\.typo"):
        BP.load_gain_sweep(top({"g_grid": [2.0, 1.0], "typo": 1}), "g_grid", 1)


def test_time_varying_fate_of_toy_loops():
    ev = [limit_event(0, 3.0)]
    assert time_varying_fate(lambda t, x: [-x], (1.0,), 2.0, 10.0,
                             lambda t, x: abs(x[0]) < 1e-3, events=ev) == ("tracks", None)
    fate, t = time_varying_fate(lambda t, x: [x], (1.0,), 2.0, 10.0,
                                lambda t, x: True, events=ev)
    assert fate == "diverges" and t == pytest.approx(math.log(3.0), rel=1e-3)
    # a shifted limit: |x + 1| reaches 3 at x = 2
    _, t2 = time_varying_fate(lambda t, x: [x], (1.0,), 0.0, 10.0, lambda t, x: True,
                              events=[limit_event(0, 3.0, 1.0)])
    assert t2 == pytest.approx(math.log(2.0), rel=1e-3)
    assert time_varying_fate(lambda t, x: [math.sin(t)], (0.0,), 0.0, 1.0,
                             lambda t, x: False, events=ev) == ("undecided", None)


def _duffing():
    """GainLoop of x1' = x2, x2' = u + x1^3 under u = k1 x1 + k2 x2 (no paper):
    linearisation A + B K, a finite basin (x1^3 wins far out), escape |x1| = 4."""
    from workbench.features.basin_loop import GainLoop
    x1, x2, k1, k2 = sp.symbols("x1 x2 k1 k2", real=True)
    return GainLoop([x2, k1 * x1 + k2 * x2 + x1**3], (x1, x2), (k1, k2),
                    np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), (0.0, 0.0),
                    ("x1", "x2"), ((-4.0, -20.0), (4.0, 20.0)), (1.0, 10.0),
                    lambda w: [1.0, w], (limit_event(0, 4.0),), loop="toy Duffing")


def test_gain_loop_on_a_toy_system():
    loop, K = _duffing(), (-2.0, -3.0)
    f, (J, _), A_cl = loop.at(K)
    assert np.allclose(A_cl, [[0.0, 1.0], [-2.0, -3.0]])
    assert sp.simplify(J[1][0] - (-2.0 + 3 * loop.states[0] ** 2)) == 0
    assert loop.numeric(K)(1.0, 0.5) == [0.5, -2.0 - 1.5 + 1.0]
    res = loop.basin(K, [("near", (0.2, 0.0)), ("far", (3.0, 0.0))], n_traj=3,
                     T=20.0, scale=(1, 1), pad=(0, 0), default=(1, 1))
    chk, trajs = res.check, res.trajectories
    assert res.w in loop.candidates and chk.loop == "toy Duffing" and res.K == K
    assert [p.verdict.outcome for p in chk.points] == [Outcome.CERTIFIED, Outcome.REFUTED]
    assert [t.fate for t in trajs[:2]] == ["converges", "diverges"] and len(trajs) == 5
    near, far = loop.judge(K, (0.2, 0.0), 20.0), loop.judge(K, (3.0, 0.0), 20.0)
    assert (near.outcome, near.fate) == (Outcome.CERTIFIED, "converges")
    assert (far.outcome, far.fate) == (Outcome.REFUTED, "diverges")
    prob, est = loop.estimate(K, 1.0, [(0.2, 0.0)])
    assert prob.P_source == "optimised" and 0 < est.c_certified <= est.c_refuted
    assert est.point_verdict((0.2, 0.0)).outcome is Outcome.CERTIFIED
    # k1 > 0: no Hurwitz linearisation, hence no basin
    assert loop.basin((1.0, -3.0), [("near", (0.2, 0.0))], n_traj=0, T=1.0, scale=(1, 1),
                      pad=(0, 0), default=(1, 1)) is None


def test_gain_loop_sweep_on_a_toy_system():
    """k2 of the toy Duffing loop swept at k1 = -2: certified for k2 well below 0,
    no basin from k2 = 0 on (A + B K not Hurwitz), the edge bisected in between."""
    loop = _duffing()
    sw = loop.sweep((-2.0, 0.0), (0.3, 0.0), 1, [1.0, -3.0, 0.0], 20.0, point=(1.3, 0.0),
                    compare=[("far", (-2.0, -3.0))], bisect=3)
    assert sw.point == (1.3, 0.0) and sw.gain == (-2.0, 0.0) and sw.grid_min == -3.0
    assert [r.gain[1] for r in sw.rows] == sorted(r.gain[1] for r in sw.rows)
    assert len(sw.rows) == 3 + 3 and sw.edge is not None and -3.0 <= sw.edge[0] < sw.edge[1] <= 0
    by = {r.gain[1]: r.verdict for r in sw.rows}
    assert by[-3.0].outcome is Outcome.CERTIFIED and by[-3.0].fate == "converges"
    assert by[0.0].outcome is Outcome.REFUTED and not by[0.0].hurwitz
    assert sw.compared[0].source == "far" and sw.compared[0].verdict == by[-3.0]


def test_switch_basin_quantities_and_figure_of_a_toy_switched_run():
    """The Duffing toy's basin judged at two switch states, a one-state loop
    z' = 1 frozen at another switch (no equilibrium: REFUTED), the gain sweep:
    the claimable quantities of all three (basin_switch.switch_basin_quantities),
    the frozen switches' table and the figure on one axes (basin_plot.basin_figure)."""
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure as MplFigure

    from workbench.features.basin_plot import BasinPlotStyle, basin_figure
    from workbench.features.basin_scalar import FrozenSwitch, scalar_verdict
    from workbench.features.basin_scalar_render import frozen_switch_table, scalar_method_text
    from workbench.features.basin_switch import (switch_basin_quantities,
                                                 switch_basin_quantity_names)
    loop, K = _duffing(), (-2.0, -3.0)
    res = loop.basin(K, [("near", (0.2, 0.0)), ("far", (3.0, 0.0))], n_traj=2, T=20.0,
                     scale=(1, 1), pad=(0, 0), default=(1, 1))
    assert res.judged == [("near", Outcome.CERTIFIED, "converges"),
                          ("far", Outcome.REFUTED, "diverges")]
    z = sp.symbols("z", real=True)
    sw = FrozenSwitch("up", (0.0, 0.5), 1.0, scalar_verdict(1 + 0 * z, z, 0.5, -2.0, 2.0),
                      "diverges", 1.5)
    assert sw.judged == ("up", Outcome.REFUTED, "diverges")
    sweep = loop.sweep((-2.0, 0.0), (0.2, 0.0), 1, [-3.0, -1.0], 20.0, bisect=1)
    labels = ["near", "far", "up", "never"]
    judged = {"fixed": res.judged, "frozen": [sw.judged]}
    q = switch_basin_quantities(res.check.estimate, labels, judged, sweep, "k2")
    assert set(q) == switch_basin_quantity_names(labels, ("fixed", "frozen"), "k2")
    assert q["basin.c_certified"] == res.check.estimate.c_certified
    assert (q["switch.fixed[far].in_basin"], q["switch.frozen[up].fate"]) == ("REFUTED",
                                                                              "diverges")
    assert q["switch.frozen[never].in_basin"] is None and "basin.k2_safe_max" in q
    bare = switch_basin_quantities(res.check.estimate, labels, judged)
    assert set(bare) == switch_basin_quantity_names(labels, ("fixed", "frozen"))
    assert not any(k.startswith("basin.k2") for k in bare)
    table = frozen_switch_table([sw], ["s", "y", "z", "r", "frozen", "verdict", "fate"], 2.0,
                                index=1, name="z", at="t_s")
    assert "| `up` | 0 | 0.5 | 1 | no equilibrium from the state up to z = 2" in table
    assert "| REFUTED | diverges: \\|z\\| = 2 at t_s + 1.5 s |" in table
    from workbench.features.basin_points_render import points_verdict_text
    note = points_verdict_text("toy", "\"diverges\": |x1| reaches 4")
    assert note.startswith("CERTIFIED: V at the state is below c_certified, so the toy loop")
    assert note.endswith("what the toy trajectory does (\"diverges\": |x1| reaches 4).")
    method = scalar_method_text(2.0, name="z")
    assert method.startswith("The frozen loop has one state, z' = g(z), so")
    assert "between the state and |z| = 2 (the sign of g proven" in method
    fig = MplFigure()
    ax = basin_figure(fig, res.check.estimate, res.check.points, res.trajectories, (0, 1),
                      BasinPlotStyle(), ("x1", "x2"), ylim=(-5.0, 5.0),
                      extra=lambda a: a.axhline(1.0, label="mark"))
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_ylim()) == ("x1", "x2", (-5.0, 5.0))
    assert "mark" in [t.get_text() for t in ax.get_legend().get_texts()]


def test_gain_loop_sweep_shared_once_per_run(tmp_path, monkeypatch):
    """GainLoop.sweep with ``share``: computed once in the process, read from
    the run folder by another process of the run (the in-process results
    emptied), computed again for another argument; without ``share`` every
    call computes."""
    from workbench import memo
    from workbench.features import basin_loop
    loop, calls = _duffing(), []
    orig = basin_loop.sweep_gain_entry
    monkeypatch.setattr(basin_loop, "sweep_gain_entry",
                        lambda *a, **k: calls.append(1) or orig(*a, **k))
    monkeypatch.setenv(memo.CACHE_ENV, str(tmp_path))
    monkeypatch.setattr(memo, "_RESULTS", {})
    args = ((-2.0, 0.0), (0.2, 0.0), 1, [-3.0, -1.0], 20.0)
    a = loop.sweep(*args, bisect=1, share=("toy.sweep", "duffing"))
    assert loop.sweep(*args, bisect=1, share=("toy.sweep", "duffing")) is a and len(calls) == 1
    monkeypatch.setattr(memo, "_RESULTS", {})
    b = loop.sweep(*args, bisect=1, share=("toy.sweep", "duffing"))
    assert b == a and len(calls) == 1 and len(list(tmp_path.glob("*.pickle"))) == 1
    loop.sweep(*args, bisect=2, share=("toy.sweep", "duffing"))
    assert len(calls) == 2
    assert loop.sweep(*args, bisect=1) == a and len(calls) == 3
    assert a.point == (0.2, 0.0) and [r.gain for r in a.rows][:2] == [(-2.0, -3.0), (-2.0, -2.0)]
