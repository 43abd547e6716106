"""Bad input exits 2 with one line; edges give right answers (issue 32, items 1, 2, 5).

Each design case mutates one line of a shipped design and runs ``workbench
verify`` in-process: the file is refused while it is read (a few seconds).
"""
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from workbench import api
from workbench.cli import main
from workbench.errors import DesignError
from workbench.lmi.core import Outcome, Step, bisect_delay
from workbench.toml_input import MAX_DEPTH, load_toml

ROOT = Path(__file__).resolve().parents[1]
TRAIN = "train-brake-lag-delay-feedback"
#: The train-brake design as it was before it was designed to requirements
#: (robust-descriptor synthesis with a search cap and an eps grid): the
#: inputs the cap and grid checks mutate.
TRAIN_ROBUST = "train-brake-lag-robust"
CRUISE = "antiskid-cruise-dry"


def _verify(tmp_path, capsys, design, old, new):
    src = ROOT / "designs" / f"{design}.toml"
    if not src.is_file():
        src = ROOT / "tests" / "data" / f"{design}.toml"
    text = src.read_text()
    assert old in text, old
    p = tmp_path / f"{design}.toml"
    p.write_text(text.replace(old, new, 1))
    code = main(["verify", str(p)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert len(err.splitlines()) == 1 and "Traceback" not in err and err.startswith("error: ")
    return err


@pytest.mark.parametrize("old, new, words", [
    # a negative time constant was accepted and hung the robust bisection
    ("T_b   = { value = 0.65,", "T_b   = { value = -0.65,",
     ["parameters.T_b.value = -0.65", "a positive time in [1e-09, 1e+09] s"]),
    ("T_b   = { value = 0.65,", "T_b   = { value = 1e308,", ["positive time"]),
    ("T_b   = { value = 0.65,", "T_b   = { value = 1e-300,", ["positive time"]),
    ("m0    = { value = 5.0e5,", "m0    = { value = 1e308,", ["positive mass"]),
    ("m = 4.0e5\nmu = 0.307", "m = 0\nmu = 0.307", ["vertices[light_dry].m = 0.0",
                                                     "positive mass"]),
    # units of the user's own equations (pint)
    ('T_b   = { value = 0.65,       unit = "s"', 'T_b   = { value = 0.65,       unit = "km/h"',
     ["equations.a", "m / s ** 3", "h * m / km / s ** 2"]),
    ('T_b   = { value = 0.65,       unit = "s"', 'T_b   = { value = 0.65,       unit = "parsec"',
     ["equations.a", "m / s ** 3", "pc"]),
    ('T_b   = { value = 0.65,       unit = "s"', 'T_b   = { value = 0.65,       unit = "blorp"',
     ["parameters.T_b.unit = 'blorp'", "a unit pint knows"]),
    ('T_b   = { value = 0.65,       unit = "s"', 'T_b   = { value = 0.65,       unit = "degC"',
     ["parameters.T_b.unit = 'degC'", "OffsetUnitCalculusError"]),   # fuzz run 186
    ('a = "(max(u, -u_sb) - a)/T_b"', 'a = "(max(u, -u_sb) - a)*T_b"', ["equations.a", "m / s ** 3", "found m / s"]),
    ('a = "(max(u, -u_sb) - a)/T_b"', 'a = "(max(u, -u_sb) - a)/T_b + v"', ["equations.a", "terms of one unit"]),
    ('F_rail = "F_max*tanh(m0*a/F_max)"', 'F_rail = "F_max*tanh(m0*a)"',
     ["definitions.F_rail", "dimensionless argument of tanh"]),
    # zero divisors and complex values, named by their expression
    ('a = "(max(u, -u_sb) - a)/T_b"', 'a = "(max(u, -u_sb) - a)/T_b + a/0"', ["equations.a", "division by zero"]),
    ('a = "(max(u, -u_sb) - a)/T_b"', 'a = "(max(u, -u_sb) - a)/T_b*log(-1)"', ["equations.a", "complex value"]),
    # the search cap: a sane range, and not below the design's delay
    ("h_max = 1.5 ", "h_max = 0.5 ", ["synthesis.h_max = 0.5", "delay.max = 0.8 s"]),
    ("h_max = 1.5 ", "h_max = 1e308 ", ["synthesis.h_max", "[0.001, 10000]"]),
])
def test_train_design_bad_input_exits_2(tmp_path, capsys, old, new, words):
    design = TRAIN_ROBUST if old.startswith("h_max") else TRAIN
    err = _verify(tmp_path, capsys, design, old, new)
    for w in words:
        assert w in err, (w, err)


def test_zero_divisor_at_the_parameter_values(tmp_path, capsys):
    err = _verify(tmp_path, capsys, TRAIN, 'a = "(max(u, -u_sb) - a)/T_b"',
                  'a = "(max(u, -u_sb) - a)/T_b + grade/(grade + 0.01)*a/T_b"')
    assert "equations.a" in err and "division by zero" in err and "parameter values" in err


@pytest.mark.parametrize("old, new, words", [
    ("h_max = 100.0 ", "h_max = 1e308 ", ["synthesis.h_max = 1e+308", "[0.001, 10000]"]),
    ("h_max = 100.0 ", "h_max = 1e-300 ", ["synthesis.h_max = 1e-300", "[0.001, 10000]"]),
    ("c0   = { value = 180.9,", "c0   = { value = " + "9" * 39 + ",",
     ["operating_point.v_d", "the resistance needs mu = 8.503e+33"]),
])
def test_cruise_design_bad_input_exits_2(tmp_path, capsys, old, new, words):
    err = _verify(tmp_path, capsys, CRUISE, old, new)
    for w in words:
        assert w in err, (w, err)


def test_long_values_are_cut(tmp_path, capsys):
    big = "[" + ", ".join(["[" + ", ".join(["1.0"] * 300) + "]"] * 300) + "]"
    err = _verify(tmp_path, capsys, CRUISE, "c0   = { value = 180.9,", f"c0   = {{ value = {big},")
    assert "plant.c0.value" in err and len(err) < 600 and "characters)" in err


@pytest.mark.parametrize("tail, words", [
    ("z = " + "[" * 10000 + "]" * 10000, ["nested"]),
    ("z = " + "{a = " * 50 + "1" + "}" * 50, ["nested"]),
    ("[zz]\n" + ".".join(["a"] * 5000) + " = 1", ["nested", "dotted keys"]),
    ("huge = " + "9" * 1900, ["1900 digits"]),
    ('s = "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[ 999999999999999999999999999999999999999999999999"',
     None),
])
def test_toml_limits_before_parsing(tmp_path, tail, words):
    p = tmp_path / "x.toml"
    p.write_text("[design]\nname = 'x'\n" + tail + "\n")
    if words is None:                      # brackets and digits inside a string are text
        assert load_toml(p, "x.toml")["design"]["s"].startswith("[[[")
        return
    with pytest.raises(DesignError) as exc:
        load_toml(p, "x.toml")
    msg = str(exc.value)
    assert "\n" not in msg and len(msg) < 300
    for w in words:
        assert w in msg, msg
    assert MAX_DEPTH == 32


# -- searches ---------------------------------------------------------------------------
def _threshold(bound):
    def decide(h):
        ok = h <= bound
        return Step(h, Outcome.CERTIFIED if ok else Outcome.REFUTED, "optimal",
                    1.0 if ok else -1.0, {}, None, 0.0)
    return decide


@pytest.mark.parametrize("h_hi", [10.0, 1e4, 1e93, 1e308])
def test_the_search_finds_the_bound_whatever_the_cap(h_hi):
    """h_max = 1e308 reported every row refuted (the search never looked below 1e93)."""
    br = bisect_delay(_threshold(0.0433), h_lo=1e-4, h_hi=h_hi, rel_tol=1e-4, secant=False)
    assert br.outcome is Outcome.CERTIFIED
    assert 0.0433 * (1 - 1e-4) <= br.h_certified <= 0.0433 < br.h_refuted <= 0.0433 * 1.0002
    assert len(br.steps) <= 60


def test_the_search_stops_at_its_wall_clock_cap():
    br = bisect_delay(_threshold(1e-6), h_lo=1e-4, h_hi=10.0, max_seconds=0.0)
    assert len(br.steps) == 2 and br.outcome is not Outcome.CERTIFIED
    assert br.steps[-1].solver_status == "error: wall-clock cap of 0 s reached"


def test_a_solver_panic_is_inconclusive():
    """Clarabel's Rust panic is a BaseException (pyo3_runtime.PanicException)."""
    from workbench.lmi.core import MarginLMI

    class PanicException(BaseException):
        pass

    class Problem:
        def solve(self, **kw):
            raise PanicException("SVD error")

    class Fake:
        def set_delay(self, h):
            pass
    status, _ = MarginLMI._run(Fake(), Problem(), 0.1, {})
    assert status == "error: solver panic: SVD error"

    class Interrupt(Problem):
        def solve(self, **kw):
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt):
        MarginLMI._run(Fake(), Interrupt(), 0.1, {})


# -- simulate_delay ---------------------------------------------------------------------
A, B = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])


def test_simulate_delay_without_delay():
    from scipy.linalg import expm
    r = api.simulate_delay(A, [[-1.0, -1.0]], B=B, h=0.0, x0=[1.0, 0.0], t_end=5.0, dt=0.01)
    # x' = (A + B K) x (the input held over each step: first order in dt)
    exact = expm((A + B @ np.array([[-1.0, -1.0]])) * 5.0) @ [1.0, 0.0]
    assert r.diverged is None and np.max(np.abs(r.x[:, -1] - exact)) < 1e-3


def test_a_divergent_simulation_says_where():
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = api.simulate_delay(A, [[-100.0, -100.0]], B=B, h=1.0, x0=[1.0, 0.0],
                               t_end=2000.0, dt=0.01)
    t, state = r.diverged
    assert 0 < t < 2000.0 and state in ("x1", "x2") and r.t[-1] == t
    assert np.all(np.isfinite(r.x)) and "diverged" in str(w[0].message)


@pytest.mark.parametrize("kw", [dict(t_end=1e308), dict(dt=1e-300), dict(h=1e308)])
def test_simulate_delay_overflow_is_a_value_error(kw):
    args = dict(h=0.1, x0=[1.0, 0.0], t_end=5.0, dt=0.01) | kw
    with pytest.raises(ValueError, match="steps|finite"):
        api.simulate_delay(A, [[-1.0, -1.0]], B=B, **args)


def test_matrix_size_is_capped():
    with pytest.raises(ValueError, match="at most 200 rows"):
        api.simulate_delay(np.eye(500), np.ones((1, 500)), B=np.ones((500, 1)), h=0.1,
                           x0=np.ones(500), t_end=1.0, dt=0.01)
    assert math.isfinite(api.MAX_ORDER)


# -- equilibria (item 6) ----------------------------------------------------------------
_GIVEN = ('a = { solve = [-3.0, 3.0], source = "the force holding the speed on the grade (solved)" }\n'
          'u = { solve = [-3.0, 3.0], source = "its command (solved)" }')


def test_a_given_point_must_be_an_equilibrium(tmp_path, capsys):
    given = ('a = { value = 0.0, unit = "m/s^2", source = "t" }\n'
             'u = { value = 0.0, unit = "m/s^2", source = "t" }')
    err = _verify(tmp_path, capsys, TRAIN, _GIVEN, given)
    assert "operating_point = <max |f| = " in err and "trim = false" in err


def test_trim_false_linearises_off_equilibrium(tmp_path):
    from workbench.design import load_design
    from workbench.kinds.delay_feedback.run import nominal_point
    given = ('a = { value = 0.0, unit = "m/s^2", source = "t" }\n'
             'u = { value = 0.0, unit = "m/s^2", source = "t" }\ntrim = false')
    text = (ROOT / "designs" / f"{TRAIN}.toml").read_text().replace(_GIVEN, given)
    p = tmp_path / f"{TRAIN}.toml"
    p.write_text(text)
    d = load_design(p)
    assert d.spec.plant.trim is False
    assert nominal_point(d.spec)[2].residual > 1e-3      # reported, not hidden


def test_new_writes_into_the_project_roots_designs(tmp_path, monkeypatch, capsys):
    assert main(["init", str(tmp_path / "p")]) == 0
    (tmp_path / "p" / "proofs" / "deep").mkdir()
    monkeypatch.chdir(tmp_path / "p" / "proofs" / "deep")
    assert main(["new", "delay-feedback", "my-plant"]) == 0
    assert (tmp_path / "p" / "designs" / "my-plant.toml").is_file()
    assert not (tmp_path / "p" / "proofs" / "deep" / "designs").exists()


@pytest.mark.parametrize("J", ["5e-324", "1e-300"])
def test_an_ill_scaled_paper_model_exits_2(tmp_path, capsys, J):
    """J = 1e-300 ended in Clarabel's Rust panic, J = 5e-324 in a scipy traceback."""
    err = _verify(tmp_path, capsys, CRUISE, "J    = { value = 80.0,", f"J    = {{ value = {J},")
    assert "the linearisation at v_d = 70 m/s has an entry of" in err


def test_an_absurd_initial_state_exits_2(tmp_path, capsys):
    err = _verify(tmp_path, capsys, TRAIN, "x0 = { v = 22.89 }", "x0 = { v = 1e308 }")
    assert "scenarios[0].x0.v = 1e+308" in err


def test_a_syntax_error_at_the_end_is_not_column_0():
    from workbench.expr import check_expression
    with pytest.raises(DesignError, match="at the end of the expression"):
        check_expression("x +", {"x"}, path="p", key="k")
    with pytest.raises(DesignError, match="at col 3"):
        check_expression("a b", {"a", "b"}, path="p", key="k")


def test_a_large_benchmark_matrix_is_refused(tmp_path):
    """A 500 x 500 example tried to allocate 466 GiB."""
    from workbench.benchmark import MAX_ORDER, load_example
    n = MAX_ORDER + 1
    row = "[" + ", ".join(["0.0"] * n) + "]"
    p = tmp_path / "big.toml"
    p.write_text('[example]\nname = "big"\ntitle = "t"\nsource = "s"\n'
                 f"A = [{', '.join([row] * n)}]\nAd = [{', '.join([row] * n)}]\n")
    with pytest.raises(DesignError, match=f"example.A = <a {n} x {n} matrix>; expected at most"):
        load_example(p)


def test_eps_values_in_a_sane_range(tmp_path, capsys):
    """grid = [1e-300, ...] left the robust bisection solving past 120 s."""
    err = _verify(tmp_path, capsys, TRAIN_ROBUST, "grid = [0.3, 1.0, 3.0]",
                  "grid = [1e-300, 1.0, 3.0]")
    assert "synthesis.grid[0] = 1e-300" in err and "[1e-06, 1e+06]" in err
