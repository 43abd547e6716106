"""The general linear cross-check of a delay bound
(:mod:`workbench.features.linear_delay_check`) on a toy loop that names no
paper: x1' = -x1, x2' = -x2 + k x2(t - h), whose exact answers are known
(|k| < 1: stable for every delay; |k| > 1: a finite margin)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.linear_delay_check import (TEST_PROBLEM, LinearCheckSpec,
                                                   linear_delay_check, load_linear_check)
from workbench.reader import Reader

A = -np.eye(2)
B = np.array([[0.0], [1.0]])


def test_toy_loop_decays_below_the_exact_margin_and_grows_above():
    spec = LinearCheckSpec((0.0, -3.0), (0.9, 1.1), (1.0, 5.0), 30.0)
    lc = linear_delay_check(spec, A, B, (0.0, -0.5), np.array([1.0, 1.0]))
    # x2' = -x2 - 3 x2(t - h): omega* = sqrt(9 - 1), h* = acos(-1/3) / omega*
    omega = math.sqrt(8.0)
    assert lc.finite_margin.h == pytest.approx(math.acos(-1 / 3) / omega, rel=1e-6)
    (f1, h1, r1), (f2, h2, r2) = lc.ratios_finite
    assert (f1, f2) == (0.9, 1.1) and h1 < lc.finite_margin.h < h2
    assert r1 < 1 < r2
    assert len(lc.runs) == 2
    assert math.isinf(lc.margin.h)                       # |k| = 0.5 < 1: delay-independent
    assert [h for h, _ in lc.ratios] == [1.0, 5.0]
    assert all(r < 1 for _, r in lc.ratios)
    assert [round(r.order) for r in lc.halving[1:]] == [2, 2, 2]   # Heun: second order
    assert TEST_PROBLEM[1] == 0.7


def test_no_finite_margin_no_factor_runs():
    spec = LinearCheckSpec((0.0, -0.5), (0.9,), (1.0,), 10.0)
    lc = linear_delay_check(spec, A, B, (0.0, -0.5), np.array([1.0, 1.0]))
    assert lc.ratios_finite == () and lc.runs == ()


def test_load_linear_check_reads_and_rejects():
    t = Reader("toy.toml", {"linear_check": {"finite_gain": [0.0, -3.0], "factors": [0.9],
                                             "far_delays": [1.0], "periods": 20.0}})
    spec = load_linear_check(t)
    assert spec.finite_gain == (0.0, -3.0) and spec.periods == 20.0
    bad = Reader("toy.toml", {"linear_check": {"finite_gain": [0.0, -3.0], "factors": [-1.0],
                                               "far_delays": [1.0], "periods": 20.0}})
    with pytest.raises(DesignError, match="linear_check.factors"):
        load_linear_check(bad)


@pytest.mark.parametrize("k", [1.0, 1.0 - 1e-13])
def test_marginal_gain_runs_a_bounded_window(k, monkeypatch):
    """A + B K with abscissa 0 (or 1e-13) asked for a window 3 / 0: it is cut to max_steps."""
    import workbench.sim.delay as delay
    seen = []
    real = delay.simulate_linear_dde

    def spy(A_, BK, h, x0, t_end, dt):
        seen.append(t_end / dt)
        return real(A_, BK, h, x0, t_end, dt)

    monkeypatch.setattr(delay, "simulate_linear_dde", spy)
    spec = LinearCheckSpec((0.0, -0.5), (0.9,), (1.0,), 10.0)
    A0 = np.diag([-1.0, -1.0 - k])        # A + B K = diag(-1, -1 - k + k) -> abscissa ~0
    lc = linear_delay_check(spec, A0, B, (0.0, k), np.array([1.0, 1.0]), max_steps=3000)
    assert len(lc.ratios) == 1 and math.isfinite(lc.ratios[0][1])
    assert seen and max(seen) <= 3000 * (1 + 1e-9)
