"""Damping of a stop-accuracy design's linearised loops
(:mod:`workbench.kinds.stop_accuracy.loop_damping`) on non-paper systems: the
speed PID of the general synthetic design (with and without the predictor's
dead time), a toy controller with the module ``deceleration_loop``, and the
oscillation count of a recorded error
(:func:`~workbench.kinds.stop_accuracy.loop_damping.sign_changes`)."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import pytest

from workbench.design import load_design
from workbench.kinds.stop_accuracy.loop_damping import (loop_damping, loop_values, pid_damping,
                                                        pid_dead_time, pid_gains)
from workbench.tuning.pid import damping, deceleration_loop, speed_loop

SYNTH = Path(__file__).resolve().parent.parent / "designs" / "stop-accuracy-synthetic.toml"


@pytest.fixture(scope="module")
def spec():
    return load_design(SYNTH).spec


def test_speed_pid_of_the_synthetic_design(spec):
    c = {k: q.value for k, q in spec.constants.items()}
    assert pid_gains(spec, "profile_pid") == {"kp": c["k_v"], "ki": c["k_i"], "kd": c["k_d"]}
    h = spec.params["T1"].value + spec.dt_ctrl / 2          # no predictor: T1 + sample and hold
    assert pid_dead_time(spec, "profile_pid") == h
    p = {k: q.value for k, q in spec.params.items()}
    want = damping(*speed_loop(c["k_v"], c["k_i"], c["k_d"], P1=p["P1"], T2=p["T2"]), h)
    assert pid_damping(spec, "profile_pid") == want
    ctl = [replace(x, predictor=True) if x.name == "profile_pid" else x for x in spec.controllers]
    assert pid_dead_time(replace(spec, controllers=tuple(ctl)), "profile_pid") == spec.dt_ctrl / 2


def test_deceleration_loop_of_a_toy_controller():
    q = lambda x: SimpleNamespace(value=x)
    values = {"kp": 0.5, "ki": 0.4, "tau_filter": 0.2}
    loop = SimpleNamespace(values=lambda constants: values)
    toy = SimpleNamespace(controllers=(SimpleNamespace(name="other"),
                                       SimpleNamespace(name="c", loop=loop)),
                          params={"T1": q(0.3), "T2": q(0.5), "P1": q(0.9)}, dt_ctrl=0.1,
                          constants={})
    assert loop_values(toy, "c") == values
    got = loop_damping(toy, "c")
    assert got == damping(*deceleration_loop(0.5, 0.4, P1=0.9, T2=0.5, tau=0.2), 0.3 + 0.1)
    assert got.alpha < 0 and 0 < got.zeta <= 1


def test_sign_changes_ignore_the_deadband():
    from workbench.kinds.stop_accuracy.loop_damping import sign_changes
    assert sign_changes([1.0, 0.01, -1.0, -0.5, 0.2, 0.03, -0.01], 0.05) == 2
    assert sign_changes([0.01, -0.02, 0.03], 0.05) == 0                  # all inside the band
