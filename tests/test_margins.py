"""Exact delay margins against analytic cases, and the two methods agreeing."""
import math

import numpy as np
import pytest

from workbench.margins import delay_margin_eig, delay_margin_siso, spectral_abscissa

CASES = [
    # x' = -x(t-h): pi/2 (Gu, Kharitonov & Chen 2003, sec 2.2)
    (np.array([[0.0]]), np.array([[1.0]]), np.array([[-1.0]]), math.pi / 2),
    # x' = -x - 2 x(t-h): w = sqrt(3), h = (2 pi/3)/sqrt(3)
    (np.array([[-1.0]]), np.array([[1.0]]), np.array([[-2.0]]), 2 * math.pi / (3 * math.sqrt(3))),
]


@pytest.mark.parametrize("A, B, K, expected", CASES)
def test_scalar_analytic(A, B, K, expected):
    assert delay_margin_eig(A, B @ K).h == pytest.approx(expected, rel=1e-10)
    assert delay_margin_siso(A, B, K).h == pytest.approx(expected, rel=1e-8)


def test_classic_two_by_two():
    # Gu, Kharitonov & Chen (2003) example: exact margin about 6.1726
    A = np.array([[-2.0, 0.0], [0.0, -0.9]])
    Ad = np.array([[-1.0, 0.0], [-1.0, -1.0]])
    dm = delay_margin_eig(A, Ad)
    assert dm.h == pytest.approx(6.1726, abs=5e-5)
    # the spectral abscissa changes sign there
    assert spectral_abscissa(A, Ad, 0.99 * dm.h) < 0 < spectral_abscissa(A, Ad, 1.01 * dm.h)


def test_infinite_and_zero():
    # |k| < a: delay-independent stable
    dm = delay_margin_eig([[-2.0]], [[1.0]])
    assert math.isinf(dm.h) and dm.reason == "delay-independent"
    assert math.isinf(delay_margin_siso([[-2.0]], [[1.0]], [[1.0]]).h)
    # A + A_d not Hurwitz: 0
    dm = delay_margin_eig([[1.0]], [[-0.5]])
    assert dm.h == 0.0 and dm.reason == "unstable-at-zero-delay"


def test_methods_agree_on_random_single_input_loops():
    rng = np.random.default_rng(20261121)
    checked = 0
    for _ in range(200):
        n = int(rng.integers(2, 5))
        A = rng.normal(size=(n, n))
        B = rng.normal(size=(n, 1))
        K = rng.normal(size=(1, n)) * 2
        a = delay_margin_eig(A, B @ K)
        b = delay_margin_siso(A, B, K)
        if a.reason == "unstable-at-zero-delay":
            assert b.reason == a.reason
            continue
        checked += 1
        if math.isinf(a.h):
            assert math.isinf(b.h)
        else:
            assert b.h == pytest.approx(a.h, rel=1e-6)
    assert checked >= 20
