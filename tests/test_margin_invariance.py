"""Invariance of the exact delay margin and the stability windows (issue 21, item 2).

For x' = A x + A_d x(t - h):

* time scaling (A, A_d) -> (c A, c A_d) is the same system in another time unit:
  h* -> h* / c and every window -> window / c, for c in [1e-6, 1e6];
* a similarity T A T^-1, T A_d T^-1 and a state permutation change nothing.

Random systems come from three families, so the suite always covers stability
windows and delay-independent systems:

``generic``
    Gaussian A, A_d with A shifted so that A + A_d is Hurwitz (n = 2..5).
``windowed``
    x'' + a x = -k x'(t - h) with small k / sqrt(a) (several windows, see
    tests/test_margins_exact.py) driving 0-2 stable states, in a random
    orthogonal basis.
``delay-independent``
    A = -alpha I + S (S skew) and ||A_d||_2 < alpha, so Re lambda(A + A_d z) <=
    -alpha + ||A_d||_2 < 0 on |z| = 1: no crossing; in a random basis.

Hypothesis is derandomized (fixed examples, no database): the suite checks
FAMILIES x PROPERTIES x EXAMPLES = 3 x 3 x 20 = 180 random systems per run, each
against a transformed copy (and the Kronecker method on the scaled copy).
"""
import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from workbench.margins import (AGREEMENT_RTOL, delay_margin_eig, delay_margin_sweep,
                               relative_difference, scale, stability_windows)

FAMILIES = ("generic", "windowed", "delay-independent")
EXAMPLES = 20
RUN = settings(derandomize=True, database=None, max_examples=EXAMPLES, deadline=None,
               suppress_health_check=[HealthCheck.too_slow])
SEEDS = st.integers(min_value=0, max_value=2**32 - 1)


def _orthogonal(rng, n):
    q, r = np.linalg.qr(rng.normal(size=(n, n)))
    return q * np.sign(np.diag(r))


def make_system(family: str, seed: int):
    """One random system of the family (deterministic in ``seed``)."""
    rng = np.random.default_rng(np.random.SeedSequence([21, FAMILIES.index(family), seed]))
    if family == "generic":
        n = int(rng.integers(2, 6))
        A = rng.normal(size=(n, n)) / math.sqrt(n)
        Ad = rng.normal(size=(n, n)) / math.sqrt(n)
        A -= (np.max(np.linalg.eigvals(A + Ad).real) + rng.uniform(0.05, 0.5)) * np.eye(n)
        return A, Ad
    if family == "windowed":
        a, k, m = rng.uniform(0.5, 4.0), rng.uniform(0.05, 0.3), int(rng.integers(0, 3))
        n = 2 + m
        A, Ad = np.zeros((n, n)), np.zeros((n, n))
        A[:2, :2] = [[0.0, 1.0], [-a, 0.0]]
        Ad[1, 1] = -k
        if m:
            A[2:, 2:] = -np.diag(rng.uniform(0.5, 2.0, m))
            A[2:, :2] = rng.normal(size=(m, 2))
            Ad[2:, :2] = rng.normal(size=(m, 2))
        Q = _orthogonal(rng, n)
        return Q @ A @ Q.T, Q @ Ad @ Q.T
    n = int(rng.integers(2, 6))
    alpha = rng.uniform(0.5, 2.0)
    S = rng.normal(size=(n, n))
    A = -alpha * np.eye(n) + (S - S.T) / 2
    Ad = rng.normal(size=(n, n))
    Ad *= rng.uniform(0.2, 0.9) * alpha / np.linalg.norm(Ad, 2)
    Q = _orthogonal(rng, n)
    return Q @ A @ Q.T, Q @ Ad @ Q.T


def horizon(A, Ad) -> float:
    """h_max = 80 / R (s): scale-covariant, beyond the second window of the
    windowed family."""
    return 80.0 / scale(A, Ad)


def analyse(A, Ad, h_max):
    return delay_margin_sweep(A, Ad), stability_windows(A, Ad, h_max)


def check_family(family, dm, windows):
    if family == "delay-independent":
        assert dm.h == math.inf and windows == ((0.0, math.inf),)
    if family == "windowed":
        assert len(windows) >= 2


def assert_same(dm1, w1, dm2, w2, h_max, c=1.0):
    """dm2, w2 (of the transformed system, delays / c) equal dm1, w1."""
    assert dm1.reason == dm2.reason
    assert relative_difference(dm1.h, dm2.h * c) <= AGREEMENT_RTOL
    near = 1e-6 * h_max           # a window starting at the horizon may fall either side
    w1 = [w for w in w1 if w[0] < h_max - near]
    w2 = [(a * c, b * c) for a, b in w2 if a * c < h_max - near]
    assert len(w1) == len(w2), (w1, w2)
    for (a1, b1), (a2, b2) in zip(w1, w2):
        assert relative_difference(a1, a2) <= AGREEMENT_RTOL
        assert relative_difference(b1, b2) <= AGREEMENT_RTOL


@pytest.mark.parametrize("family", FAMILIES)
@RUN
@given(seed=SEEDS, log_c=st.floats(min_value=-6.0, max_value=6.0))
def test_time_scaling(family, seed, log_c):
    A, Ad = make_system(family, seed)
    c = 10.0 ** log_c
    h_max = horizon(A, Ad)
    dm, windows = analyse(A, Ad, h_max)
    check_family(family, dm, windows)
    dm_c, windows_c = analyse(c * A, c * Ad, h_max / c)
    assert_same(dm, windows, dm_c, windows_c, h_max, c)
    kron = delay_margin_eig(c * A, c * Ad)           # the other method, other units
    assert relative_difference(kron.h * c, dm.h) <= AGREEMENT_RTOL


@pytest.mark.parametrize("family", FAMILIES)
@RUN
@given(seed=SEEDS, t_seed=SEEDS)
def test_similarity(family, seed, t_seed):
    A, Ad = make_system(family, seed)
    n = A.shape[0]
    rng = np.random.default_rng(t_seed)
    # T = U diag(e^u) V with u in [-1, 1]: condition number <= e^2
    T = _orthogonal(rng, n) @ np.diag(np.exp(rng.uniform(-1, 1, n))) @ _orthogonal(rng, n)
    Ti = np.linalg.inv(T)
    h_max = horizon(A, Ad)
    dm, windows = analyse(A, Ad, h_max)
    check_family(family, dm, windows)
    assert_same(dm, windows, *analyse(T @ A @ Ti, T @ Ad @ Ti, h_max), h_max)


@pytest.mark.parametrize("family", FAMILIES)
@RUN
@given(seed=SEEDS, p_seed=SEEDS)
def test_permutation(family, seed, p_seed):
    A, Ad = make_system(family, seed)
    p = np.random.default_rng(p_seed).permutation(A.shape[0])
    h_max = horizon(A, Ad)
    dm, windows = analyse(A, Ad, h_max)
    check_family(family, dm, windows)
    assert_same(dm, windows, *analyse(A[np.ix_(p, p)], Ad[np.ix_(p, p)], h_max), h_max)
