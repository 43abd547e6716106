"""Figure data and axis ends on a grid (workbench/printed_grid.py, issue 36 item 5)."""
from __future__ import annotations

import math

import numpy as np

from workbench.printed_grid import axis_end, directed, quantised


def test_directed_rounds_towards_the_certified_side():
    assert directed(1.23456, up=False) == 1.234
    assert directed(1.23411, up=True) == 1.235
    assert directed(0.0, up=True) == 0.0 and math.isinf(directed(math.inf, up=False))
    assert math.isnan(directed(math.nan, up=True))


def test_axis_end_ignores_last_bit_noise():
    x = 1.25 * 1.7802
    ends = {axis_end(v) for v in (x, np.nextafter(x, 0), np.nextafter(x, 9), x * (1 + 3e-13))}
    assert ends == {2.3}
    assert axis_end(0.5 * 1.25) == 0.63


def test_quantised_keeps_nan_and_drops_noise():
    v = np.array([0.123456789, -1.5, np.nan, 2.0])
    q = quantised(v)                          # decade of 2.0: step 1e-3
    assert np.isnan(q[2]) and np.allclose(q[[0, 1, 3]], [0.123, -1.5, 2.0])
    noisy = quantised(v * (1 + 4e-13))
    assert np.array_equal(np.nan_to_num(q, nan=-9), np.nan_to_num(noisy, nan=-9))
    assert np.allclose(quantised([0.98765], scale=1.0), [0.988])
    assert np.array_equal(quantised([np.nan]), [np.nan], equal_nan=True)
