"""The delay-feedback study: loading, operating points, linearisation, the template."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.errors import DesignError

BASE = '''
[design]
name = "{name}"
kind = "delay-feedback"
title = "test"
source = "tests/test_delay_feedback.py"

[states]
x = {{ unit = "rad", source = "test" }}

[inputs]
u = {{ unit = "rad/s", source = "test" }}

[parameters]
a = {{ value = 2.0, unit = "1/s", source = "test" }}

[equations]
x = "-a*sin(x) + u"

[operating_point]
x = {{ value = 0.5, unit = "rad", source = "test" }}
u = {{ solve = [{lo}, {hi}] }}

[delay]
h = {{ value = 0.1, unit = "s", source = "test" }}

[synthesis]
method = "wirtinger"
'''


def write(tmp_path, name="d", lo=-5.0, hi=5.0, extra="", replace=None):
    text = BASE.format(name=name, lo=lo, hi=hi) + extra
    for old, new in (replace or {}).items():
        assert old in text
        text = text.replace(old, new)
    p = tmp_path / f"{name}.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_operating_point_and_jacobians_are_analytic(tmp_path, monkeypatch):
    """x' = -a sin x + u at x = 0.5: u = a sin 0.5, A = -a cos 0.5, B = 1."""
    from workbench.kinds.delay_feedback.run import nominal_point
    monkeypatch.chdir(tmp_path)
    d = load_design(write(tmp_path))
    _, _, op, A, B = nominal_point(d.spec)
    assert op.solved == ("u",)
    assert op.u[0] == pytest.approx(2 * math.sin(0.5), rel=1e-14)
    assert A[0, 0] == pytest.approx(-2 * math.cos(0.5), rel=1e-14)
    assert B[0, 0] == 1.0


def _cli_error(path, capsys) -> str:
    code = main(["verify", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1
    return lines[0]


def test_no_root_in_range_is_a_design_error(tmp_path, monkeypatch, capsys):
    """u = 2 sin 0.5 = 0.959 lies outside [2, 5]: exit 2, naming the range."""
    monkeypatch.chdir(tmp_path)
    line = _cli_error(write(tmp_path, lo=2.0, hi=5.0), capsys)
    assert "d.toml: operating_point" in line and "u in [2, 5]" in line


@pytest.mark.parametrize("replace, words", [
    ({'x = { value = 0.5, unit = "rad"': 'x = { value = 0.5, unit = "deg"'},
     ['operating_point.x.unit', '"rad"']),
    ({'x = { value = 0.5, unit = "rad", source = "test" }': 'x = { solve = [0.0, 1.0] }'},
     ["as many entries with solve"]),
    ({'method = "wirtinger"': 'method = "magic"'}, ["synthesis.method", "'magic'"]),
    ({'method = "wirtinger"': 'method = "robust-descriptor"'}, ["[[vertices]]"]),
    ({'x = "-a*sin(x) + u"': 'y = "-a*sin(x) + u"'}, ["equations.x", "<missing>"]),
    ({'a = { value = 2.0': 'sin = { value = 2.0'}, ["parameters.sin", "not a function"]),
    ({'a = { value = 2.0': 'x = { value = 2.0'}, ["parameters.x", "not already declared"]),
    ({'h = { value = 0.1, unit = "s"': 'h = { value = 100, unit = "ms"'}, ["delay.h.unit"]),
])
def test_malformed_designs_exit_2_with_one_line(tmp_path, monkeypatch, capsys, replace, words):
    monkeypatch.chdir(tmp_path)
    line = _cli_error(write(tmp_path, replace=replace), capsys)
    for w in words:
        assert w in line, line


def test_vertices_name_parameters(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    extra = ('\n[[vertices]]\nname = "v1"\nsource = "t"\nb = 1.0\n'
             '[[vertices]]\nname = "v2"\nsource = "t"\na = 1.0\n')
    line = _cli_error(write(tmp_path, extra=extra,
                            replace={'method = "wirtinger"': 'method = "robust-descriptor"'}),
                      capsys)
    assert "vertices[0].b" in line and "a parameter" in line


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    """(exit code, project folder, design file) of ``workbench new delay-feedback
    my-plant`` in a fresh folder. The tests that run this one file share its
    synthesis (computed once per process: ``design_synthesis`` is keyed by the
    spec, file path included)."""
    root = tmp_path_factory.mktemp("template")
    with pytest.MonkeyPatch.context() as mp:
        mp.chdir(root)
        code = main(["new", "delay-feedback", "my-plant"])
    return code, root, root / "designs" / "my-plant.toml"


def test_template_runs_as_written(template, monkeypatch, capsys):
    """``workbench new delay-feedback NAME`` writes a design that verifies, and
    simulate / synthesize accept it; a second ``new`` never overwrites."""
    code, root, path = template
    assert code == 0
    assert path.is_file()
    monkeypatch.chdir(root)
    written = path.read_bytes()
    assert main(["new", "delay-feedback", "my-plant"]) == 2
    assert path.read_bytes() == written
    assert main(["new", "delay-feedback", "Bad_Name"]) == 2
    assert main(["new", "pid", "x"]) == 2
    capsys.readouterr()
    assert main(["verify", str(path)]) == 0
    out = capsys.readouterr().out
    assert "4 of 4 claims ok" in out
    assert main(["simulate", str(path), "--dt", "0.1"]) == 0
    out = capsys.readouterr().out
    assert "final_error.x1" in out
    assert main(["simulate", str(path), "--case", "nope"]) == 2


def test_simulate_writes_the_trajectory_csv(template, tmp_path, monkeypatch, capsys):
    """``simulate --csv --plot --json`` of a delay-feedback design (the one
    ``workbench new`` writes: its gain is synthesised in about a quarter of the
    time of a shipped design's requirements synthesis; the CSV and the figure
    are written by the same code for every delay-feedback design). Moved here
    from tests/test_hardening.py: it shares the template's synthesis."""
    out = tmp_path / "run.csv"
    png = tmp_path / "run.png"
    code, root, path = template
    assert code == 0
    monkeypatch.chdir(root)
    code = main(["simulate", str(path), "--csv", str(out), "--plot", str(png), "--json"])
    assert code == 0, capsys.readouterr().err
    lines = out.read_text().splitlines()
    head = lines[0].split(",")
    assert head[0] == "t" and len(lines) > 100
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    assert data.shape[1] == len(head) and np.all(np.diff(data[:, 0]) > 0)
    assert np.all(np.isfinite(data))
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_expression_functions_reach_the_model(tmp_path, monkeypatch):
    """where/min/max/abs build piecewise sympy that lambdifies: the Jacobian
    of x' = where(x > 0, -a x, -2 a x) + u at x = 0.5 is -a."""
    from workbench.kinds.delay_feedback.run import nominal_point
    monkeypatch.chdir(tmp_path)
    d = load_design(write(tmp_path, replace={'"-a*sin(x) + u"':
                                             '"where(x > 0, -a*x, -2*a*x) + min(u, 10)"'}))
    _, _, op, A, B = nominal_point(d.spec)
    assert A[0, 0] == -2.0 and B[0, 0] == 1.0 and op.u[0] == pytest.approx(1.0)


def test_delay_range_stable_needs_one_window():
    from workbench.kinds.delay_feedback.run import delay_range_stable
    assert delay_range_stable(((0.0, 1.0),), 0.3, 0.8)
    assert not delay_range_stable(((0.0, 0.5), (0.6, 2.0)), 0.3, 0.8)
    assert delay_range_stable(((0.0, 0.2), (0.25, np.inf)), 0.3, 0.8)


ROOT = __import__("pathlib").Path(__file__).resolve().parents[1]
SHIPPED = sorted(ROOT.glob("designs/*delay-feedback*.toml")) + [
    ROOT / "designs" / "antiskid-cruise-dry-generic.toml"]


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_designs_load_with_claims(path):
    """Each shipped delay-feedback design loads (operating point solved in its
    ranges) and claims the certificate or the exact set and a simulation."""
    d = load_design(path)
    assert d.kind == "delay-feedback" and len(d.claims) >= 5
    quantities = {c.quantity for c in d.claims}
    assert any(q.startswith("simulation.") for q in quantities)
    assert quantities & {"exact.delay_range_stable", "exact_margin",
                         "certificate.covers_delay_range"}
    for q in d.spec.plant.parameters.values():
        assert q.source.strip()


ROBUST = BASE.format(name="rob", lo=-5.0, hi=5.0).replace(
    "value = 2.0, unit", "value = 0.75, unit").replace('method = "wirtinger"', '''method = "robust-descriptor"
decay_rate = 0.1
grid = [0.3, 1.0]
h_max = 0.5''').replace('"-a*sin(x) + u"', '"a*x + u"').replace(
    'x = { value = 0.5, unit = "rad", source = "test" }',
    'x = { value = 0.0, unit = "rad", source = "test" }') + '''
[[vertices]]
name = "slow"
a = 0.5
source = "test"
[[vertices]]
name = "fast"
a = 1.0
source = "test"

[[scenarios]]
name = "kick"
x0 = { x = 0.1 }
t_end = 20.0
dt = 0.01
'''


def test_robust_vertices_end_to_end(tmp_path, monkeypatch):
    """Unstable scalar plants x' = a x + u(t - h), a in {0.5, 1}: one gain,
    certified at both vertices with decay rate 0.1 at its delay; the exact
    margin at each vertex is at least the certified delay and the spectral
    abscissa there is at most -0.1 (independent checks)."""
    from workbench.kinds.delay_feedback import STUDY
    monkeypatch.chdir(tmp_path)
    p = tmp_path / "rob.toml"
    p.write_text(ROBUST, encoding="utf-8")
    d = load_design(p)
    res = STUDY.run(d)
    q = STUDY.quantities(res)
    assert q["synthesis.status"] == "certified"
    h = q["synthesis.h_gain"]
    assert h > 0
    for v in ("slow", "fast"):
        assert q[f"vertices.{v}.exact_margin"] >= h
        assert q[f"vertices.{v}.abscissa_at_h_gain"] <= -0.1
    assert q["synthesis.K[1,1]"] < -1.0            # it must beat the unstable a = 1
    assert q["certificate.covers_delay_range"] in ("at-h-only", "no")   # alpha > 0: at h
    sim = res.scenarios[0]
    assert q["simulation.kick.converged"] == "yes", (sim.metrics, sim.metrics_coarse)


PREDICTOR = BASE.format(name="pred", lo=-50.0, hi=50.0).replace(
    '"-a*sin(x) + u"', '"a*x + u"').replace("value = 2.0, unit", "value = 1.0, unit").replace(
    'x = { value = 0.5, unit = "rad", source = "test" }',
    'x = { value = 0.0, unit = "rad", source = "test" }').replace(
    'method = "wirtinger"', 'method = "wirtinger"\nh_max = 0.5') + '''
[[scenarios]]
name = "plain"
x0 = { x = 0.1 }
h = 2.0
t_end = 20.0
dt = 0.05

[[scenarios]]
name = "predicted"
x0 = { x = 0.1 }
h = 2.0
t_end = 20.0
dt = 0.05
predictor = true
'''


def test_predictor_removes_the_delay_from_the_loop(tmp_path, monkeypatch):
    """x' = x + u(t - h) at h = 2 s, far beyond the exact margin of the loop
    with the synthesised K: without the predictor the nonlinear run grows,
    with it (paper 003 Lemma 1; the model is exact here) it decays as the
    delay-free loop A + BK does."""
    from workbench.kinds.delay_feedback import STUDY
    monkeypatch.chdir(tmp_path)
    p = tmp_path / "pred.toml"
    p.write_text(PREDICTOR, encoding="utf-8")
    res = STUDY.run(load_design(p))
    q = STUDY.quantities(res)
    assert q["exact_margin"] < 2.0
    plain, pred = res.scenarios
    assert plain.metrics["diverged"] == 1.0 or plain.metrics["final_error.x"] > 0.1
    assert pred.metrics["diverged"] == 0.0 and pred.metrics["final_error.x"] < 1e-3
    assert q["simulation.predicted.converged"] == "yes"
