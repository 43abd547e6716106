"""Batches of the stop-accuracy kind on its general synthetic design (no
paper): the Monte Carlo of named controllers
(:func:`workbench.kinds.stop_accuracy.run.controller_montecarlo`: keyed by
speed and controller, a controller's statistics independent of which others
share the batch), the recorded stops over the values of one factor
(:func:`workbench.kinds.stop_accuracy.run.factor_traces`), and the first repeat of a
controller on a section with its target (:func:`~workbench.kinds.stop_accuracy.run.section_example`,
on toy traces)."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from workbench.design import load_design
from workbench.kinds.stop_accuracy.run import (compile_laws, controller_index,
                                               controller_montecarlo, factor_traces,
                                               simulate_cases, stopping_points)

SYNTH = Path(__file__).resolve().parent.parent / "designs" / "stop-accuracy-synthetic.toml"


@pytest.fixture(scope="module")
def spec():
    s = load_design(SYNTH).spec
    return replace(s, montecarlo=replace(s.montecarlo, samples=16))


def test_controller_montecarlo_keys_and_common_draws(spec):
    D = stopping_points(spec)
    both = controller_montecarlo(spec, ["held", "profile"], D)
    assert list(both) == [(s, c) for s in spec.speeds_kmh for c in ("held", "profile")]
    alone = controller_montecarlo(spec, ["profile"], D)
    for s in spec.speeds_kmh:
        assert alone[s, "profile"].errors == both[s, "profile"].errors
        assert both[s, "held"].n == 16


def test_factor_traces_end_at_the_stops(spec):
    D = stopping_points(spec)
    s = spec.speeds_kmh[0]
    tr = factor_traces(spec, ["held", "profile"], s, D[s], "gradient", [-2.0, 0.0, 2.0])
    assert list(tr) == [(g, c) for c in ("held", "profile") for g in (-2.0, 0.0, 2.0)]
    one, _ = simulate_cases(spec, compile_laws(spec), spec.dt,
                            [(s, controller_index(spec, "profile"), None, D[s])])
    dx, v = tr[0.0, "profile"]
    assert dx[-1] == pytest.approx(one.x_stop[0] - D[s], abs=1e-9) and v[-1] == 0.0
    assert tr[2.0, "held"][0][-1] < tr[-2.0, "held"][0][-1]      # uphill stops shorter


def test_section_example_is_the_first_repeat_with_its_target():
    from types import SimpleNamespace

    import numpy as np

    from workbench.kinds.stop_accuracy.modules import Reference
    from workbench.kinds.stop_accuracy.run import section_example
    toy = SimpleNamespace(controllers=(SimpleNamespace(name="a"), SimpleNamespace(name="b")),
                          reference=Reference(10.0, 1.0, 0.5))
    t = np.linspace(0.0, 20.0, 5)
    x = np.arange(20.0).reshape(5, 4)
    runs = {"controller": np.array([0, 0, 1, 1]), "section": np.array([0, 1, 1, 0]),
            "D": np.array([1000.0, 2000.0, 2000.0, 1000.0])}
    tt, dx, v, xd, vd = section_example(toy, SimpleNamespace(t=t, x=x, v=-x), runs, "b")
    assert tt is t and list(dx) == list(x[:, 3] - 1000.0) and list(v) == list(-x[:, 3])
    assert xd[0] == pytest.approx(-100.0) and vd[0] == pytest.approx(10.0)   # v^2 / (2 a_dec)
    assert xd[-1] == pytest.approx(0.0) and vd[-1] == pytest.approx(0.0)     # stopped at D
