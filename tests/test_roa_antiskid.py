"""Basin of paper 003's cruise law (61): the printed switch at lambda_opt is
outside every certified basin and diverges; the workbench's handover state is
inside; a small k2 makes the printed switch safe (workbench.papers.p003.antiskid_basin)."""
import numpy as np
import pytest

from workbench.papers.p003 import antiskid_basin as AB
from workbench.plants.adhesion import NumericAdhesion
from workbench.outcome import Outcome

# 003 Tables 1-2 (dry rail); the gain is the workbench's certified synthesis at
# eps = 0.35 (reports/antiskid-run-dry.md: K = [-0.004575, 10.27])
DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)
K = (-0.004575, 10.27)


@pytest.fixture(scope="module")
def lam_opt():
    return NumericAdhesion.from_dict(DRY).lambda_opt()


def judge(K, point, v_d=70.0):
    """The switch state ``point`` = (v, lambda) judged for the gain K as the k2
    sweep judges it: the best verdict over the weight grid, and the fate."""
    loop, lam_d, _ = AB.cruise_loop(tuple(sorted(DRY.items())), v_d)
    return loop.judge(tuple(K), (point[0] - v_d, point[1] - lam_d), AB.T_JUDGE)


def test_printed_switch_is_refuted_and_diverges(lam_opt):
    v = judge(K, (70.0, lam_opt))
    assert v.outcome is Outcome.REFUTED and v.hurwitz
    assert v.fate == "diverges"


def test_handover_state_is_certified_and_converges():
    # the compensated variant's handover state (reports/antiskid-run-dry.md)
    v = judge(K, (70.29, 0.02145))
    assert v.outcome is Outcome.CERTIFIED and v.fate == "converges"


def test_small_k2_makes_the_printed_switch_safe(lam_opt):
    v = judge((K[0], 0.0), (70.0, lam_opt))
    assert v.outcome is Outcome.CERTIFIED and v.fate == "converges"


def test_cruise_loop_linearisation_matches_A_plus_BK():
    vals = tuple(sorted(DRY.items()))
    loop = AB.cruise_loop(vals, 70.0)[0]
    (f, _, A_cl), states = loop.at(K), loop.states
    import sympy as sp
    fn = sp.lambdify(states, f, "math")
    assert max(abs(c) for c in fn(0.0, 0.0)) < 1e-12          # equilibrium at E = 0
    h = np.array([1e-5, 1e-8])
    J = np.column_stack([(np.array(fn(*(h[j] * np.eye(2)[j]))) -
                          np.array(fn(*(-h[j] * np.eye(2)[j])))) / (2 * h[j]) for j in range(2)])
    assert np.allclose(J, A_cl, rtol=1e-5, atol=1e-9)


def test_certified_cruise_level_holds_no_sampled_point_with_vdot_nonnegative(lam_opt):
    vals = tuple(sorted(DRY.items()))
    lam_d = AB.cruise_loop(vals, 70.0)[1]
    prob, est = AB.cruise_loop(vals, 70.0)[0].estimate(K, 100.0, [(0.0, lam_opt - lam_d)])
    assert 0 < est.c_certified < est.c_refuted < prob.V(np.array([[0.0, lam_opt - lam_d]]))[0]
    rng = np.random.default_rng(5)
    u = rng.standard_normal((100_000, 2))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    u *= np.sqrt(rng.random((100_000, 1)) * est.c_certified * (1 - 1e-9))
    X = u @ np.linalg.inv(np.linalg.cholesky(prob.P).T).T
    V = prob.V(X)
    keep = V > 1e-12 * est.c_certified
    assert np.all(prob.vdot_numeric(X[keep]) < 0)
    # the counterexample really has V' >= 0 below the switch state's level
    cx = np.array([est.counterexample])
    assert prob.vdot_numeric(cx)[0] >= 0


@pytest.mark.parametrize("old, new, key", [
    ("bisect = 4", "bisect = 2.5", "basin.bisect"),
    ("compare_gains = [[-0.0049, 10.5080],", "compare_gains = [[-0.0049],", "basin.compare_gains[0]"),
    ("k2_grid = [-40.0,", 'k2_grid = ["a",', "basin.k2_grid[0]"),
])
def test_bad_basin_table_is_exit_2(tmp_path, capsys, old, new, key):
    from pathlib import Path

    from workbench.cli import main
    src = Path(__file__).resolve().parents[1] / "designs" / "antiskid-run-dry.toml"
    bad = tmp_path / "antiskid-run-dry.toml"
    text = src.read_text()
    at = text.index("\n[basin]")            # edit the [basin] table (other tables have a bisect too)
    assert old in text[at:]
    bad.write_text(text[:at] + text[at:].replace(old, new, 1))
    assert main(["verify", str(bad)]) == 2
    err = capsys.readouterr().err
    assert key in err and "Traceback" not in err


def test_delay_feedback_design_gets_a_basin():
    """The general pipeline: a delay-feedback design's sympy model, operating
    point and gain (its report's canonical K = [-0.1218, -0.1211]) give a
    certified basin that holds a nearby state."""
    from workbench.design import load_design
    from workbench.features.basin import delay_feedback_basin
    from workbench.kinds.delay_feedback.model import PlantModel, solve_operating_point
    spec = load_design("designs/train-brake-lag-delay-feedback.toml").spec
    model = PlantModel(spec.plant)
    values = spec.plant.values()
    op = solve_operating_point(model, values)
    x1 = tuple(op.x + np.array([0.5, 0.02]))
    chk = delay_feedback_basin(model, values, op, [[-0.1218, -0.1211]], points=[("near", x1)],
                               c_search=50.0)
    est = chk.estimate
    assert 0 < est.c_certified <= est.c_refuted
    assert chk.points[0].verdict.outcome is Outcome.CERTIFIED


def test_brake_switch_at_lambda_d_is_in_no_basin_and_spins():
    """Cruise -> braking (law 69) at t_brake, dry rail: the state (v_d, lambda_d)
    of the compensated run (reports/antiskid-run-dry.md) lies in the basin of
    no equilibrium of the frozen loop (lambda' > 0 proven up to 0.9), and the
    time-varying delay-free loop spins the wheel too."""
    from workbench.controllers.antiskid003_settings import CreepSpeedProfile
    from workbench.papers.p003.antiskid_basin_brake import brake_switch
    from workbench.papers.p003.antiskid_basin_render import brake_text
    b = brake_switch(DRY, "compensated", (70.0126, 0.01954),
                     profile=CreepSpeedProfile(t_brake=300.0), k_de=10.0)
    assert b.outcome is Outcome.REFUTED and b.verdict.why == "no equilibrium"
    assert b.verdict.direction > 0 and b.verdict.rate > 0 and b.fate == "diverges" and 0 < b.t_fate < 0.1
    text = brake_text([b])
    assert "frozen at the switch instant" in text and "| REFUTED |" in text
    assert "no equilibrium from the state up to lambda = 0.9: \\|lambda'\\| >= " in text


def test_brake_switch_on_the_braking_side_is_certified():
    """Frozen 1 s after t_brake (v_s* < 0: equilibrium on the braking side), a
    state at lambda = -0.01 reaches the certified level set of the equilibrium;
    the time-varying delay-free loop (no frozen assumption) tracks."""
    from workbench.controllers.antiskid003_settings import CreepSpeedProfile
    from workbench.papers.p003.antiskid_basin_brake import brake_switch
    b = brake_switch(DRY, "later", (69.0, -0.01), profile=CreepSpeedProfile(t_brake=300.0),
                     k_de=10.0, t=301.0)
    assert b.outcome is Outcome.CERTIFIED and b.verdict.star < 0 and b.fate == "tracks"
    # the frozen equilibrium is the law's own: k_de (v lambda - v_s*) = -lambda z1
    assert abs(b.verdict.star - b.reference / b.x[0]) < 0.1 * abs(b.verdict.star)


def test_brake_switch_claims_are_known_quantities():
    from workbench.design import load_design
    d = load_design("designs/antiskid-run-dry.toml")
    ids = {c.id: c for c in d.claims}
    assert ids["switch-brake-outside-basin"].quantity == "switch.brake[compensated].in_basin"
