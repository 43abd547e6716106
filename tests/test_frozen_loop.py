"""The loop frozen at a state (:mod:`workbench.features.frozen_loop`) on toys
that name no paper: a pendulum-like f and a scalar delayed loop with known
exact answers."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.features.frozen_loop import central_jacobian, freeze


def test_central_jacobian_of_a_known_field():
    f = lambda x: np.array([x[1], -math.sin(x[0]) - 0.5 * x[1] ** 2])
    A = central_jacobian(f, (0.3, 2.0), (1e-5, 1e-5))
    np.testing.assert_allclose(A, [[0.0, 1.0], [-math.cos(0.3), -2.0]], atol=1e-8)


def test_freeze_scalar_delayed_loop_margin_and_abscissa():
    # x' = -x + k x(t - h), k = -2: delay-free abscissa -3; omega* = sqrt(3),
    # h* = acos(-1/2) / sqrt(3)
    fl = freeze(lambda x: np.array([-x[0] + 0.1 * x[0] ** 3]), (0.0,), (1e-6,),
                np.array([[-2.0]]))
    assert fl.A[0, 0] == pytest.approx(-1.0, abs=1e-9)
    assert fl.abscissa == pytest.approx(-3.0, abs=1e-9)
    assert fl.margin.h == pytest.approx(math.acos(-0.5) / math.sqrt(3.0), rel=1e-6)
    assert fl.x0 == (0.0,)                  # the state it is frozen at, kept
    # |k| < 1: stable for every delay
    assert math.isinf(freeze(lambda x: -x, (1.0,), (1e-6,), np.array([[0.5]])).margin.h)


def test_frozen_loop_cells_of_toys():
    """The printed cells (features.frozen_loop_render): A on the grid of its
    largest entry (a last-bit-noise entry prints 0), the abscissa, the margin."""
    from workbench.features.frozen_loop_render import (FROZEN_ALIGN, FROZEN_HEADS,
                                                       frozen_loop_cells, margin_cell)
    fl = freeze(lambda x: np.array([-x[0] + 0.1 * x[0] ** 3]), (0.0,), (1e-6,),
                np.array([[-2.0]]))
    cells = frozen_loop_cells(fl.A, fl.abscissa, fl.margin)
    assert len(cells) == len(FROZEN_HEADS) == len(FROZEN_ALIGN)
    A, ab, m = cells
    assert (A, ab) == ("$\\begin{bmatrix} -1 \\end{bmatrix}$", "-3")
    assert m == f"{math.acos(-0.5) / math.sqrt(3.0):.3g} s"
    assert frozen_loop_cells(np.array([[1.0, 2.6e-7]]), 0.5, fl.margin)[0] == (
        "$\\begin{bmatrix} 1 & 0 \\end{bmatrix}$")
    assert margin_cell(freeze(lambda x: -x, (1.0,), (1e-6,), np.array([[0.5]])).margin) == (
        "∞ (delay-independent)")
    assert margin_cell(freeze(lambda x: x, (1.0,), (1e-6,), np.array([[0.5]])).margin) == (
        "unstable at h = 0")
