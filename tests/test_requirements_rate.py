"""A time-varying delay in the requirements (issue 31, ``rate = mu``): the
descriptor certificates with the (1 - mu) factor against the constant-delay
certificates and the exact constant-delay decay, the varying-delay
simulation, bad input."""
from __future__ import annotations

import numpy as np
import pytest

import workbench
from workbench.lmi.core import Outcome
from workbench.lmi.requirements import Loop, RequirementAnalysis
from workbench.lmi.requirements_synthesis import certify_gain
from workbench.margins.decay import worst_decay
from workbench.requirements import simulate_varying

from test_delay_feedback_requirements import write

B = np.array([[0.0], [1.0]])
#: (A, K, H): the pendulum-type loop of tests/test_requirements.py and a
#: stable oscillator (fixed gains, delay range [0, H] s).
LOOPS = [
    (np.array([[0.0, 1.0], [1.0, 0.0]]), np.array([[-2.622, -2.615]]), 0.3),
    (np.array([[0.0, 1.0], [-2.0, -0.1]]), np.array([[-0.5, -1.2]]), 0.2),
]


def _cert(A, K, H, mu):
    return certify_gain(Loop(((A, B),)), K, h_min=0.0, H=H, alpha=0.0, gamma=1.0, mu=mu)


@pytest.mark.parametrize("A, K, H", LOOPS)
def test_rate_zero_is_the_constant_delay_descriptor_lmi(A, K, H):
    # the same LMI: mu = 0 and mu = None decide every decay rate alike
    for alpha in (0.1, 0.5, 0.8):
        out = []
        for mu in (None, 0.0):
            lmi = RequirementAnalysis(Loop(((A, B),)), K, mu=mu)
            lmi.set_rate(alpha)
            out.append(lmi.solve_at(H).outcome)
        assert out[0] is out[1]


@pytest.mark.parametrize("A, K, H", LOOPS)
def test_rate_certificates_shrink_with_mu_and_stay_below_the_exact_decay(A, K, H):
    exact = worst_decay([(A, B @ K)], 0.0, H)
    prev = None
    for mu in (0.0, 0.3, 0.6):
        c = _cert(A, K, H, mu)
        assert c.alpha.outcome is Outcome.CERTIFIED and c.delay.outcome is Outcome.CERTIFIED
        # a constant delay is a delay function with h' = 0: the exact decay bounds it
        assert c.alpha_certified <= exact.decay
        assert c.h_certified >= H
        if prev is not None:
            # the feasible set only shrinks as mu grows: certified at most the
            # previous bracket's refuted end (the bisection's own tolerance)
            assert c.alpha_certified <= prev.alpha.h_refuted
            assert c.h_certified <= prev.delay.h_refuted
        prev = c
    # the delay cap is strictly smaller at mu = 0.6 than at 0 on these loops
    assert prev.h_certified < _cert(A, K, H, 0.0).delay.h_certified


@pytest.mark.slow
def test_rate_zero_is_no_better_than_the_constant_delay_cells():
    A, K, H = LOOPS[0]
    cells = _cert(A, K, H, None)        # Bessel-Legendre cells (constant delays only)
    desc = _cert(A, K, H, 0.0)
    assert desc.alpha_certified <= cells.alpha.h_refuted


def test_design_gain_with_rate_and_its_varying_delay_simulation():
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    r = workbench.design_gain(A, B, delay=(0.1, 0.3), objective="decay", rate=0.3)
    assert r.K is not None and r.rate == 0.3
    row = r.row("decay")
    assert row.verdict in ("PASS", "INCONCLUSIVE")
    assert row.certified <= row.exact
    assert "|h'| <= 0.3" in row.note
    run = r.varying
    assert run is not None and np.max(run.h) <= 0.3 + 1e-12 and np.min(run.h) >= 0.1 - 1e-12
    assert np.max(np.abs(np.diff(run.h))) <= 0.3 * (run.t[1] - run.t[0]) * 1.0001
    assert run.decay() < np.exp(-0.5 * row.certified * run.t[-1])


def test_varying_simulation_of_an_unstable_gain_grows():
    # a gain too weak for the pendulum: the check can fail
    A = np.array([[0.0, 1.0], [1.0, 0.0]])
    run = simulate_varying((A, B), np.array([[-0.5, -0.5]]), (0.1, 0.3), 0.3, None)
    assert run.decay() > 1.0


@pytest.mark.parametrize("rate", [1.0, 1.5, -0.1, True])
def test_api_rejects_a_bad_rate(rate):
    with pytest.raises(ValueError, match="rate"):
        workbench.design_gain(np.array([[0.0, 1.0], [1.0, 0.0]]), B, delay=(0.0, 0.3),
                              rate=rate)


@pytest.mark.parametrize("line, replace, words", [
    ('rate = { value = 1.2, unit = "1", source = "t" }\n', None,
     ["requirements.rate.value", "below 1"]),
    ('rate = { value = 0.2, unit = "s", source = "t" }\n', None,
     ["requirements.rate.unit", '"1"']),
    ('rate = { value = 0.2, unit = "1", source = "t" }\n',
     {'delay = [0.0, 0.2]': 'delay = [0.2, 0.2]'}, ["requirements.delay", "rate"]),
])
def test_bad_rate_in_a_design_exits_2(tmp_path, monkeypatch, capsys, line, replace, words):
    from workbench.cli import main
    monkeypatch.chdir(tmp_path)
    code = main(["verify", str(write(tmp_path, extra=line, replace=replace))])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1
    for w in words:
        assert w in err, err


def test_rate_loads(tmp_path):
    from workbench.design import load_design
    spec = load_design(write(tmp_path, extra='rate = { value = 0.25, unit = "1", '
                                             'source = "t" }\n')).spec
    assert spec.requirements.rate == 0.25


SCHEDULE = '''
[[scenarios]]
name = "push"
parameters = {{ w = {steps} }}
t_end = 2.0
dt = 0.01
'''


def test_scenario_parameter_schedule_loads_and_adds_min_error(tmp_path):
    from workbench.design import load_design
    d = load_design(write(tmp_path, extra=SCHEDULE.format(steps="[[0.0, 0.0], [0.5, 1.0]]")))
    sc = d.spec.scenarios[0]
    assert sc.parameters == {"w": ((0.0, 0.0), (0.5, 1.0))}
    from workbench.kinds.delay_feedback import DelayFeedback
    names = DelayFeedback().quantity_names(d.spec)
    assert "simulation.push.min_error.x" in names


@pytest.mark.parametrize("steps, words", [
    ("[[0.0, 0.0], [0.5, 1.0], [0.5, 2.0]]", ["scenarios[0].parameters.w", "increasing"]),
    ("[[0.1, 0.0]]", ["scenarios[0].parameters.w", "from 0"]),
    ("[[0.0, 0.0], [3.0, 1.0]]", ["scenarios[0].parameters.w", "t_end"]),
    ("[[0.0, true]]", ["scenarios[0].parameters.w", "pairs"]),
])
def test_bad_schedule_exits_2(tmp_path, monkeypatch, capsys, steps, words):
    from workbench.cli import main
    monkeypatch.chdir(tmp_path)
    code = main(["verify", str(write(tmp_path, extra=SCHEDULE.format(steps=steps)))])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    for w in words:
        assert w in err, err


def test_schedule_of_an_unknown_parameter_exits_2(tmp_path, monkeypatch, capsys):
    from workbench.cli import main
    monkeypatch.chdir(tmp_path)
    text = SCHEDULE.format(steps="[[0.0, 0.0]]").replace("w = ", "q = ")
    code = main(["verify", str(write(tmp_path, extra=text))])
    err = capsys.readouterr().err
    assert code == 2 and "scenarios[0].parameters.q" in err and "a parameter" in err
