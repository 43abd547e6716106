"""Exact delay margins for general A, A_d (any n, any rank of A_d): the
Chen-Gu-Nett eigenvalue method and the independent phase sweep agree."""
import math

import numpy as np
import pytest

from workbench.margins import (AGREEMENT_RTOL, delay_margin_eig, delay_margin_sweep,
                               relative_difference, spectral_abscissa)

W_OSC = math.sqrt((math.sqrt(5) - 1) / 2)    # x'' + x' + x(t-h): w^4 + w^2 = 1

ANALYTIC = [
    # (A, Ad, exact h*, source)
    ([[0.0]], [[-1.0]], math.pi / 2, "x' = -x(t-h): pi/2 (Hayes 1950)"),
    ([[-1.0]], [[-2.0]], 2 * math.pi / (3 * math.sqrt(3)), "a=-1, b=-2: 2 pi/(3 sqrt 3) (Hayes)"),
    ([[0.0, 1.0], [0.0, -1.0]], [[0.0, 0.0], [-1.0, 0.0]], math.atan2(W_OSC, W_OSC**2) / W_OSC,
     "x'' + x' + x(t-h) = 0 (rank-one A_d), analytic"),
]


@pytest.mark.parametrize("method", [delay_margin_eig, delay_margin_sweep])
@pytest.mark.parametrize("A, Ad, expected, source", ANALYTIC)
def test_analytic_margins(method, A, Ad, expected, source):
    dm = method(A, Ad)
    assert dm.reason == "crossing"
    assert dm.h == pytest.approx(expected, rel=1e-10), source


@pytest.mark.parametrize("method", [delay_margin_eig, delay_margin_sweep])
def test_classic_example(method):
    # issue 4 / Seuret & Gouaisbaut 2015 Example 1: exact margin 6.1726 (4 decimals)
    dm = method([[-2, 0], [0, -0.9]], [[-1, 0], [-1, -1]])
    assert round(dm.h, 4) == 6.1726
    assert dm.omega == pytest.approx(math.sqrt(0.19), rel=1e-9)


@pytest.mark.parametrize("method", [delay_margin_eig, delay_margin_sweep])
def test_infinite_and_zero(method):
    assert method([[-2.0]], [[-1.0]]).h == math.inf          # |b| < -a: every delay
    assert method(-np.eye(3), np.zeros((3, 3))).h == math.inf  # no delayed term
    z = method([[1.0]], [[-0.5]])                              # A + A_d = 0.5 > 0
    assert z.h == 0.0 and z.reason == "unstable-at-zero-delay"


def _random_system(rng, n, rank=None):
    A = rng.normal(size=(n, n)) / math.sqrt(n)
    Ad = rng.normal(size=(n, n)) / math.sqrt(n)
    if rank is not None:
        Ad = rng.normal(size=(n, rank)) @ rng.normal(size=(rank, n)) / math.sqrt(n)
    A -= (np.max(np.linalg.eigvals(A + Ad).real) + rng.uniform(0.05, 0.5)) * np.eye(n)
    return A, Ad


# issue 36: the two n = 20 draws (about 1 s each) run in `make test-full`
@pytest.mark.parametrize("n, rank, seed", [(2, None, 1), (3, None, 2), (4, 1, 3), (6, 2, 4),
                                           (8, None, 5), (12, None, 6), (12, 3, 7),
                                           pytest.param(20, None, 8, marks=pytest.mark.slow),
                                           pytest.param(20, 1, 9, marks=pytest.mark.slow)])
def test_methods_agree_random(n, rank, seed):
    rng = np.random.default_rng(seed)
    A, Ad = _random_system(rng, n, rank)
    a, b = delay_margin_eig(A, Ad), delay_margin_sweep(A, Ad)
    assert a.reason == b.reason
    assert relative_difference(a.h, b.h) <= AGREEMENT_RTOL
    if math.isfinite(a.h):
        assert relative_difference(a.omega, b.omega) <= AGREEMENT_RTOL


def test_agreement_on_many_small_systems():
    rng = np.random.default_rng(np.random.SeedSequence(2026))
    finite = 0
    for _ in range(60):
        A, Ad = _random_system(rng, int(rng.integers(1, 5)))
        a, b = delay_margin_eig(A, Ad), delay_margin_sweep(A, Ad)
        assert relative_difference(a.h, b.h) <= AGREEMENT_RTOL
        finite += math.isfinite(a.h)
    assert finite >= 20          # the comparison is not only inf == inf


def test_spectral_abscissa_changes_sign_at_the_margin():
    A, Ad = np.array([[-2, 0], [0, -0.9]]), np.array([[-1, 0], [-1, -1]])
    h = delay_margin_sweep(A, Ad).h
    assert spectral_abscissa(A, Ad, h * 0.99) < 0 < spectral_abscissa(A, Ad, h * 1.01)
