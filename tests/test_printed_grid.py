"""Figure data and axis ends on a grid (workbench/printed_grid.py, issue 36 item 5)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.printed_grid import axis_end, directed, printed_digits, quantised, sig_round


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


def test_a_value_on_a_rounding_tie_gets_one_more_digit():
    from workbench.printed_grid import printed_digits
    from workbench.report.markdown import fmt
    # antiskid-cruise-dry-generic's peak_input_dev.w is 0.0022875 (repr
    # 0.002287499999999998): 0.002287 as designed, 0.002288 moved +3 ulp
    x = 0.002287499999999998
    up = math.nextafter(0.0022875, 1.0)
    assert fmt(x, 4) != fmt(up, 4)
    assert printed_digits(x) == printed_digits(up) == 5
    assert fmt(x, printed_digits(x)) == fmt(up, printed_digits(up)) == "0.0022875"
    # away from a tie, and for non-numbers, nothing changes
    assert printed_digits(0.0022871) == 4 and printed_digits(-2.5e-3) == 4
    assert printed_digits(float("nan")) == printed_digits(0.0) == printed_digits("yes") == 4
    assert printed_digits(-0.12345) == 5


@pytest.mark.parametrize("x", [5e-324, -5e-324, 1e-310, 2.2250738585072014e-308, 1e-300,
                               1.7e308, -1.7e308])
def test_sig_round_takes_subnormal_and_huge_values(x):
    """Fuzz campaign 3202 (round 3): a design value 3.0 -> 5e-324 made a basin
    level subnormal, 10**e underflowed to 0 and the report died dividing by it."""
    for how in (math.floor, math.ceil, round):
        y = sig_round(x, 4, how)
        assert math.isfinite(y) and (y == 0 or math.copysign(1, y) == math.copysign(1, x))
    lo, hi = directed(x, up=False), directed(x, up=True)
    assert lo <= hi
    assert printed_digits(x) == 4
    assert np.all(np.isfinite(quantised([x, 0.0])))
    from workbench.report.markdown import fmt_floor
    from workbench.roa.render import fmt_level
    assert fmt_level(abs(x), "up") and fmt_level(abs(x)) and fmt_floor(abs(x))


@pytest.mark.parametrize("x", [0.1234, 3.0, 123456.7, 9.99949e-7, 2.5e-12, 7.77e15])
def test_sig_round_in_range_is_the_float_expression(x):
    """Within the normal range the helper is the expression it replaced, bit for bit
    (the committed reports stay byte-identical)."""
    e = math.floor(math.log10(abs(x))) - 3
    for how in (math.floor, math.ceil, round):
        assert sig_round(x, 4, how, 1e-12) == how(x / 10.0**e + 1e-12) * 10.0**e
