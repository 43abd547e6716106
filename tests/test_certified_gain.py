"""Issue 31 items 3 and 5: the returned gain is the certified gain; diagnosis before solving.

Item 3: every synthesis path reports the bound of the K it returns (rounded to
its printed digits, then certified with K fixed), so the certified delay is
below the exact delay margin of *that* K (workbench.margins, no LMI).
Item 5: an uncontrollable mode with Re >= -alpha is INFEASIBLE before any LMI
solve, with the mode named; every inconclusive answer carries its reason.
"""
from __future__ import annotations

import math

import control
import cvxpy as cp
import numpy as np
import pytest

import workbench
from workbench.lmi.core import Bracket, Outcome, Step
from workbench.lmi.diagnosis import inconclusive_reason, uncontrollable_mode
from workbench.lmi.gain import DEFAULT_DIGITS, round_significant
from workbench.margins import exact_margin, stability_windows


def _sound(A, B, res):
    """The certified delay lies in an exact stability window of x' = A x + B K x(t - h)."""
    Ad = B @ res.K
    wins = stability_windows(A, Ad, 2 * res.h_certified + 1)
    assert any(a < res.h_certified < b for a, b in wins), (res.h_certified, wins)
    return exact_margin(A, Ad).h


# Issue 31's two counterexamples (Wirtinger synthesis through the API): before
# the fix the API returned 1.98599 and 0.332725, the bounds of the unrounded
# solver gains, above the exact margins 1.98361 and 0.330981 of the returned K.
@pytest.mark.parametrize("a, b", [(0.5, 2.0), (3.0, 1.0)])
def test_api_bound_is_the_returned_gains(a, b):
    res = workbench.delay_bound(control.ss([[a]], [[b]], [[1.0]], [[0]]), method="wirtinger",
                                h_max=10)
    assert res.status == "certified" and res.recheck_passed
    A, B = np.array([[a]]), np.array([[b]])
    h_star = _sound(A, B, res)
    assert 0 < res.h_certified < h_star
    assert np.array_equal(res.K, round_significant(res.K, DEFAULT_DIGITS))   # printed digits
    assert "K fixed" in res.certifies and res.reason == ""
    assert res.to_dict()["certifies"] == res.certifies


def _random_systems(count: int, seed: int = 3101):
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    out = []
    while len(out) < count:
        n = int(rng.integers(1, 3))
        A = np.round(rng.normal(size=(n, n)), 2)
        B = np.round(rng.normal(size=(n, 1)), 2)
        if np.linalg.matrix_rank(control.ctrb(A, B)) == n:
            out.append((A, B))
    return out


# a derandomised batch of small random plants: the certified delay of the
# returned K must hold for that K by the exact spectrum (every method)
@pytest.mark.parametrize("k", range(6))
def test_api_batch_sound_against_exact_margin(k):
    A, B = _random_systems(6)[k]
    method = ("wirtinger", "free-weighting-003", "bessel-legendre")[k % 3]
    res = workbench.delay_bound(A, B, method=method, N=2, h_max=10, rel_tol=1e-3)
    assert res.status in ("certified", "inconclusive"), res.reason
    if res.status == "certified":
        assert res.h_certified > 0 and res.K is not None
        h_star = _sound(A, B, res)
        if method == "free-weighting-003":       # an interval [0, h]: below h*
            assert res.h_certified < h_star
    else:
        assert res.reason


def test_uncontrollable_unstable_mode_is_infeasible_before_any_solve(monkeypatch):
    def no_solve(*a, **k):
        raise AssertionError("an LMI was solved")
    monkeypatch.setattr(cp.Problem, "solve", no_solve)
    A, B = np.diag([1.0, -1.0]), np.array([[0.0], [1.0]])     # x1' = x1, x2' = -x2 + u
    res = workbench.delay_bound(A, B, method="wirtinger", h_max=10)
    assert res.status == "infeasible" and res.K is None and res.h_certified == 0
    assert "eigenvalue 1 of A is uncontrollable from u" in res.reason
    from workbench.lmi.robust import synthesize_robust
    r = synthesize_robust([(A, B)], h_hi=2.0, alpha=0.5)
    assert r.bracket.outcome is Outcome.INFEASIBLE and r.K is None
    assert r.reason.endswith("no gain can give decay 0.5")
    from workbench.lmi.tight_synthesis import synthesize_tight
    from workbench.lmi.varying_synthesis import synthesize_varying
    from workbench.synthesis import synthesize_delay_bound
    t = synthesize_tight(A, B, h_max=2.0)
    assert t.bracket.outcome is Outcome.INFEASIBLE and t.K is None and "eigenvalue 1" in t.reason
    v = synthesize_varying(A, B, h_max=2.0, mu=0.5)
    assert v.bracket.outcome is Outcome.INFEASIBLE and v.K is None
    (row,) = synthesize_delay_bound(A, B, (0.1,))
    assert row.status is Outcome.INFEASIBLE and row.K is None and "eigenvalue 1" in row.reason


@pytest.mark.parametrize("A, B, alpha, infeasible", [
    (np.diag([-0.5, -3.0]), np.array([[0.0], [1.0]]), 0.5, True),    # Re = -alpha exactly
    (np.diag([-0.5, -3.0]), np.array([[0.0], [1.0]]), 0.25, False),  # decays faster than alpha
    (np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]), 2.0, False),  # controllable
    (np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -3.0]]),
     np.array([[0.0], [0.0], [1.0]]), 0.0, True),                    # +-1j, uncontrollable
    (np.diag([1.0, 2.0]), np.array([[1.0], [1.0]]), 0.0, False),     # distinct: controllable
    (np.diag([2.0, 2.0]), np.array([[1.0], [1.0]]), 0.0, True),      # repeated: one mode is not
])
def test_pbh_decides_exactly(A, B, alpha, infeasible):
    d = uncontrollable_mode([(A, B)], alpha)
    assert (d is not None) == infeasible
    if d is not None:
        assert "is uncontrollable from u" in d.reason


def test_pbh_names_the_vertex():
    good = (np.diag([1.0, -1.0]), np.array([[1.0], [1.0]]))
    bad = (np.diag([1.0, -1.0]), np.array([[0.0], [1.0]]))
    d = uncontrollable_mode([good, bad])
    assert d.vertex == 1 and "at vertex 2" in d.reason


def _step(h, outcome, status="optimal", recheck=None):
    return Step(h, outcome, status, None, recheck or {}, None, 0.0)


def test_every_inconclusive_has_a_reason():
    br = Bracket(0.0, math.inf, Outcome.INCONCLUSIVE, None,
                 (_step(1.0, Outcome.INCONCLUSIVE, recheck={"phi": -3e-9, "theta": 1e-3}),))
    assert "block 'phi' failed the numpy re-check" in inconclusive_reason(br, margin=1e-7,
                                                                          h_cap=10)
    br = Bracket(0.0, math.inf, Outcome.INCONCLUSIVE, None,
                 (_step(1.0, Outcome.INCONCLUSIVE, status="optimal_inaccurate"),))
    assert "solver status 'optimal_inaccurate'" in inconclusive_reason(br, margin=1e-7,
                                                                       h_cap=10)
    ok = Bracket(1.0, 1.1, Outcome.CERTIFIED, None, (_step(1.0, Outcome.CERTIFIED),))
    assert inconclusive_reason(ok, margin=1e-7, h_cap=10) == ""
    assert inconclusive_reason(ok, margin=1e-7, h_cap=2.0, h_required=3.0).startswith(
        "search cap below the required delay")


def test_solver_panic_is_inconclusive(monkeypatch):
    from workbench.lmi.analysis import WirtingerLMI

    class PanicException(BaseException):     # what pyo3 raises for a Rust panic
        pass

    def panic(*a, **k):
        raise PanicException("index out of bounds")
    lmi = WirtingerLMI(np.array([[-2.0]]), np.array([[-1.0]]))
    monkeypatch.setattr(cp.Problem, "solve", panic)
    step = lmi.solve_at(0.5)
    assert step.outcome is Outcome.INCONCLUSIVE and "panic" in step.solver_status

    def interrupt(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(cp.Problem, "solve", interrupt)
    with pytest.raises(KeyboardInterrupt):
        lmi.solve_at(0.5)


def test_claim_on_a_synthesis_without_gain_is_inconclusive():
    from types import SimpleNamespace

    from workbench.claims import Claim, Verdict, check_claim
    from workbench.kinds.delay_feedback.run import SynthesisOutcome, quantities
    s = SynthesisOutcome("robust-descriptor", 0.8, math.inf, None, None, "inconclusive", 0.1,
                         None, True, False)
    res = SimpleNamespace(synthesis=s, op=SimpleNamespace(residual=0.0, x=np.zeros(1),
                                                          u=np.zeros(1)),
                          A=np.array([[-1.0]]), B=np.array([[1.0]]), exact=None,
                          range_stable=None, names=("x", "u"), vertex_checks=(), scenarios=(),
                          basin=None, implementation=None, delay=SimpleNamespace(h_max=0.5),
                          spec=SimpleNamespace(
                              plant=SimpleNamespace(states=(SimpleNamespace(name="x", unit="m"),),
                                                    inputs=(SimpleNamespace(name="u", unit="N"),)),
                              synthesis=SimpleNamespace(eps=()), vertices=(), scenarios=(),
                              requirements=None, basin=None, implementation=None,
                                  montecarlo=None, gain_tables=None))
    q = quantities(res)
    claim = Claim("h", "h", "synthesis.h_certified", ">=", 0.5, 0.0, None, "round", "", False,
                  "pass", "")
    assert check_claim(claim, q["synthesis.h_certified"]).verdict is Verdict.INCONCLUSIVE


def test_design_reason_names_a_search_cap_below_the_required_delay():
    from workbench.kinds.delay_feedback.run import SynthesisOutcome
    s = SynthesisOutcome("robust-descriptor", 0.0, math.inf, None, None, "inconclusive", 0.1,
                         None, True, False, required=3.0, h_cap=2.0)
    assert s.reason == "search cap below the required delay: h_max = 2 s < 3 s"
    s = SynthesisOutcome("wirtinger", 0.0, math.inf, None, None, "inconclusive", 0.1, None,
                         False, False, required=0.5, h_cap=2.0)
    assert s.reason == "no reason recorded"      # (no result object attached here)


def test_shared_fixed_gain_lmi_decides_like_a_fresh_one():
    """One fixed-gain LMI with K and eps as parameters (set_gain / set_eps,
    issue 36) gives the same steps as a new LMI built for that K and eps."""
    from workbench.lmi.freeweighting003 import FreeWeighting003FixedK
    A = np.array([[0.0, 1.0], [-2.0, -0.5]])
    B = np.array([[0.0], [1.0]])
    K1, K2 = np.array([[-0.3, -0.8]]), np.array([[-0.5, -0.6]])
    shared = FreeWeighting003FixedK(A, B, 0.3, K=K1, shared=True)
    shared.set_eps(0.5)
    shared.set_gain(K2)
    fresh = FreeWeighting003FixedK(A, B, 0.5, K=K2)
    for h in (0.05, 0.5, 5.0):
        a, b = shared.solve_at(h), fresh.solve_at(h)
        assert a.outcome is b.outcome
        assert (a.t_opt is None) == (b.t_opt is None)
        if a.t_opt is not None:
            assert a.t_opt == pytest.approx(b.t_opt, rel=1e-6, abs=1e-9)
    with pytest.raises(ValueError):
        shared.set_gain(np.zeros((2, 2)))
    with pytest.raises(ValueError):
        fresh.set_gain(K1)
