"""The general basin feature on toy loops that belong to no paper:
trajectories and fates (workbench.features.basin_trajectory), the choice of P
and the staged estimate (basin_select), the best verdict and the gain sweep
(basin_sweep) and the figure (basin_plot)."""
import matplotlib
import numpy as np
import pytest
import sympy as sp

from workbench.features import basin_select as SEL
from workbench.features.basin_plot import BasinPlotStyle, plot_basin
from workbench.features.basin_sweep import best_verdict, gain_edge
from workbench.features.basin_trajectory import trajectory
from workbench.outcome import Outcome
from workbench.roa import BasinProblem, estimate_basin
from workbench.roa.check import PointCheck, check_basin, largest_level_in_box

matplotlib.use("Agg")
X, Y = sp.symbols("x y", real=True)
# x' = -x + x^3, y' = -y: the true basin is |x| < 1 (y free)
F = [-X + X**3, -Y]
FN = sp.lambdify((X, Y), F, "math")


def _escape(t, s):
    return 3.0 - abs(s[0])


_escape.terminal = True


def test_fates_of_the_toy_loop():
    inside = lambda p: p[:, 0] ** 2 + p[:, 1] ** 2 <= 0.01          # noqa: E731
    conv = trajectory(FN, (0.5, 0.5), 20.0, inside, events=[_escape], escape="diverges")
    div = trajectory(FN, (1.2, 0.0), 20.0, inside, events=[_escape], escape="diverges")
    stay = trajectory(FN, (1.0, 0.0), 1.0, inside, events=[_escape], escape="diverges")
    assert (conv.fate, div.fate, stay.fate) == ("converges", "diverges", "undecided")
    assert inside(conv.path[-1:])[0] and abs(div.path[-1, 0]) == pytest.approx(3.0)
    drawn = trajectory(FN, (0.5, 0.5), 20.0, inside, path_dt=0.1)
    # the drawn path is the dense output every 0.1 s, cut at the certified set
    assert drawn.fate == "converges" and inside(drawn.path[-1:])[0]
    assert not inside(drawn.path[:-1]).any() and len(drawn.path) < len(conv.path) + 50


def _problem(q, x_max=0.9):
    """V = x^2 + q y^2 on the box |x| <= x_max, |y| <= 2."""
    P = np.diag([1.0, q])
    prob = BasinProblem(F, (X, Y), (0.0, 0.0), P, P_source="candidate", names=("x", "y"))
    return prob, largest_level_in_box(P, np.zeros(2), (-x_max, -2.0), (x_max, 2.0))


@pytest.mark.parametrize("eager", [False, True])
def test_best_estimate_certifies_the_points_it_can(monkeypatch, eager):
    """A point far out in y is certified only with a small weight on y; the
    coarse pass (covers of losing candidates skipped) chooses as the eager one."""
    if eager:
        monkeypatch.setenv(SEL.EAGER_ENV, "1")
    else:
        monkeypatch.delenv(SEL.EAGER_ENV, raising=False)
    pts = [(0.3, 1.6)]
    q, prob, est = SEL.best_estimate((4.0, 0.25), _problem, pts)
    assert q == 0.25 and est.point_verdict(pts[0]).outcome is Outcome.CERTIFIED
    assert SEL.score(est, pts) <= SEL.score_bound(prob, min(est.c_search, est.c_refuted), pts)
    assert SEL.best_estimate((), _problem, pts) is None


def test_deferred_estimate_answers_as_the_full_one():
    prob, c = _problem(1.0, 2.0)          # V' = 0 at x = 1: refuted from V = 1 on
    d = SEL.DeferredEstimate(prob, c, seed=0)
    far, near = (1.5, 0.0), (0.2, 0.1)
    assert d.outcome(far) is Outcome.REFUTED
    full = estimate_basin(prob, c, seed=0)
    assert d.est == full
    assert d.outcome(near) is full.point_verdict(near).outcome is Outcome.CERTIFIED
    assert d.enters(np.array([far, near])) and not d.enters(np.array([far, (1.4, 0.0)]))


Z = sp.symbols("z", real=True)


def _verdict(k: float) -> Outcome:
    """z' = -z + k z^3 (basin |z| < 1/sqrt(k)): is z = 0.5 certified?"""
    chk = check_basin([-Z + sp.Float(k) * Z**3], (Z,), (0.0,), A_cl=[[-1.0]],
                      points=[("z", (0.5,))], domain=((-4.0,), (4.0,)))
    return chk.points[0].verdict.outcome


def test_gain_edge_brackets_the_true_edge():
    """The true edge is k = 4; the sweep certifies only gains below it."""
    sw = gain_edge(lambda k, src: (k, src, _verdict(k)), [8.0, 0.5, 2.0, 1.0],
                   ok=lambda r: r[2] is Outcome.CERTIFIED, gain=lambda r: r[0], bisect=3)
    lo, hi = sw.edge
    assert 2.0 <= lo < 4.0 < hi + 0.75 and hi - lo == pytest.approx(6.0 / 8)
    assert sw.certified_below_edge and [r[0] for r in sw.rows] == sorted(r[0] for r in sw.rows)
    assert sum(r[1] == "edge" for r in sw.rows) == 3


def test_best_verdict_stops_at_the_first_certified():
    seen = []
    out = {1: Outcome.REFUTED, 2: Outcome.INCONCLUSIVE, 3: Outcome.CERTIFIED, 4: Outcome.REFUTED}
    assert best_verdict([1, 2, 3, 4], lambda c: seen.append(c) or out[c]) == (Outcome.CERTIFIED, 3)
    assert seen == [1, 2, 3]
    assert best_verdict([1], out.get) == (Outcome.REFUTED, None)


def test_figure_of_the_toy_basin():
    from matplotlib.figure import Figure
    prob, c = _problem(1.0, 2.0)
    est = estimate_basin(prob, c, seed=0)
    pts = (PointCheck("a", (0.5, 0.5), est.point_verdict((0.5, 0.5))),)
    inside = lambda p: prob.V(p) <= est.c_certified                    # noqa: E731
    trs = [trajectory(FN, x0, 5.0, inside, events=[_escape]) for x0 in ((0.5, 0.5), (1.2, 0.0))]
    ax = Figure().add_subplot(111)
    plot_basin(ax, est, pts, trs, (0, 1), BasinPlotStyle(point_label="p {label}: {outcome}",
                                                          clip=((-0.4, 2.0), None)))
    labels = [ln.get_label() for ln in ax.get_lines()]
    assert "p a: CERTIFIED" in labels and "sampled: leaves the domain" in labels
    sampled = ax.get_lines()[-3]          # from (1.2, 0) to |x| = 3, clipped at x = 2
    assert sampled.get_label() == "sampled: leaves the domain"
    assert np.max(sampled.get_xdata()) == 2.0


def test_scalar_verdicts_of_toy_loops():
    """One-state loops: no equilibrium ahead (REFUTED, |x'| >= 1 proven), and the
    stable equilibrium x* = 1 of x' = x - x^3 reached from either side."""
    from workbench.features.basin_scalar import scalar_verdict
    none = scalar_verdict(1 + Z**2, Z, 0.0, -1.0, 2.0)
    assert (none.outcome, none.why, none.direction, none.star) == (
        Outcome.REFUTED, "no equilibrium", 1.0, None)
    assert 0.5 < none.rate <= 1.0
    for x_s in (0.05, 0.5, 1.6):
        sv = scalar_verdict(Z - Z**3, Z, x_s, -2.0, 2.0)
        assert sv.outcome is Outcome.CERTIFIED and sv.star == pytest.approx(1.0)
        assert sv.direction == (1.0 if x_s < 1 else -1.0) and sv.level[1] > 0


def test_point_quantities_of_a_toy_check():
    from workbench.features.basin import level_quantities, point_quantities, point_quantity_names
    chk = check_basin([-Z + Z**3], (Z,), (0.0,), A_cl=[[-1.0]],
                      points=[("in", (0.5,)), ("out", (1.5,))], domain=((-2.0,), (2.0,)))
    q = point_quantities(chk, "toy[{label}]", fate=["converges", "diverges"])
    assert list(q) == ["toy[in].in_basin", "toy[in].fate", "toy[out].in_basin", "toy[out].fate"]
    assert (q["toy[in].in_basin"], q["toy[out].in_basin"]) == ("CERTIFIED", "REFUTED")
    assert set(q) == point_quantity_names(["in", "out"], "toy[{label}]", ("in_basin", "fate"))
    lv = level_quantities(chk.estimate)
    assert 0 < lv["basin.c_certified"] <= lv["basin.c_refuted"] <= 0.5 * 1.0 + 1e-9


def test_frozen_switch_of_a_toy_tracking_loop_and_its_text():
    """x' = -(x - r(t)), r(t) = 0.5 + 0.1 sin t, switched on at x = 0.2: frozen at
    r(0) the state moves to x* = 0.5 (CERTIFIED), the time-varying loop tracks;
    x' = 1 + x^2 has no equilibrium ahead (REFUTED: the rate and the time)."""
    import math
    from workbench.features.basin_scalar import FrozenSwitch, scalar_verdict
    from workbench.features.basin_scalar_render import scalar_verdict_text
    from workbench.features.basin_trajectory import limit_event, time_varying_fate
    ref = lambda t: 0.5 + 0.1 * math.sin(t)                          # noqa: E731
    fate = time_varying_fate(lambda t, x: [-(x - ref(t))], (0.2,), 0.0, 20.0,
                             lambda t, x: abs(x[0] - ref(t)) < 0.1, events=[limit_event(0, 2.0)])
    sw = FrozenSwitch("on", (0.2,), ref(0.0), scalar_verdict(-(Z - ref(0.0)), Z, 0.2, -2.0, 2.0),
                      *fate)
    assert (sw.outcome, sw.fate, sw.t_fate) == (Outcome.CERTIFIED, "tracks", None)
    assert sw.verdict.star == pytest.approx(sw.reference)
    assert scalar_verdict_text(sw.verdict, 0.2, 2.0, name="z").startswith("equilibrium z* = 0.5 (")
    none = scalar_verdict(1 + Z**2, Z, 0.0, -2.0, 2.0)
    text = scalar_verdict_text(none, 0.0, 2.0, name="z")
    # |z'| >= 1 proven (rounded down), so z = 2 within 2 / 1 s (rounded up)
    assert text.startswith("no equilibrium from the state up to z = 2: |z'| >= ")
    rate = float(text.split(">= ")[1].split(" ")[0])
    assert rate <= none.rate and float(text.split("within ")[1].split(" ")[0]) >= 2.0 / none.rate
    down = scalar_verdict(-1 - Z**2, Z, 0.5, -2.0, 2.0)
    text = scalar_verdict_text(down, 0.5, 2.0, name="z")
    # from 0.5 down to -2: a distance of 2.5
    assert "down to z = −2" in text
    assert float(text.split("within ")[1].split(" ")[0]) >= 2.5 / down.rate


def test_frozen_switch_from_a_toy_field_with_a_symbolic_reference():
    """frozen_switch on a two-state toy (y slow, x fast) tracking r(t) = 0.5 +
    0.1 sin t: x' = -2 (x - r) + dr/dt frozen at t0 = 0 goes to x* = r(0) = 0.5
    (CERTIFIED) and the time-varying loop tracks; frozen at pi/2, x* = 0.6. The
    unstable x' = x - r from x = 0.6 > r(0) has no equilibrium ahead (REFUTED) and
    the time-varying loop reaches |x| = 2 (its escape), at a time > 0."""
    import math
    from workbench.features.basin_scalar import frozen_switch
    from workbench.features.basin_trajectory import limit_event
    R, DR = sp.symbols("r dr", real=True)
    ref = lambda t, s: (0.5 + 0.1 * math.sin(t), 0.1 * math.cos(t))     # noqa: E731
    args = dict(T=10.0, settled=lambda s, r: abs(s[1] - r) < 0.01,
                events=[limit_event(1, 2.0)], name="x")
    stable = [-0.01 * Y, -2 * (X - R) + DR]
    sw = frozen_switch("on", stable, (Y, X), (R, DR), (1.0, 0.2), 1, ref, 0.0, -2.0, 2.0, **args)
    assert (sw.outcome, sw.fate, sw.t_fate, sw.x) == (Outcome.CERTIFIED, "tracks", None, (1.0, 0.2))
    assert sw.reference == pytest.approx(0.5) and sw.verdict.star == pytest.approx(0.5)
    later = frozen_switch("on", stable, (Y, X), (R, DR), (1.0, 0.2), 1, ref, 0.0, -2.0, 2.0,
                          t_frozen=math.pi / 2, **args)
    assert later.verdict.star == pytest.approx(0.6) and later.fate == "tracks"
    bad = frozen_switch("up", [0 * Y, X - R], (Y, X), (R, DR), (1.0, 0.6), 1, ref, 0.0, -2.0,
                        2.0, **args)
    assert (bad.outcome, bad.verdict.why, bad.fate) == (Outcome.REFUTED, "no equilibrium",
                                                        "diverges")
    assert 0 < bad.t_fate < 10.0
