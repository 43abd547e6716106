"""The wheel-slip plant's right-hand side under a held torque and its
holding torque (:mod:`workbench.sim.wheel_slip`), and the plant's parameters
along a batch's path on a gradient (:class:`workbench.sim.perturb.PlantOnPath`)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from workbench.design import load_design
from workbench.sim.counter_rng import run_key
from workbench.sim.perturb import Perturbations, PlantOnPath, grade_at
from workbench.sim.wheel_slip import (ScalarOps, held_torque_rhs, holding_torque,
                                      model_functions, plant_step)


@pytest.fixture(scope="module")
def p():
    from workbench.papers.p003.antiskid_run_spec import sampled_context
    spec = load_design(Path("designs/antiskid-run-dry.toml")).spec
    return tuple(sampled_context(spec, spec.K_table).plant)


def test_rhs_takes_the_form_by_the_sign_and_floors_the_speed(p):
    fns, u = model_functions("math"), 150.0
    for lam, form in ((0.01, "traction"), (-0.01, "braking")):
        y = fns[form](20.0, lam, *p)
        assert held_torque_rhs(p)(u)(0.0, (20.0, lam)) == (y[0], y[1] + y[2] * u)
    f = held_torque_rhs(p)(u)
    assert f(0.0, (0.0, 0.01)) == f(0.0, (1e-3, 0.01))


def test_rhs_agrees_with_the_plant_step_and_the_holding_torque_holds(p):
    from scipy.integrate import solve_ivp
    v, lam, u = 20.0, 0.01, 120.0
    sol = solve_ivp(held_torque_rhs(p)(u), (0.0, 0.01), (v, lam), method="Radau",
                    rtol=1e-10, atol=(1e-10, 1e-13))
    x = (v, lam)
    for _ in range(1000):
        x = plant_step(x, u, p, 1e-5, model_functions("math"), ScalarOps)
    assert math.isclose(x[0], sol.y[0, -1], rel_tol=1e-6)     # Euler in v: O(dt)
    assert math.isclose(x[1], sol.y[1, -1], rel_tol=1e-3)
    u0 = holding_torque(v, lam, p)
    assert abs(held_torque_rhs(p)(u0)(0.0, (v, lam))[1]) < 1e-12


def test_plant_on_path_appends_the_slope_at_the_integrated_positions():
    p = (np.array([1.0, 2.0]), 3.0)
    assert PlantOnPath(None, p).params(np.ones(2), 0.1) is p
    keys = {"grade": tuple(int(k) for k in run_key(7, 2, np.arange(2)))}
    pt = Perturbations(run=(0, 1), keys=keys, grade=(-0.01, 0.02), segment=5.0)
    path, pos = PlantOnPath(pt, p), np.zeros(2)
    assert path.graded and path.fns is model_functions("numpy", graded=True)
    for v in (np.array([30.0, 10.0]), np.array([40.0, 20.0]), np.array([1.0, 1.0])):
        pp = path.params(v, 0.1)
        assert pp[:2] == p
        np.testing.assert_array_equal(pp[2], grade_at(pos, np.asarray(keys["grade"], np.uint64),
                                                      -0.01, 0.02, 5.0))
        pos = pos + 0.1 * v
    assert len(set(pp[2])) == 2      # the runs are on different segments by now
