"""The ``[requirements]`` table of a delay-feedback design (issue 31): loading,
bad input (exit 2, one line), the quantities and --json of a small design."""
from __future__ import annotations

import json

import pytest

from workbench.cli import main
from workbench.design import load_design

BASE = '''
[design]
name = "{name}"
kind = "delay-feedback"
title = "test"
source = "tests/test_delay_feedback_requirements.py"

[states]
x = {{ unit = "m", source = "test" }}
v = {{ unit = "m/s", source = "test" }}

[inputs]
u = {{ unit = "m/s^2", source = "test" }}

[parameters]
w = {{ value = 0.0, unit = "m/s^2", source = "disturbance (zero at the point)" }}
k = {{ value = 1.0, unit = "1/s^2", source = "test (the stiffness that makes x + u + w one unit)" }}

[equations]
x = "v"
v = "k*x + u + w"

[operating_point]
x = {{ value = 0.0, unit = "m", source = "test" }}
v = {{ value = 0.0, unit = "m/s", source = "test" }}
u = {{ value = 0.0, unit = "m/s^2", source = "test" }}

[delay]
min = {{ value = 0.0001, unit = "s", source = "test" }}
max = {{ value = 0.2, unit = "s", source = "test" }}

[requirements]
objective = "decay"
delay = [0.0, 0.2]
decay_rate = {{ value = 0.5, unit = "1/s", source = "test" }}
'''


def write(tmp_path, name="r", extra="", replace=None):
    text = BASE.format(name=name) + extra
    for old, new in (replace or {}).items():
        assert old in text
        text = text.replace(old, new)
    p = tmp_path / f"{name}.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_requirements_load(tmp_path):
    extra = ('input_limit = { u = { value = 5.0, unit = "m/s^2", source = "t" } }\n'
             'box = { x = { value = 0.1, unit = "m", source = "t" } }\n'
             'l2_gain = { value = 3.0, source = "t" }\n'
             'disturbance = { parameter = "w", source = "t" }\n'
             'outputs = ["x", "0.1*u"]\n')
    spec = load_design(write(tmp_path, extra=extra)).spec
    r = spec.requirements
    assert spec.synthesis.method == "requirements"
    assert r.delay == (0.0, 0.2) and r.decay_rate == 0.5 and r.objective == "decay"
    assert r.input_limit == {"u": 5.0} and r.box == {"x": 0.1}
    assert r.l2_gain == 3.0 and r.disturbance == "w" and r.outputs == ("x", "0.1*u")


@pytest.mark.parametrize("extra, replace, words", [
    ("", {'objective = "decay"': 'objective = "fast"'}, ["requirements.objective", "'fast'"]),
    ("", {'delay = [0.0, 0.2]': 'delay = [0.3, 0.2]'}, ["requirements.delay", "h_min"]),
    ("", {'unit = "1/s", source = "test"': 'unit = "1/min", source = "test"'},
     ["requirements.decay_rate.unit", '"1/s"']),
    ('input_limit = { u = { value = 5.0, unit = "m/s^2", source = "t" } }\n', None,
     ["requirements.input_limit", "box"]),
    ('input_limit = { u = { value = 5.0, unit = "m/s^2", source = "t" } }\n'
     'box = { y = { value = 0.1, unit = "m", source = "t" } }\n', None,
     ["requirements.box.y", "a state"]),
    ('l2_gain = { value = 3.0, source = "t" }\ndisturbance = { parameter = "q", source = "t" }\n'
     'outputs = ["x"]\n', None, ["requirements.disturbance.parameter", "value 0"]),
    ('l2_gain = { value = 3.0, source = "t" }\ndisturbance = { parameter = "w", source = "t" }\n',
     None, ["requirements.outputs", "<missing>"]),
    ('speed = 3\n', None, ["requirements.speed", "no such key"]),
    ('[synthesis]\nmethod = "wirtinger"\n', None, ["synthesis.method", "requirements"]),
])
def test_bad_requirements_exit_2_with_one_line(tmp_path, monkeypatch, capsys, extra, replace,
                                               words):
    monkeypatch.chdir(tmp_path)
    code = main(["verify", str(write(tmp_path, extra=extra, replace=replace))])
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1
    for w in words:
        assert w in lines[0], lines[0]


@pytest.mark.slow
def test_synthesize_json_has_one_row_per_requirement(tmp_path, monkeypatch, capsys):
    """x'' = x + u(t - h) over [0, 0.2] s: decay objective with the L2 row; every
    row PASSes and the exact values confirm the certified ones."""
    monkeypatch.chdir(tmp_path)
    extra = ('l2_gain = { value = 5.0, source = "t" }\n'
             'disturbance = { parameter = "w", source = "t" }\noutputs = ["x"]\n')
    code = main(["synthesize", "delay-bound", str(write(tmp_path, extra=extra)), "--json"])
    out = json.loads(capsys.readouterr().out)
    rows = out["requirements"]
    assert set(rows) == {"delay", "decay", "l2_gain"}
    assert all(r["verdict"] == "PASS" for r in rows.values()), rows
    assert rows["decay"]["exact"] >= rows["decay"]["certified"] >= 0.5
    assert rows["l2_gain"]["exact"] <= rows["l2_gain"]["certified"] <= 5.0
    assert code == 0
