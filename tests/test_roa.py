"""Region-of-attraction core (workbench/roa): interval enclosures, certified
levels against analytic basins, soundness, refutation, closed outcomes."""
import ast
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import minimize_scalar

from workbench.outcome import Outcome
from workbench.roa import BasinProblem, estimate_basin, lyapunov_P
from workbench.roa.certify import ball_argument
from workbench.roa.check import check_basin
from workbench.roa.interval import IntervalFunction, UnsupportedExpression
from workbench.roa.render import render_basin_markdown

x, y = sp.symbols("x y", real=True)


def cubic_problem():
    """x' = -x + x^3, y' = -y: the basin is |x| < 1 exactly; with V = x^2 + y^2,
    V' = 2 x^2 (x^2 - 1) - 2 y^2 < 0 iff 0 < x^2 < 1 or y != 0 ... the lowest
    level holding V' >= 0 away from 0 is V = 1 (at (+-1, 0))."""
    P = lyapunov_P(-np.eye(2), 2 * np.eye(2))          # = I
    return BasinProblem([-x + x**3, -y], (x, y), (0.0, 0.0), P)


def vdp_problem():
    """Van der Pol in reversed time, x' = -y, y' = x - (1 - x^2) y: the origin
    is stable, its basin bounded by the (unstable) limit cycle (Khalil, Nonlinear
    Systems, example 8.5); P from the Lyapunov equation with Q = I."""
    P = lyapunov_P(np.array([[0.0, -1.0], [1.0, -1.0]]))
    return BasinProblem([-y, x - (1 - x**2) * y], (x, y), (0.0, 0.0), P)


def vdp_exact_level(P):
    """min over directions of V at the first radius with V' = 0: with
    e = r (cos t, sin t), V' = r^2 a(t) + r^4 b(t) (f = linear + cubic), so
    r^2 = -a / b where b > 0 (closed form, independent of workbench.roa)."""
    def level(t):
        u = np.array([np.cos(t), np.sin(t)])
        lin = np.array([-u[1], u[0] - u[1]])
        cub = np.array([0.0, u[0] ** 2 * u[1]])
        a, b = 2 * u @ P @ lin, 2 * u @ P @ cub
        return (-a / b) * (u @ P @ u) if b > 1e-12 else np.inf
    ts = np.linspace(0, np.pi, 20001)
    k = int(np.argmin([level(t) for t in ts]))
    res = minimize_scalar(level, bounds=(ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)]),
                          method="bounded", options={"xatol": 1e-12})
    return res.fun


@pytest.mark.parametrize("expr", [
    sp.exp(-3 * x) * y - x / (2 + y**2),
    (1 - x) ** 3 / (y + 5) + sp.Rational(1, 3) * x * y,
    sp.Piecewise((sp.exp(x) - 1, x >= 0), (-x**2 + x, True)) * (y - sp.pi),
    sp.log(x + 4) * sp.sqrt(y + 3) + sp.Abs(x - y) + sp.Max(x, y),
    (x + 2.5) ** sp.Rational(3, 2) - 0.1 * (y + 3) ** 0.7,
    sp.tanh(3 * x) * sp.atan(y) + sp.sinh(x - y) - sp.asinh(2 * y),
    sp.sin(4 * x + 1) * sp.cos(3 * y) - sp.cos(x * y) + sp.sign(x) * sp.Heaviside(y),
])
def test_interval_encloses_high_precision_values(expr):
    rng = np.random.default_rng(7)
    fn = IntervalFunction([expr], (x, y))
    c = rng.uniform(-1, 1, (20, 2))
    w = rng.uniform(0, 0.5, (20, 2)) * rng.integers(0, 2, (20, 1))   # some degenerate boxes
    lo, hi = c - w, c + w
    (iv,), _ = fn(lo, hi)
    for k in range(20):
        for _ in range(3):
            p = lo[k] + rng.random(2) * (hi[k] - lo[k])
            val = sp.N(expr.subs({x: sp.Float(p[0], 60), y: sp.Float(p[1], 60)}), 50)
            assert iv.lo[k] <= val <= iv.hi[k]


def test_unsupported_function_is_named():
    with pytest.raises(UnsupportedExpression, match="erf"):
        IntervalFunction([sp.erf(x)], (x,))


def test_cubic_known_basin_is_bracketed():
    est = estimate_basin(cubic_problem(), 4.0)
    assert est.c_certified <= 1.0 <= est.c_refuted
    assert est.c_certified > 0.999 and est.c_refuted < 1.0 + 1e-9
    assert est.c_inner == 0.0 and est.c_ball > 0
    cx = np.array(est.counterexample)
    assert abs(abs(cx[0]) - 1.0) < 1e-6


def test_vanderpol_reversed_against_closed_form():
    prob = vdp_problem()
    c_star = vdp_exact_level(prob.P)
    est = estimate_basin(prob, 10.0)
    assert est.c_certified <= c_star <= est.c_refuted * (1 + 1e-9)
    assert est.c_refuted / est.c_certified - 1 < 2e-3


@pytest.mark.parametrize("make", [cubic_problem, vdp_problem])
def test_no_certified_level_holds_a_sampled_point_with_vdot_nonnegative(make):
    prob = make()
    est = estimate_basin(prob, 10.0)
    rng = np.random.default_rng(11)
    L = np.linalg.cholesky(prob.P)
    u = rng.standard_normal((200_000, 2))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    u *= np.sqrt(rng.random((200_000, 1)))
    X = (u * np.sqrt(est.c_certified)) @ np.linalg.inv(L.T).T
    # points at the level itself too (the boundary is where V' first vanishes)
    X = np.concatenate([X, u / np.linalg.norm(u, axis=1, keepdims=True)
                        * np.sqrt(est.c_certified * (1 - 1e-9)) @ np.linalg.inv(L.T).T])
    V = prob.V(X)
    keep = (V > 1e-10) & (V <= est.c_certified)
    assert keep.sum() > 300_000
    assert np.all(prob.vdot_numeric(X[keep]) < 0)


def test_refutation_and_point_verdicts():
    prob = cubic_problem()
    est = estimate_basin(prob, 4.0)
    cx = np.array(est.counterexample)
    assert prob.vdot_numeric(cx[None, :])[0] >= 0
    assert prob.V(cx[None, :])[0] <= est.c_refuted
    assert est.verdict(1.01).outcome is Outcome.REFUTED
    assert est.verdict(0.5).outcome is Outcome.CERTIFIED
    assert est.point_verdict((0.5, 0.5)).outcome is Outcome.CERTIFIED
    assert est.point_verdict((0.2, 1.01)).outcome is Outcome.REFUTED
    # a point of the true basin beyond the level set: V cannot certify it
    assert est.point_verdict((0.5, 2.0)).outcome is Outcome.REFUTED


def test_coarse_cover_is_inconclusive_between_the_levels():
    est = estimate_basin(vdp_problem(), 10.0, min_width=2.0**-4)
    assert 0 < est.c_certified < est.c_refuted
    mid = 0.5 * (est.c_certified + est.c_refuted)
    assert est.verdict(mid).outcome is Outcome.INCONCLUSIVE
    # a level is never INFEASIBLE (that is a diagnosis of a synthesis); the
    # tables print the outcome's name
    levels = {Outcome.CERTIFIED, Outcome.REFUTED, Outcome.INCONCLUSIVE}
    assert {o.name for o in levels} == {"CERTIFIED", "REFUTED", "INCONCLUSIVE"}
    for c in (0.0, est.c_certified, mid, est.c_refuted, 1e9):
        assert est.verdict(c).outcome in levels


def test_equilibrium_residual_leaves_an_inner_set():
    # f(x*) = (1e-9, 0) at the x* we give: V' ~ 2 e'P delta near x* is not negative
    prob = BasinProblem([-x + x**3 + 1e-9, -y], (x, y), (0.0, 0.0), np.eye(2))
    ball = ball_argument(prob, 0.5)
    assert ball.c_ball > 0 and 0 < ball.c_inner < 1e-15
    est = estimate_basin(prob, 4.0)
    assert 0 < est.c_inner < 1e-15 and est.c_certified > 0.99


def test_ball_argument_refuses_an_undetermined_piecewise():
    f = [sp.Piecewise((-x, x >= 0), (-2 * x, True)), -y]
    prob = BasinProblem(f, (x, y), (0.0, 0.0), np.eye(2))
    assert ball_argument(prob, 1.0).c_ball == 0.0
    est = estimate_basin(prob, 1.0)
    assert est.c_certified == 0.0                      # nothing proven, nothing refuted
    assert est.verdict(0.5).outcome is Outcome.INCONCLUSIVE


def test_check_basin_renders_its_verdicts():
    chk = check_basin([-x + x**3, -y], (x, y), (0.0, 0.0), A_cl=-np.eye(2),
                      points=[("inside", (0.3, 0.1)), ("outside", (1.5, 0.0))],
                      loop="test loop")
    out = [p.verdict.outcome for p in chk.points]
    assert out == [Outcome.CERTIFIED, Outcome.REFUTED]
    md = render_basin_markdown(chk)
    assert "test loop" in md and "CERTIFIED" in md and "REFUTED" in md
    assert "| c_certified" in md


def test_roa_respects_the_layers():
    root = Path(__file__).resolve().parents[1] / "workbench" / "roa"
    banned = ("kinds", "features", "tuning", "papers", "report", "design", "sim", "lmi", "margins")
    for f in root.glob("*.py"):
        for node in ast.walk(ast.parse(f.read_text())):
            if isinstance(node, ast.ImportFrom) and node.level >= 1 and node.module:
                assert node.module.split(".")[0] not in banned, (f.name, node.module)
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                mod = getattr(node, "module", None) or ""
                assert not any(mod.startswith(f"workbench.{b}") for b in banned)


@pytest.mark.parametrize("A", [np.array([[0.0, -1.0], [1.0, -1.0]]),          # complex pair
                               np.array([[-0.04, 57.7], [0.006, -12.65]])])    # slow + fast
def test_modal_P_is_a_lyapunov_matrix(A):
    from workbench.roa import modal_P
    P = modal_P(A, [1.0, 10.0] if np.isreal(np.linalg.eigvals(A)).all() else None)
    assert np.all(np.linalg.eigvalsh(P) > 0)
    assert np.all(np.linalg.eigvalsh(P @ A + A.T @ P) < 0)


def test_modal_P_rejects_unstable_and_bad_weights():
    from workbench.errors import ModelError
    from workbench.roa import modal_P
    with pytest.raises(ModelError, match="Hurwitz"):
        modal_P(np.array([[0.1, 0.0], [0.0, -1.0]]))
    with pytest.raises(ModelError, match="positive weights"):
        modal_P(-np.eye(2) - np.diag([0, 1.0]), [1.0, -2.0])


def test_imul_is_the_rounded_hull_of_the_four_products():
    """imul against the hull taken directly (NaN products, as 0 * inf, give the
    whole line), on special values: signed zeros, infinities, subnormals."""
    from workbench.roa.interval import Interval, imul
    rng = np.random.default_rng(0)
    special = np.array([0.0, -0.0, np.inf, -np.inf, 1e308, -1e308, 1e-320, -1e-320, 1.0, -2.5])
    for _ in range(200):
        x = [np.where(rng.random(40) < 0.4, rng.choice(special, 40), rng.normal(size=40))
             for _ in range(4)]
        a = Interval(np.minimum(x[0], x[1]), np.maximum(x[0], x[1]))
        b = Interval(np.minimum(x[2], x[3]), np.maximum(x[2], x[3]))
        with np.errstate(invalid="ignore", over="ignore"):
            p = np.stack([a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi])
        nan = np.isnan(p).any(axis=0)
        lo = np.where(nan, -np.inf, np.nextafter(p.min(axis=0), -np.inf))
        hi = np.where(nan, np.inf, np.nextafter(p.max(axis=0), np.inf))
        r = imul(a, b)
        np.testing.assert_array_equal(r.lo, lo)
        np.testing.assert_array_equal(r.hi, hi)
