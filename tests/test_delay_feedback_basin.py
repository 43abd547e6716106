"""The basin check of a delay-feedback design (issue 15, item 4): the
``[basin]`` table, its report section and claims, bad values (exit 2), and
agreement with checks that use neither the falsifier nor interval arithmetic."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design

# An inverted pendulum, x1' = x2, x2' = a sin x1 - d x2 + u (open-loop unstable;
# sin saturates, so a linear law has a bounded basin).
DESIGN = '''{top}
[design]
name = "{name}"
kind = "delay-feedback"
title = "test pendulum"
source = "tests/test_delay_feedback_basin.py"

[states]
x1 = {{ unit = "rad", source = "test" }}
x2 = {{ unit = "rad/s", source = "test" }}

[inputs]
u = {{ unit = "rad/s^2", source = "test" }}

[parameters]
a = {{ value = 1.0, unit = "1/s^2", source = "test" }}
d = {{ value = 0.5, unit = "1/s", source = "test" }}

[equations]
x1 = "x2"
x2 = "a*sin(x1) - d*x2 + u"

[operating_point]
x1 = {{ value = 0.0, unit = "rad", source = "test" }}
x2 = {{ value = 0.0, unit = "rad/s", source = "test" }}
u = {{ value = 0.0, unit = "rad/s^2", source = "test" }}

[delay]
h = {{ value = 0.2, unit = "s", source = "test" }}

[synthesis]
method = "wirtinger"
h_max = 2.0

[[scenarios]]
name = "tilt"
x0 = {{ x1 = 0.2 }}
t_end = 10.0
dt = 0.01
{basin}
[[claims]]
id = "tilt-in-basin"
description = "the tilted start lies in the certified basin"
quantity = "basin.scenario[tilt].in_basin"
compare = "=="
value = "CERTIFIED"
source = "workbench basin check"

[[claims]]
id = "inside-converges"
description = "trajectories from the certified level's boundary converge"
quantity = "basin.inside_converge"
compare = "=="
value = "yes"
source = "workbench basin check"
'''
BASIN = '''
[basin]
enabled = true
domain = { x1 = [-3.0, 3.0] }
'''


def write(tmp_path, *, top="", basin=BASIN, name="pend"):
    p = tmp_path / "designs" / f"{name}.toml"
    p.parent.mkdir(exist_ok=True)
    p.write_text(DESIGN.format(top=top, name=name, basin=basin), encoding="utf-8")
    return p


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory):
    """The pendulum design, run once (study and claims)."""
    from workbench.verify import evaluate_design
    path = write(tmp_path_factory.mktemp("basin"))
    return evaluate_design(load_design(path))


def test_section_figure_and_claims(evaluated, tmp_path, monkeypatch, capsys):
    from workbench.kinds import renderer
    from workbench.kinds.delay_feedback import STUDY
    ev = evaluated
    assert all(c.ok for c in ev.claims), [(c.claim.id, c.got) for c in ev.claims]
    q = STUDY.quantities(ev.result)
    est = ev.result.basin.check.estimate
    assert q["basin.c_certified"] == est.c_certified > 0
    assert q["basin.outcome"] in ("CERTIFIED", "REFUTED", "INCONCLUSIVE")
    assert q["basin.certified"] == "yes" and q["basin.scenario[tilt].level"] > 0
    rendered = renderer("delay-feedback")(ev.design, ev.result)
    text = "\n".join(rendered.sections)
    assert "## Region of attraction of the delay-free loop" in text
    assert "Lyapunov equation" in text and "no input delay" in text
    assert "c_certified" in text and "{figdir}/basin.png" in text
    assert any(f.name == "basin" for f in rendered.figures)
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    fig = Figure()
    next(f for f in rendered.figures if f.name == "basin").draw(fig)   # draws without error


def test_certified_level_agrees_with_simulation(evaluated):
    """Independent of the falsifier and of interval arithmetic: delay-free
    trajectories from random points of {V <= c_certified} converge to x*, V'
    sampled there is negative, and a counterexample, if any, has V' >= 0."""
    import sympy as sp
    from scipy.integrate import solve_ivp

    from workbench.features.basin import closed_loop
    from workbench.kinds.delay_feedback.model import PlantModel
    res, spec = evaluated.result, evaluated.design.spec
    est = res.basin.check.estimate
    model = PlantModel(spec.plant)
    f, states, A_cl = closed_loop(model, spec.plant.values(), res.op, res.synthesis.K)
    T = 10.0 / np.min(np.abs(np.linalg.eigvals(A_cl).real))      # 10 slowest time constants
    fn = sp.lambdify(states, f, "numpy")
    P, x_eq = np.array(est.P), np.array(est.x_eq)
    rng = np.random.default_rng(7)
    g = rng.standard_normal((400, 2))
    g /= np.linalg.norm(g, axis=1, keepdims=True)
    E = g * np.sqrt(rng.random((400, 1)) * est.c_certified)
    E = E @ np.linalg.inv(np.linalg.cholesky(P).T).T
    X = x_eq + E
    Fx = np.array(fn(*X.T), float).T
    vdot = 2 * np.einsum("ni,ij,nj->n", E, P, Fx)
    assert np.all(vdot[np.einsum("ni,ij,nj->n", E, P, E) > 1e-9] < 0)
    V = lambda Y: np.einsum("ni,ij,nj->n", Y - x_eq, P, Y - x_eq)
    for x0 in X[:12]:
        sol = solve_ivp(lambda t, x: np.array(fn(*x), float), (0, T), x0, method="Radau",
                        rtol=1e-9, atol=1e-12)
        v = V(sol.y.T)
        assert np.all(np.diff(v) <= 1e-9 * v[0]) and v[-1] <= 1e-3 * v[0]
    if est.counterexample is not None:
        cx = np.array(est.counterexample)
        assert 2 * (cx - x_eq) @ P @ np.array(fn(*cx), float) >= 0


def test_bare_basin_true_and_disabled(tmp_path):
    d = load_design(write(tmp_path, top="basin = true", basin=""))
    assert d.spec.basin is not None and d.spec.basin.plane == ("x1", "x2")
    off = write(tmp_path, name="off", basin="\n[basin]\nenabled = false\n")
    text = off.read_text().replace('[[claims]]\nid = "tilt-in-basin"', '[[claims]]\nid = "a"')
    off.write_text(text.split('[[claims]]')[0])
    assert load_design(off).spec.basin is None


@pytest.mark.parametrize("top, basin, key, expected", [
    ('basin = "yes"', "", "basin = 'yes'", "true, false or a [basin] table"),
    ("", "\n[basin]\nenabled = 1\n", "basin.enabled = 1", "true or false"),
    ("", "\n[basin]\ndomain = { x3 = [0.0, 1.0] }\n", "basin.domain.x3", "a state: x1, x2"),
    ("", "\n[basin]\ndomain = { x1 = [1.0, -1.0] }\n", "basin.domain.x1", "lo < hi"),
    ("", "\n[basin]\ndomain = { x1 = [0.5, 1.0] }\n", "basin.domain.x1",
     "holding the operating point x1 = 0"),
    ("", '\n[basin]\nplane = ["x1", "x1"]\n', "basin.plane", "2 different states"),
    ("", "\n[basin]\nseed = -1\n", "basin.seed = -1", "non-negative integer"),
    ("", "\n[basin]\nlevel = 3\n", "basin.level = 3", "no such key"),
])
def test_bad_basin_values_are_exit_2(tmp_path, capsys, top, basin, key, expected):
    path = write(tmp_path, top=top, basin=basin)
    assert main(["verify", str(path)]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert "pend.toml: " in lines[0] and key in lines[0] and expected in lines[0], lines[0]


def test_no_domain_and_no_scenario_is_exit_2(tmp_path, capsys):
    path = write(tmp_path, basin="\n[basin]\n")
    text = path.read_text()
    path.write_text(text[:text.index("[[scenarios]]")] + "\n[basin]\n")
    assert main(["verify", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "basin.domain = <missing>" in err and "no scenario" in err
