"""The exact methods' fast path (issue 32, item 8) against the existing path on small n.

The phase sweep is computed once per (A, A_d, grid) and shared by the margin and
the windows, and a crossing's multiplicity reuses the eigenvalues of its last
Newton step: both must give the crossings of the uncached sweep with the
multiplicities recomputed, bit for bit, and the margin of Chen-Gu-Nett.
"""
import sys
from pathlib import Path

import numpy as np
import pytest

from workbench.margins import (crossings, delay_margin_eig, delay_margin_sweep, exact_margin,
                               stability_windows)

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from margins_scale import system  # noqa: E402


@pytest.mark.parametrize("n", [3, 6, 9, 12])
def test_fast_sweep_is_the_existing_sweep(n, monkeypatch):
    A, Ad = system(n)
    fast = crossings.phase_crossings(A, Ad)
    assert crossings.phase_crossings(A, Ad) is fast          # shared, not recomputed
    slow_mult = crossings._multiplicity
    monkeypatch.setattr(crossings, "_multiplicity",
                        lambda A, Ad, th, lam, R, ev=None: slow_mult(A, Ad, th, lam, R))
    slow = crossings._sweep(np.asarray(A, float), np.asarray(Ad, float), None)
    assert fast == slow
    kr = delay_margin_eig(A, Ad)
    sw = delay_margin_sweep(A, Ad)
    assert sw.h == pytest.approx(kr.h, rel=1e-10) and sw.reason == kr.reason


def test_margin_and_windows_share_one_sweep(monkeypatch):
    A, Ad = system(10)
    A = A.copy()                              # a fresh array with the same bytes
    calls = []
    real = crossings._sweep
    monkeypatch.setattr(crossings, "_sweep", lambda *a: calls.append(1) or real(*a))
    crossings._SWEEPS.clear()
    ex = exact_margin(A, Ad, cross_check="never")
    win = stability_windows(A, Ad, 4 * ex.h)
    assert len(calls) == 1 and win[0] == (0.0, ex.h)


def test_the_cache_is_bounded():
    crossings._SWEEPS.clear()
    for k in range(crossings.SWEEP_CACHE + 3):
        crossings.phase_crossings(np.array([[-1.0 - k]]), np.array([[0.5]]))
    assert len(crossings._SWEEPS) == crossings.SWEEP_CACHE
