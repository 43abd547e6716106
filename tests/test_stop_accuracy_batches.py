"""Batches of the stop-accuracy kind on its general synthetic design (no
paper): the Monte Carlo of named controllers
(:func:`workbench.kinds.stop_accuracy.run.controller_montecarlo`: keyed by
speed and controller, a controller's statistics independent of which others
share the batch) and the recorded stops over the values of one factor
(:func:`workbench.kinds.stop_accuracy.run.factor_traces`)."""
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
