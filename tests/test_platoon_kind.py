"""The general ``platoon`` kind (issue 35): laws written in the design file,
evaluated in the order written; paper 001's eq 13 from the file against the
hand-written code, bit for bit; a synthetic user design; bad input."""
import json
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.controllers.ntsm import (NTSMGains, linear_member, ntsm_force, pd_ff_force,
                                        pd_force, surface)
from workbench.design import load_design
from workbench.errors import DesignError
from workbench.kinds.platoon.laws import compile_expression
from workbench.kinds.platoon.run import scenario
from workbench.sim.platoon import simulate_platoon

PAPER = Path("designs/platoon-ntsm-001.toml")
SYNTHETIC = Path("designs/platoon-synthetic.toml")
#: paper 001's gains as designs/platoon-ntsm-001.toml writes them (ours: the paper gives none)
G = NTSMGains(beta=0.2, a=5, b=7, j=3.0, k=3.0, alpha=3, xi=5)


@pytest.fixture(scope="module")
def paper():
    return scenario(load_design(PAPER).spec)


def _old_laws(sc):
    """The hand-written laws the design's expressions replace."""
    m, bound = sc.nominal.m, sc.spec.G_w + sc.spec.G_d
    k_e, k_d = linear_member(G)
    return {"ntsm": lambda e, de, u1, a: (ntsm_force(e, de, surface(e, de, G), u1, m, a, bound, G),
                                          surface(e, de, G)),
            "pd": lambda e, de, u1, a: (pd_force(e, de, u1, m, 0.1, 0.6), np.zeros_like(e)),
            "pd_ff": lambda e, de, u1, a: (pd_ff_force(e, de, u1, m, a, 0.1, 0.6),
                                           np.zeros_like(e)),
            "linear": lambda e, de, u1, a: (pd_ff_force(e, de, u1, m, a, k_e, k_d),
                                            np.zeros_like(e))}


def test_laws_from_the_file_equal_the_old_code_bit_for_bit(paper):
    rng = np.random.default_rng(1)
    for name, old in _old_laws(paper).items():
        new = paper.law(name)
        for scale in (1e-6, 1e-3, 1.0):
            e, de, u1, a = (rng.normal(0, s, 3) for s in (scale, 10 * scale, 1e4, 0.5))
            (u0, s0), (u1_, s1) = old(e, de, u1, a), new(e, de, u1, a)
            assert np.array_equal(u0, u1_) and np.array_equal(s0, s1), name


def test_ntsm_run_from_the_file_equals_the_old_code_bit_for_bit(paper):
    """A 10 s run (1000 steps) of eq 13, from initial errors: every command and
    position the same bits."""
    old = _old_laws(paper)["ntsm"]
    e0 = np.array([3.0, 2.0, 1.0])
    a = simulate_platoon(paper.nominal, paper.true, old, paper.leader_ref,
                         **{**paper.common(), "horizon": 10.0}, initial_errors=e0)
    b = paper.simulate("ntsm", e0, horizon=10.0)
    assert np.array_equal(a.u, b.u) and np.array_equal(a.x, b.x) and np.array_equal(a.s, b.s)
    assert np.abs(b.s).max() > 0.1           # the surface is really used (not zeros)


@pytest.mark.parametrize("text, want", [
    ("x*y*z", lambda x, y, z: (x * y) * z),
    ("x - y - z", lambda x, y, z: (x - y) - z),
    ("x/y/z", lambda x, y, z: (x / y) / z),
    ("-x**2", lambda x, y, z: -(x ** 2)),
    ("sign(x)*abs(x)**(3/5)", lambda x, y, z: np.sign(x) * np.abs(x) ** 0.6),
    ("where(x > 0, y, z)", lambda x, y, z: np.where(x > 0, y, z)),
    ("piecewise(x < -0.5, y, x < 0.5, z, 1.0)",
     lambda x, y, z: np.select([x < -0.5, x < 0.5], [y, z], 1.0)),
    ("max(x, y, z) - min(x, 0.0)", lambda x, y, z: np.maximum(np.maximum(x, y), z)
     - np.minimum(x, 0.0)),
])
def test_expressions_evaluate_in_the_order_written(text, want):
    rng = np.random.default_rng(2)
    x, y, z = (rng.normal(0, 1, 50) for _ in range(3))
    names = {k: (lambda s, k=k: s[k]) for k in "xyz"}
    f = compile_expression(text, names, path="t.toml", key="k")
    assert np.array_equal(f({"x": x, "y": y, "z": z}), want(x, y, z))


def test_expressions_never_run_code():
    with pytest.raises(DesignError) as exc:
        compile_expression("__import__('os').getcwd()", {"x": 1.0}, path="t.toml", key="k")
    assert exc.value.key == "k"


def test_the_synthetic_design_runs_and_its_claims_hold():
    from workbench.verify import evaluate_design
    d = load_design(SYNTHETIC)
    assert d.kind == "platoon" and d.spec.n == 3 and d.spec.analysis is None
    ev = evaluate_design(d)
    assert ev.ok
    q = {r.claim.quantity: r.got for r in ev.claims}
    assert q["pd_over_pd_ff.max_abs_e"] >= 2.0
    # the PD + feed-forward's gains, read off its expression, are the design's kp, kd
    assert (ev.result.realism.margin.k_e, ev.result.realism.margin.k_d) == (0.2, 0.9)


@pytest.mark.parametrize("old, new, key, shown", [
    ('law = "u1 + m*(kp*e + kd*de)"', 'law = "u1 + m*(kp*e + kd*de) + os.system(1)"',
     "laws[0].law", "os.system"),
    ('law = "u1 + m*(kp*e + kd*de)"', 'law = "u1 + m*(kp*e + kd*de) + speed"', "laws[0].law",
     "speed"),
    ('law = "u1 + m*(kp*e + kd*de)"', 'law = "u1 + kp*e"', "laws[0].law", "u1 + kp*e"),
    ('law = "u1 + m*(kp*e + kd*de) + m*a_pred"', 'law = "u1 + m*(kp*e + kd*de) + a_pred"',
     "laws[1].law", "a_pred"),
])
def test_a_bad_law_is_exit_2_with_one_line(tmp_path, capsys, old, new, key, shown):
    text = SYNTHETIC.read_text()
    assert old in text
    p = tmp_path / SYNTHETIC.name
    p.write_text(text.replace(old, new, 1))
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert p.name in err and key in err and shown in err and "expected" in err


def test_simulate_prints_a_run(tmp_path, capsys):
    csv = tmp_path / "run.csv"
    assert main(["simulate", str(SYNTHETIC), "--case", "pd_ff", "--json", "--csv", str(csv)]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["case"] == "pd_ff" and out["metrics"]["max_abs_e"] > 0
    head, first = csv.read_text().splitlines()[:2]
    assert head == "t,x1,x2,x3,v1,v2,v3,u1,u2,u3,e2,e3"
    assert [float(x) for x in first.split(",")][:4] == [0.0, 0.0, -50.0, -100.0]
    assert main(["simulate", str(SYNTHETIC), "--case", "nope"]) == 2


def _with_headway(tmp_path, h: float, *, margin: bool) -> Path:
    text = SYNTHETIC.read_text().replace(
        'T = { value = 0.05, unit = "s"',
        f'headway = {{ value = {h}, unit = "s", source = "test" }}\nT = {{ value = 0.05, unit = "s"',
        1)
    if not margin:
        text = text.replace('[delay_margin]\nlaw = "pd_ff"\nshort = "PD + feed-forward"\n'
                            'sweep = ["pd_ff"]\nfactors = [0.5, 0.9, 1.1]\n', "")
        text = text.split("# Claims:")[0]
    p = tmp_path / SYNTHETIC.name
    p.write_text(text)
    return p


def test_time_headway_policy_keeps_gap_d_plus_h_v(tmp_path):
    """The time-headway policy: in the settled cruise the PD + feed-forward
    holds gap = D + h v (to the error the external force leaves), about h v =
    16.7 m more than constant spacing would."""
    spec = load_design(_with_headway(tmp_path, 1.0, margin=False)).spec
    assert spec.headway == 1.0
    sc = scenario(spec)
    r = sc.simulate("pd_ff")
    cruise = (r.t > 40.0) & (r.t < 80.0)
    extra = r.gap[cruise] - spec.D.value
    assert abs(extra.mean() - 16.6667) < 0.5
    assert np.abs(r.e[cruise]).max() < 0.5
    with pytest.raises(DesignError) as exc:       # the margin's loop model is constant spacing
        load_design(_with_headway(tmp_path, 1.0, margin=True))
    assert exc.value.key == "delay_margin"
