"""The ``switched-run`` kind (issue 35, item 1): guards, delay, predictor,
sampled ZOH with quantisation, chattering, Monte Carlo, convergence, and bad
input (exit 2). Toy plants with exact answers (steps of 1/8 s: binary-exact
times, constant right-hand sides that Runge-Kutta 4 integrates exactly)."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds.switched_run.simulate import Compiled, simulate
from workbench.kinds.switched_run.study import runs_for
from workbench.outcome import Verdict
from workbench.verify import evaluate_design

HEAD = """
[design]
name = "toy"
kind = "switched-run"
title = "toy"
source = "test"

[states]
x = { unit = "m", source = "test" }

[inputs]
u = { unit = "m/s", source = "test" }

[parameters]
a = { value = 0.0, unit = "1/s", source = "test" }
k = { value = 3.0, unit = "1/s", source = "test" }
one = { value = 1.0, unit = "m", source = "test" }
speed = { value = 1.0, unit = "m/s", source = "test" }

[equations]
x = "a*x + u"
"""

#: x' = u: u = 1 until x reaches 1 m, then u = 0.
GUARD = HEAD + """
[delay]
h = { value = H, unit = "s", source = "test" }

[[phases]]
name = "go"
law = { u = "speed" }
next = [ { to = "hold", when = "x - one" } ]

[[phases]]
name = "hold"
law = { u = "0*speed" }

[[scenarios]]
name = "s"
x0 = { x = 0.0 }
t_end = 2.0
dt = 0.125
phase = "go"
"""


def write(tmp_path, text: str, name: str = "toy"):
    p = tmp_path / f"{name}.toml"
    p.write_text(text.replace('name = "toy"', f'name = "{name}"'), encoding="utf-8")
    return p


def run_once(path, dt=None, record=False, **spec_changes):
    d = load_design(path)
    spec = dataclasses.replace(d.spec, **spec_changes) if spec_changes else d.spec
    sc = spec.scenarios[0]
    return spec, simulate(spec, Compiled(spec), sc, dt or sc.dt, record=record)


def test_guard_switches_at_the_exact_time(tmp_path):
    _, b = run_once(write(tmp_path, GUARD.replace("H", "0.0")))
    m = {k: float(v[0]) for k, v in b.metrics.items()}
    assert m["switch_time.go.hold"] == 1.0
    assert m["final.x"] == 1.0 and m["time_in.go"] == 1.0 and m["time_in.hold"] == 1.0
    assert m["switches"] == 1.0 and m["diverged"] == 0.0 and m["completed"] == 0.0


def test_input_delay_applies_the_command_h_later(tmp_path):
    """u = 0 before t = 0 acts until h = 0.25 s, so x reaches 1 m at 1.25 s; the
    command u = 1 then keeps acting h longer: x ends at 1.25 m."""
    _, b = run_once(write(tmp_path, GUARD.replace("H", "0.25")))
    assert float(b.metrics["switch_time.go.hold"][0]) == 1.25
    assert float(b.metrics["final.x"][0]) == 1.25


def test_terminal_phase_ends_the_run(tmp_path):
    text = GUARD.replace("H", "0.0").replace('law = { u = "0*speed" }',
                                            'law = { u = "speed" }\nterminal = true\n'
                                            'until = "x - 3*one/2"')
    _, b = run_once(write(tmp_path, text))
    assert b.reasons == ("until",)
    assert float(b.metrics["end_time"][0]) == 1.5 and float(b.metrics["completed"][0]) == 1.0


LINEAR = HEAD + """
[delay]
h = { value = 0.2, unit = "s", source = "test" }
predictor = PRED

[[phases]]
name = "p"
law = { u = "-k*x" }

[[scenarios]]
name = "s"
x0 = { x = 1.0 }
t_end = 3.0
dt = 0.01
phase = "p"
"""


def test_predictor_removes_the_delay_on_a_linear_toy(tmp_path):
    """x' = x + u, u = -3 x(t + h) predicted: after h the delayed loop is the
    undelayed loop started from x(h) (same Runge-Kutta steps: to rounding);
    without the predictor it is not."""
    path = write(tmp_path, LINEAR.replace("0.0, unit = \"1/s\"", "1.0, unit = \"1/s\"")
                 .replace("PRED", "true"))
    spec, b = run_once(path, record=True)
    k = 20                                                  # h / dt
    sc = dataclasses.replace(spec.scenarios[0], x0=(float(b.x[0, k]),))
    free = dataclasses.replace(spec, h=0.0, predictor=False, scenarios=(sc,))
    ref = simulate(free, Compiled(free), sc, sc.dt, record=True)
    n = ref.x.shape[1] - k
    assert np.max(np.abs(b.x[0, k:] - ref.x[0, :n])) < 1e-12
    _, plain = run_once(write(tmp_path, LINEAR.replace("0.0, unit = \"1/s\"", "1.0, unit = "
                                                       "\"1/s\"").replace("PRED", "false"),
                              "plain"), record=True)
    assert np.max(np.abs(plain.x[0, k:] - ref.x[0, :n])) > 1e-2


SAMPLED = HEAD + """
[delay]
h = { value = 0.0, unit = "s", source = "test" }

[[phases]]
name = "p"
law = { u = "-x*speed/one" }

[[scenarios]]
name = "s"
x0 = { x = 1.0 }
t_end = 1.0
dt = 0.0625
phase = "p"

[sampled]
period = 0.5
QUANT
"""


@pytest.mark.parametrize("quant, final", [
    ("", 0.25),                               # x_{k+1} = x_k - T x_k = x_k / 2
    ("quantisation = { x = 0.3 }", 0.25),     # 1 - 0.5*0.9 = 0.55; 0.55 - 0.5*0.6 = 0.25
    ("quantisation = { x = 0.4 }", 0.4),      # 1 - 0.5*0.8 = 0.6; 0.6 - 0.5*0.4 = 0.4
])
def test_sampled_zoh_holds_the_command_between_instants(tmp_path, quant, final):
    _, b = run_once(write(tmp_path, SAMPLED.replace("QUANT", quant)))
    assert float(b.metrics["final.x"][0]) == pytest.approx(final, abs=1e-15)


def test_chattering_is_diverged_not_a_hang(tmp_path):
    text = HEAD + """
[delay]
h = { value = 0.0, unit = "s", source = "test" }
[[phases]]
name = "up"
law = { u = "speed" }
next = [ { to = "down", when = "x" } ]
[[phases]]
name = "down"
law = { u = "-speed" }
next = [ { to = "up", when = "-x" } ]
[[scenarios]]
name = "s"
x0 = { x = 0.0 }
t_end = 100.0
dt = 0.01
phase = "up"
"""
    _, b = run_once(write(tmp_path, text))
    assert float(b.metrics["diverged"][0]) == 1.0
    assert b.reasons[0].startswith("chattering: 11 switches within 1 s")
    assert float(b.metrics["diverged_time"][0]) < 0.2
    assert math.isnan(float(b.metrics["final.x"][0]))


MC = SAMPLED.replace("QUANT", "").replace('x = "a*x + u"', 'x = "a*x + g*u"').replace(
    "[equations]", 'g = { value = 1.0, unit = "1", source = "test" }\n\n[equations]') + """
[montecarlo]
samples = SAMPLES
seed = SEED
[montecarlo.distributions]
g = { dist = "uniform", lo = 0.5, hi = 1.5, source = "test" }

[[claims]]
id = "small"
description = "x ends small"
quantity = "scenario.s.final.x"
compare = "<="
value = 0.3
source = "test"
"""


def test_montecarlo_is_seeded_and_counts_passes(tmp_path):
    """x' = g u, u = -x(t_k) held: x_{k+1} = x_k (1 - T g), g drawn on [0.5, 1.5]
    (the law does not know it), so x(1) = (1 - 0.5 g)^2 <= 0.3 exactly when
    g >= 2 (1 - sqrt(0.3))."""
    path = write(tmp_path, MC.replace("SAMPLES", "50").replace("SEED", "7"))
    d = load_design(path)
    ev = evaluate_design(d)
    again = evaluate_design(load_design(path))
    mc = ev.result.scenarios[0].montecarlo
    c = mc.draws["g"]
    x1 = mc.metrics["final.x"]
    assert np.array_equal(x1, again.result.scenarios[0].montecarlo.metrics["final.x"])
    assert np.allclose(x1, (1 - 0.5 * c) ** 2, rtol=0, atol=1e-14)
    rate = ev.result.claim_rates[0]
    assert rate.passes == int(np.sum(c >= 2 * (1 - math.sqrt(0.3)))) and rate.n == 50
    assert rate.lo < rate.p < rate.hi and rate.success_run_lower is None
    other = load_design(write(tmp_path, MC.replace("SAMPLES", "50").replace("SEED", "8"),
                              "other"))
    assert not np.array_equal(evaluate_design(other).result.scenarios[0].montecarlo.draws[
        "g"], c)


def test_success_run_rule():
    assert runs_for(0.99) == 299 and 0.99 ** 299 < 0.05 < 0.99 ** 298


CONV = HEAD.replace('value = 0.0, unit = "1/s"', 'value = -1.0, unit = "1/s"') + """
[delay]
h = { value = 0.0, unit = "s", source = "test" }

[[phases]]
name = "fall"
law = { u = "0*speed" }
next = [ { to = "low", when = "3*one/10 - x" } ]

[[phases]]
name = "low"
law = { u = "0*speed" }

[[scenarios]]
name = "s"
x0 = { x = 1.0 }
t_end = 2.0
dt = 0.1
phase = "fall"

[convergence]

[[claims]]
id = "final"
description = "x(2) = exp(-2)"
quantity = "scenario.s.final.x"
compare = "within"
value = 0.1353
tolerance = 1e-4
source = "exact solution"

[[claims]]
id = "switch"
description = "x reaches 3/10 near ln(10/3) s"
quantity = "scenario.s.switch_time.fall.low"
compare = "within"
value = 1.3
tolerance = 0.01
source = "step-quantised crossing"
"""


def test_convergence_makes_an_unconverged_claim_inconclusive(tmp_path):
    """x' = -x (the plant; u = 0): x(2) converges at order 4; the switch time sits on the step
    grid (1.3, 1.25, 1.225 s at dt, dt/2, dt/4: first order, estimate 0.025 s
    > the claim's 0.01 s), so its claim passes at dt but is INCONCLUSIVE."""
    ev = evaluate_design(load_design(write(tmp_path, CONV)))
    by = {r.claim.id: r for r in ev.claims}
    assert by["final"].verdict is Verdict.PASS
    assert by["switch"].got == pytest.approx(1.3)
    assert by["switch"].verdict is Verdict.INCONCLUSIVE
    assert "not converged" in by["switch"].note
    rows = {r.claim_id: r for r in ev.result.refinement}
    assert rows["final"].converged and not rows["switch"].converged
    assert rows["switch"].values == pytest.approx((1.3, 1.25, 1.225))
    assert rows["switch"].check.estimate == pytest.approx(0.025)


def _cli_error(path, capsys) -> str:
    code = main(["verify", str(path)])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1
    return lines[0]


@pytest.mark.parametrize("old, new, key, expected", [
    ('to = "hold"', 'to = "nowhere"', "phases[0].next[0].to", "another phase: hold"),
    ('when = "x - one"', 'when = "x - two"', "phases[0].next[0].when", "undeclared name"),
    ('law = { u = "speed" }', 'law = { v = "speed" }', "phases[0].law.u", "required key"),
    ('law = { u = "speed" }', 'law = { u = "__import__(1)" }', "phases[0].law.u",
     "safe expression"),
    ("dt = 0.125", "dt = 0.1", "scenarios[0].dt", "whole multiple"),
    ('phase = "go"', 'phase = "stop"', "scenarios[0].phase", "one of"),
    ("t_end = 2.0\ndt = 0.125", "t_end = 1e5\ndt = 0.03125", "scenarios[0].dt", "at most"),
    ('name = "hold"', 'name = "go"', "phases[1].name", "used once"),
])
def test_bad_input_is_one_line_exit_2(tmp_path, monkeypatch, capsys, old, new, key, expected):
    monkeypatch.chdir(tmp_path)
    text = GUARD.replace("H", "0.25")
    assert old in text
    line = _cli_error(write(tmp_path, text.replace(old, new, 1)), capsys)
    assert key in line and expected in line, line


def test_a_law_may_not_use_a_definition_of_the_input(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    text = GUARD.replace("H", "0.0").replace("[equations]", '[definitions]\nw = "2*u"\n\n'
                                             "[equations]").replace('"0*speed"', '"w"')
    line = _cli_error(write(tmp_path, text), capsys)
    assert "phases[1].law.u" in line and "undeclared name 'w'" in line, line


# -- [montecarlo] on a delay-feedback design (issue 35, "Done when") ------------------------
DF = """
[design]
name = "df"
kind = "delay-feedback"
title = "test"
source = "test"

[states]
x = { unit = "rad", source = "test" }

[inputs]
u = { unit = "rad/s", source = "test" }

[parameters]
a = { value = 2.0, unit = "1/s", source = "test" }

[equations]
x = "-a*sin(x) + u"

[operating_point]
x = { value = 0.5, unit = "rad", source = "test" }
u = { solve = [-5.0, 5.0] }

[delay]
h = { value = 0.1, unit = "s", source = "test" }

[synthesis]
method = "wirtinger"

[[scenarios]]
name = "s"
x0 = { x = 0.8 }
t_end = 2.0
dt = 0.01

[montecarlo]
samples = 20
seed = 3
[montecarlo.distributions]
a = { dist = "uniform", lo = LO, hi = HI, source = "test" }
"""


def test_delay_feedback_montecarlo_reproduces_the_nominal_run(tmp_path):
    """Draws all at the nominal a = 2: every run's metrics are the nominal
    run's (same steps, same delayed ZOH averages); a wide draw spreads them."""
    p = tmp_path / "df.toml"
    p.write_text(DF.replace("LO", "1.9999999999").replace("HI", "2.0000000001"))
    ev = evaluate_design(load_design(p))
    nominal = ev.result.scenarios[0].metrics
    mc = ev.result.montecarlo[0]
    assert mc.samples == 20 and mc.metrics["diverged"].sum() == 0
    for k in ("peak_error.x", "final_error.x", "peak_input_dev.u"):
        assert np.allclose(mc.metrics[k], nominal[k], rtol=1e-6, atol=1e-12), k
    from workbench import kinds
    from workbench.kinds.delay_feedback.montecarlo import run_montecarlo
    from workbench.kinds.delay_feedback.run import nominal_point, predict, reference
    p.write_text(DF.replace("LO", "0.5").replace("HI", "4.0"))
    d = load_design(p)
    model, values, op, _, _ = nominal_point(d.spec)
    wide = run_montecarlo(d.spec, model, values, op, ev.result.synthesis.K, reference, predict)
    assert np.ptp(wide[0].metrics["final_error.x"]) > 1e-3
    names = kinds.REGISTRY["delay-feedback"].quantity_names(d.spec)
    assert {"montecarlo.s.runs", "montecarlo.s.diverged", "montecarlo.s.max.final_error.x"} <= names


@pytest.mark.parametrize("old, new, key, expected", [
    ('law = { u = "speed" }', 'law = { u = "one" }', "phases[0].law.u", "in the unit of u"),
    ('when = "x - one"', 'when = "x - speed"', "phases[0].next[0].when", "terms of one unit"),
])
def test_laws_and_guards_are_unit_checked(tmp_path, monkeypatch, capsys, old, new, key,
                                          expected):
    monkeypatch.chdir(tmp_path)
    line = _cli_error(write(tmp_path, GUARD.replace("H", "0.0").replace(old, new)), capsys)
    assert key in line and expected in line, line


def test_with_convergence_the_delay_is_a_multiple_of_the_designed_step(tmp_path, monkeypatch,
                                                                       capsys):
    """h = 0.25 s is 10 steps of dt/4 = 0.025 s but 2.5 of dt = 0.1 s: refused."""
    monkeypatch.chdir(tmp_path)
    text = GUARD.replace("H", "0.25").replace("dt = 0.125", "dt = 0.1") + "\n[convergence]\n"
    line = _cli_error(write(tmp_path, text), capsys)
    assert "scenarios[0].dt" in line and "2.5 steps" in line, line


#: v' = u: u = 1 m/s^2 until v reaches 1 m/s (t = 1 s), then 0.
COMFORT = GUARD.replace("H", "0.0").replace('x = { unit = "m", source = "test" }',
                                            'x = { unit = "m/s", source = "test" }').replace(
    'u = { unit = "m/s", source = "test" }', 'u = { unit = "m/s^2", source = "test" }').replace(
    'one = { value = 1.0, unit = "m", ', 'one = { value = 1.0, unit = "m/s", ').replace(
    'speed = { value = 1.0, unit = "m/s", ', 'speed = { value = 1.0, unit = "m/s^2", ').replace(
    'x = "a*x + u"', 'x = "u"') + """
[comfort]
speed = "x"
LIMITS
"""
LIMITS = ('a_max = { value = 0.5, unit = "m/s^2", source = "test" }\n'
          'jerk_max = { value = 4.0, unit = "m/s^3", source = "test" }')


def test_comfort_limits_give_the_time_above_them(tmp_path, monkeypatch, capsys):
    """The general comfort feature in the switched-run kind: a = 1 m/s^2 on the
    8 steps before t = 1 s, then 0: peak |a| 1, peak |jerk| 1 / dt = 8 m/s^3;
    above 0.5 m/s^2 for 1 s, above 4 m/s^3 for one step (0.125 s). Without
    limits, only the peaks are metrics."""
    spec, b = run_once(write(tmp_path, COMFORT.replace("LIMITS", LIMITS)))
    m = {k: float(v[0]) for k, v in b.metrics.items()}
    assert (m["peak_abs_accel"], m["peak_abs_jerk"]) == (1.0, 8.0)
    assert (m["time_above_accel"], m["time_above_jerk"]) == (1.0, 0.125)
    from workbench.kinds.switched_run.quantities import scenario_metrics
    units = scenario_metrics(spec, "s")
    assert units["time_above_accel"] == "s" and units["peak_abs_jerk"] == "(m/s)/s^2"
    spec, b = run_once(write(tmp_path, COMFORT.replace("LIMITS", "")))
    assert "time_above_accel" not in b.metrics and b.metrics["peak_abs_jerk"][0] == 8.0
    assert "time_above_accel" not in scenario_metrics(spec, "s")
    monkeypatch.chdir(tmp_path)
    line = _cli_error(write(tmp_path, COMFORT.replace("LIMITS", LIMITS.replace("m/s^3", "m/s^2"))),
                      capsys)
    assert "comfort.jerk_max.unit" in line and '"m/s^3"' in line, line


def test_whole_steps_of_the_delay_and_the_control_period():
    """A delay or period of 3 steps with decimal rounding is whole; a quarter
    step off, or a value that rounds to 0 steps, is not."""
    from workbench.kinds.switched_run import whole_steps
    assert whole_steps(0.3, 0.1) and whole_steps(0.1, 0.1)
    assert not whole_steps(0.25, 0.1) and not whole_steps(1e-300, 0.1)
