"""Soundness suite with stability windows (issue 13 item 5).

Invariant: no certified interval contains a delay at which the exact stability
set, or the spectral abscissa on a grid inside the interval, says unstable; a
certified point lies in an exact stable window; a time-varying certificate
[h1, h2] lies inside the exact constant-delay window that contains it.

Systems (every one has a window that does not start at 0, or two windows):

* ``pocket``: x'' - 0.1 x' + 2 x = x(t - h), unstable at h = 0, stable on
  (0.10017, 1.71785) — Seuret & Gouaisbaut, SCL 81 (2015), Example 2;
* ``damping-unstable``: x'' + x = 0.5 x'(t - h), unstable at h = 0, one window;
  ``damping-two``: x'' + x = -0.5 x'(t - h), two windows — delayed damping,
  the stability switches of Cooke & Grossman, J. Math. Anal. Appl. 86 (1982);
* ``triangular-3``: damping-two driving y' = -y + x(t - h) (two windows, 3 x 3);
* ``coupled-3``: a coupled 3 x 3 system with two windows (seeded search, see
  tests/test_margins_exact.py);
* ``random-k``: random 2 x 2 / 3 x 3 systems with one-decimal entries, drawn
  with a fixed seed and kept (rejection) when they have such windows.

Cost: Wirtinger and Bessel-Legendre N = 2 on the 2 x 2 systems, N = 2 on the
3 x 3 ones, at a bracket width of 1e-2 (soundness does not need tight
brackets): about 40 s on one shared core.
"""
import math

import numpy as np
import pytest

from workbench.benchmark_windows import in_window, interval_inside, middle
from workbench.lmi.analysis import certified_delay, make_criterion
from workbench.lmi.interval import certified_interval
from workbench.lmi.varying import certified_varying_delay
from workbench.margins import spectral_abscissa, stability_windows

H_MAX = 20.0
RANDOM_SYSTEMS = 3


def _damping(k):
    return [[0.0, 1.0], [-1.0, 0.0]], [[0.0, 0.0], [0.0, -k]]


def _triangular():
    A, Ad = np.zeros((3, 3)), np.zeros((3, 3))
    A[:2, :2], Ad[:2, :2] = _damping(0.5)
    A[2, 2], Ad[2, 0] = -1.0, 1.0
    return A, Ad


def random_windowed(count: int, seed: int = 1313):
    """The first ``count`` random systems (seeded) that are unstable at h = 0 with
    a window, or have two or more windows, within [0, H_MAX]."""
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    out = []
    for draw in range(20_000):
        n = 2 + draw % 2
        A = np.round(rng.uniform(-2, 2, (n, n)), 1)
        Ad = np.round(rng.uniform(-2, 2, (n, n)), 1)
        w = stability_windows(A, Ad, H_MAX)
        if (w and w[0][0] > 0) or len(w) >= 2:
            out.append((f"random-{draw}", A, Ad))
            if len(out) == count:
                return out
    raise AssertionError("rejection sampling found too few windowed systems")


#: The draws :func:`random_windowed` picks (``test_the_suite_has_windows`` checks
#: it still does): replaying the generator to them is cheap, the rejection test's
#: stability windows of every draw cost 1.5 s at each worker's collection.
RANDOM_DRAWS = (30, 53, 306)


def random_draws(draws, seed: int = 1313):
    """The systems of :func:`random_windowed`'s generator at these draw indices."""
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    out = []
    for draw in range(max(draws) + 1):
        n = 2 + draw % 2
        A = np.round(rng.uniform(-2, 2, (n, n)), 1)
        Ad = np.round(rng.uniform(-2, 2, (n, n)), 1)
        if draw in draws:
            out.append((f"random-{draw}", A, Ad))
    return out


SYSTEMS = [("pocket", [[0.0, 1.0], [-2.0, 0.1]], [[0.0, 0.0], [1.0, 0.0]]),
           ("damping-unstable", *_damping(-0.5)),
           ("damping-two", *_damping(0.5)),
           ("triangular-3", *_triangular()),
           ("coupled-3", [[-0.6, -1.4, -0.1], [1.0, -0.3, 0.3], [-0.4, -0.6, -0.9]],
            [[-0.7, 0.5, 0.0], [-0.2, -0.3, -0.1], [0.1, 0.2, -0.7]])]
SYSTEMS += random_draws(RANDOM_DRAWS)


def test_the_suite_has_windows():
    sampled = random_windowed(RANDOM_SYSTEMS)
    assert [name for name, _, _ in sampled] == [name for name, _, _ in SYSTEMS[5:]]
    for (_, A, Ad), (_, A2, Ad2) in zip(sampled, SYSTEMS[5:]):
        assert np.array_equal(A, A2) and np.array_equal(Ad, Ad2)
    shapes = {name: stability_windows(A, Ad, H_MAX) for name, A, Ad in SYSTEMS}
    assert sum(1 for w in shapes.values() if w and w[0][0] > 0) >= 3      # unstable at 0
    assert sum(1 for w in shapes.values() if len(w) >= 2) >= 3           # two windows
    assert len(SYSTEMS) == 5 + RANDOM_SYSTEMS


# issue 36: the named systems run in `make test`, the random draws (the random
# soundness suite, 1-3 s each) in `make test-full`
@pytest.mark.parametrize("name,A,Ad", [s if not s[0].startswith("random-") else
                                       pytest.param(*s, marks=pytest.mark.slow)
                                       for s in SYSTEMS], ids=[s[0] for s in SYSTEMS])
def test_no_certificate_outside_the_exact_windows(name, A, Ad):
    A, Ad = np.array(A, float), np.array(Ad, float)
    windows = stability_windows(A, Ad, H_MAX)
    starts = [middle(a, b, H_MAX) for a, b in windows if a > 0]
    rng = np.random.default_rng(np.random.SeedSequence([13, len(name)]))
    certified = 0
    criteria = (("wirtinger", None), ("bessel-legendre", 2)) if len(A) == 2 else \
        (("bessel-legendre", 2),)
    for method, N in criteria:
        lmi = make_criterion(method, A, Ad, N=N)
        res = certified_interval(lmi, h_hi=H_MAX, starts=starts, rel_tol=1e-2,
                                 max_solves=50, scan=0)
        for iv in res.intervals:
            certified += 1
            assert interval_inside(iv.lo, iv.hi, windows), (method, iv.lo, iv.hi, windows)
            grid = iv.lo + (min(iv.hi, H_MAX) - iv.lo) * np.r_[0.0, rng.uniform(0, 1, 6), 1.0]
            for h in grid:
                assert spectral_abscissa(A, Ad, float(h)) < 0, (method, h)
        guess = starts[0] if windows and windows[0][0] > 0 else None
        b = certified_delay(lmi, h_hi=H_MAX, rel_tol=1e-2, guess=guess, max_solves=20)
        if 0 < b.h_certified < math.inf:
            assert in_window(b.h_certified, windows), (method, b.h_certified, windows)
            assert spectral_abscissa(A, Ad, b.h_certified) < 0
    if name in ("pocket", "damping-two", "triangular-3"):
        assert certified >= 1          # the suite does certify something on these


@pytest.mark.parametrize("name,h1,mu", [("pocket", 0.3, 0.1), ("damping-two", 0.0, None)])
def test_time_varying_certificate_within_the_constant_window(name, h1, mu):
    """A certified (h2, mu) never exceeds the constant-delay exact window: constant
    delays are among the delay functions the certificate covers."""
    _, A, Ad = next(s for s in SYSTEMS if s[0] == name)
    windows = stability_windows(A, Ad, H_MAX)
    b = certified_varying_delay(A, Ad, h1=h1, mu=mu, h_hi=H_MAX, rel_tol=1e-2,
                                guess=0.8, max_solves=20)
    assert b.interval is not None
    assert interval_inside(*b.interval, windows), (b.interval, windows)
