"""Interval certificates (issue 13 item 2): the convexity argument of
workbench.lmi.interval checked criterion by criterion, certificates re-checked
inside the interval, the lower block at h = 0, windows of a system unstable at
h = 0, and input checks (issue 21 item 5)."""
import math

import numpy as np
import pytest

from workbench.lmi import analysis as an
from workbench.lmi.core import MarginLMI, Outcome, Step, relative_margins
from workbench.lmi.interval import Form, IntervalLMI, _grow, certified_interval

CLASSIC = (np.array([[-2.0, 0.0], [0.0, -0.9]]), np.array([[-1.0, 0.0], [-1.0, -1.0]]))
# Seuret & Gouaisbaut 2015 (SCL 81) Example 2: unstable at h = 0, stable on (0.10017, 1.71785)
POCKET = (np.array([[0.0, 1.0], [-2.0, 0.1]]), np.array([[0.0, 0.0], [1.0, 0.0]]))
POCKET_WINDOW = (0.10016826845243432, 1.7178581782970908)   # stability_windows, 1e-12
CRITERIA = [("jensen", None), ("free-weighting", None), ("wirtinger", None),
            ("bessel-legendre", 2), ("bessel-legendre", 3)]


def _random_values(lmi, rng):
    """Random decision values: symmetric ones positive definite, others Gaussian."""
    out = {}
    for k, v in lmi._vars.items():
        M = rng.normal(size=v.shape)
        out[k] = M @ M.T + 0.1 * np.eye(v.shape[0]) if v.is_symmetric() else M
    return out


@pytest.mark.parametrize("method,N", CRITERIA + [("delay-independent", None)])
def test_blocks_depend_on_h_as_declared(method, N):
    """w(h) B(h) is a polynomial of degree <= 2 with a PSD h^2 coefficient ("h")
    or B affine ("1"); undeclared blocks do not depend on h."""
    lmi = an.make_criterion(method, *CLASSIC, N=N)
    rng = np.random.default_rng(np.random.SeedSequence([13, len(method), N or 0]))
    for _ in range(3):
        vals = _random_values(lmi, rng)
        hs = (0.4, 1.1, 2.3, 3.7)
        blocks = [{b.name: np.asarray(b.matrix, float) for b in lmi.evaluate_blocks(vals, h)}
                  for h in hs]
        for name in blocks[0]:
            w = lmi.h_blocks.get(name)
            M = [b[name] * (h if w == "h" else 1.0) for b, h in zip(blocks, hs)]
            scale = max(np.abs(m).max() for m in M)
            if w is None:
                assert all(np.allclose(m, M[0], rtol=0, atol=1e-12 * scale) for m in M)
                continue
            deg = 2 if w == "h" else 1
            V = np.vander(hs[:deg + 1], deg + 1, increasing=True)
            coef = np.linalg.solve(V, np.stack([m.ravel() for m in M[:deg + 1]]))
            pred = sum(c * hs[3] ** k for k, c in enumerate(coef)).reshape(M[0].shape)
            assert np.allclose(pred, M[3], rtol=0, atol=1e-9 * scale)
            if deg == 2:      # convex in h: the h^2 coefficient is F'RF >= 0
                Z = coef[2].reshape(M[0].shape)
                assert np.linalg.eigvalsh((Z + Z.T) / 2)[0] >= -1e-10 * scale


@pytest.mark.parametrize("method,N", CRITERIA)
def test_interval_certificate_holds_inside(method, N):
    """Each link's shared variables satisfy the point criterion at interior delays
    (the convexity argument, checked with numpy)."""
    lmi = an.make_criterion(method, *CLASSIC, N=N, margin=1e-8)
    res = certified_interval(lmi, h_hi=100.0, rel_tol=1e-3, max_solves=80)
    iv = res.interval
    assert res.outcome is Outcome.CERTIFIED and iv.form is Form.INTERVAL and iv.lo == 0.0
    assert 4.0 < iv.hi < 6.172581371221286           # below the exact margin
    for link in iv.links:
        vals = link.step.certificate
        for h in np.linspace(max(link.lo, 1e-3 * link.hi), link.hi, 7):
            blocks = lmi.evaluate_blocks(vals, float(h))
            assert min(relative_margins(blocks).values()) > 0, (method, link, h)


def test_lower_block_at_zero_proves_hurwitz():
    """The h -> 0 limit block is certified only when A + A_d is Hurwitz: the
    pocket system (A + A_d unstable) gets no interval from 0."""
    for method, N in CRITERIA[2:4]:
        zero = IntervalLMI(an.make_criterion(method, *POCKET, N=N), from_zero=True)
        assert all(zero.solve_at(h).outcome is not Outcome.CERTIFIED for h in (0.2, 1.0))
    res = certified_interval(an.make_criterion("bessel-legendre", *POCKET, N=3),
                             h_hi=10.0, rel_tol=1e-4)
    assert res.outcome is Outcome.CERTIFIED and res.interval.lo > 0


def test_pocket_window_certified_inside_the_exact_window():
    """SG15 Example 2: Bessel-Legendre N = 3 certifies most of the exact window and
    nothing outside it."""
    res = certified_interval(an.make_criterion("bessel-legendre", *POCKET, N=3),
                             h_hi=10.0, starts=[0.4], rel_tol=1e-5)
    lo, hi = res.bounds
    assert POCKET_WINDOW[0] < lo < 1.001 * POCKET_WINDOW[0]
    assert 0.999 * POCKET_WINDOW[1] < hi < POCKET_WINDOW[1]


def test_delay_independent_interval_is_everything():
    res = certified_interval(an.make_criterion("delay-independent", [[-2.0]], [[-1.0]]),
                             h_hi=10.0)
    assert res.bounds == (0.0, math.inf) and res.solves == 1


def _step(h, outcome):
    return Step(h, outcome, "optimal", 1.0, {}, {} if outcome is Outcome.CERTIFIED else None, 0.0)


def test_one_inconclusive_solve_does_not_end_a_search():
    """Issue 21 item 4: an inaccurate answer is retried nearer the certified end."""
    calls = []

    def decide(h):
        calls.append(h)
        if len(calls) == 1:
            return _step(h, Outcome.INCONCLUSIVE)
        return _step(h, Outcome.CERTIFIED if h <= 3.0 else Outcome.REFUTED)
    best, st = _grow(decide, 1.0, 100.0, 1e-4, [60], [])
    assert st is not None and 3.0 * (1 - 1e-4) <= best <= 3.0


def test_inconclusive_point_is_retried_on_a_twin(monkeypatch):
    lmi = an.make_criterion("wirtinger", *CLASSIC)
    real, seen = MarginLMI.solve_at, []

    def flaky(self, h):
        seen.append(self)
        if len(seen) == 1:
            return _step(h, Outcome.INCONCLUSIVE)
        return real(self, h)
    monkeypatch.setattr(MarginLMI, "solve_at", flaky)
    step = lmi.solve_at(3.0)
    assert step.outcome is Outcome.CERTIFIED and seen[1] is not lmi
    assert min(lmi.recheck(step.certificate, 3.0).values()) >= lmi.margin


@pytest.mark.parametrize("kw,match", [
    (dict(h_lo=10.0, h_hi=1.0), "expected h_lo < h_hi"),
    (dict(h_lo=math.nan), "h_lo = nan; expected a positive finite delay"),
    (dict(h_hi=-1.0), "h_hi = -1.0; expected a positive finite delay"),
    (dict(rel_tol=0.0), "rel_tol = 0.0; expected a relative tolerance in"),
    (dict(guess=math.inf), "guess = inf; expected a positive finite delay"),
    (dict(max_solves=0), "max_solves = 0; expected an integer >= 1"),
])
def test_certified_delay_rejects_bad_arguments(kw, match):
    with pytest.raises(ValueError, match=match):
        an.certified_delay(an.make_criterion("jensen", *CLASSIC), **kw)


@pytest.mark.parametrize("A,Ad,match", [
    ([[1j]], [[-1.0]], "A is complex; expected a real matrix"),
    ([[math.nan]], [[-1.0]], "A contains NaN or inf"),
    ([[-1.0, 0.0], [0.0, -1.0]], [[-1.0]], r"A \(2, 2\), A_d \(1, 1\); expected equal square"),
    (np.zeros((0, 0)), np.zeros((0, 0)), "expected a non-empty n x n matrix"),
    ([["a"]], [[-1.0]], "expected a real numeric matrix"),
])
def test_criteria_reject_bad_matrices(A, Ad, match):
    with pytest.raises(ValueError, match=match):
        an.make_criterion("jensen", A, Ad)


def test_certified_interval_rejects_bad_arguments():
    lmi = an.make_criterion("jensen", *CLASSIC)
    for kw, match in [(dict(h_hi=math.nan), "h_hi = nan"),
                      (dict(h_hi=1.0, starts=[-1.0]), "starts contains -1.0"),
                      (dict(h_hi=1.0, rel_tol=2.0), "rel_tol = 2.0")]:
        with pytest.raises(ValueError, match=match):
            certified_interval(lmi, **kw)


def test_search_range_is_relative_to_the_time_scale():
    lmi = an.make_criterion("jensen", *CLASSIC)
    fast = an.make_criterion("jensen", *(1e6 * M for M in CLASSIC))
    lo, hi = an.search_range(lmi.A, lmi.Ad, None, None)
    lo6, hi6 = an.search_range(fast.A, fast.Ad, None, None)
    assert math.isclose(lo / lo6, 1e6) and math.isclose(hi / hi6, 1e6)


def test_point_search_is_resumed_past_an_inconclusive_answer(monkeypatch):
    """Issue 21 item 4: the first trial answered inaccurately (as when the
    bracket closed near zero) no longer decides the bound."""
    lmi = an.make_criterion("wirtinger", *CLASSIC)
    real, calls = an._DelayAnalysis.solve_at, []

    def flaky(self, h):
        calls.append(h)
        if len(calls) == 1:
            return _step(h, Outcome.INCONCLUSIVE)
        return real(self, h)
    monkeypatch.setattr(an._DelayAnalysis, "solve_at", flaky)
    b = an.certified_delay(lmi, guess=5.0, rel_tol=1e-4)
    assert b.bracket.outcome is Outcome.CERTIFIED
    # without the resume the bound stops at the inconclusive 5.0; SG13 Table 1 gives 6.059
    assert 6.05 < b.h_certified < 6.172581371221286
