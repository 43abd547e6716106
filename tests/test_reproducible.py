"""Decisions with a margin against last-bit differences
(workbench/features/reproducible.py, issue 36 item 5)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from workbench.features.reproducible import (NUDGE, RTOL, count_text, decide, nudged,
                                              relative_spread, reproducible, window)


@dataclass(frozen=True)
class _Params:
    delay: float
    lag: float
    e: float
    n: int
    name: str


def test_nudged_scales_every_nonzero_float_and_keeps_the_rest():
    p = _Params(0.3, 0.65, 0.0, 7, "x")
    q = nudged(p, NUDGE, keep=("delay",))
    assert q.lag == 0.65 * (1 + NUDGE) and q.delay == 0.3
    assert q.e == 0.0 and q.n == 7 and q.name == "x"
    assert nudged(p, -NUDGE).delay < 0.3


def test_relative_spread_per_run_over_metrics():
    base = np.array([[1.0, 100.0], [0.08, 530.0], [2.0, 3.0]])
    again = base.copy()
    again[0, 1] *= 1 + 1e-13          # rounding-level: reproducible
    again[1, 0] = 0.0803               # a relay run: 0.08 -> 0.0803
    again[2, 1] = math.nan             # stops in one repetition only
    rel = relative_spread([base, again])
    assert rel[0] < 1e-12
    assert math.isclose(rel[1], 0.0003 / 0.0803)
    assert rel[2] == math.inf
    assert list(reproducible([base, again])) == [True, False, False]


def test_relative_spread_equal_and_all_nonfinite_runs_are_reproducible():
    x = np.array([[0.0, math.nan], [5.0, math.inf]])
    assert list(relative_spread([x, x.copy()])) == [0.0, 0.0]


def test_the_nudge_is_far_above_last_bits_and_the_band_far_above_a_linear_response():
    assert 1e-12 <= NUDGE <= 1e-6 and RTOL / NUDGE >= 1e5


def test_decide_needs_the_whole_band_beyond_the_margin():
    lo = np.array([0.1, 0.29, 0.31, 0.35, math.nan])
    hi = np.array([0.2, 0.31, 0.32, 0.40, math.nan])
    assert list(decide(lo, hi, 0.3, 0.0)) == [-1, 0, 1, 1, 0]
    assert list(decide(lo, hi, 0.3, 0.02)) == [-1, 0, 0, 1, 0]


def test_count_text_prints_the_undecided_range():
    assert count_text(53, 0) == "53"
    assert count_text(53, 1) == "53-54"


def test_window_end_on_a_sample_time_survives_a_last_bit_change_of_the_step():
    for dt in (0.01, math.nextafter(0.01, 1.0), math.nextafter(0.01, 0.0)):
        t = np.arange(4001) * dt
        assert window(t, -np.inf, 30.0).sum() == 3001
        assert window(t, 5.0, 35.0).sum() == 3001
