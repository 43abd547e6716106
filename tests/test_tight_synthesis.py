"""Wirtinger-based delay-bound synthesis (workbench/lmi/tight_synthesis.py):
certificate re-check and tampering, soundness against exact margins on
textbook examples, and the comparison with paper 003's free-weighting bound."""
import math

import numpy as np
import pytest

from workbench.crosscheck import check_tight
from workbench.lmi.analysis import WirtingerLMI, certified_delay
from workbench.lmi.core import Outcome
from workbench.lmi.core import bisect_delay
from workbench.lmi.robust import maximise_log_scalar
from workbench.lmi.tight_synthesis import (WirtingerSynthesis, WirtingerSynthesisFixedK,
                                           recheck_tight, synthesize_tight)
from workbench.margins import delay_margin_eig
from workbench.plants.adhesion import NumericAdhesion
from workbench.symbolic.linearise import linearise_cruise
from workbench.synthesis import SynthesisSettings, synthesize_delay_bound

DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)   # 003 Tables 1-2

# x' = x + u(t - h): a real unstable pole a = 1 can be stabilised by static
# delayed feedback only for h < 1/a = 1 s (x' = a x + b x(t-h), a > 0, is
# stable iff a h < 1 and -b sin(w h) ... : Hale & Verduyn Lunel 1993, ch. 5,
# the scalar stability chart). Exact margins are computed, never typed.
SCALAR = (np.array([[1.0]]), np.array([[1.0]]))
# Fridman & Shaked 2002 (IEEE TAC 47(11)), Example: A = [[0, 0], [0, 1]], B = [1; 1].
FS02 = (np.array([[0.0, 0.0], [0.0, 1.0]]), np.array([[1.0], [1.0]]))
# tolerance of the soundness comparison: bisection brackets and eigenvalue
# crossings are computed to ~1e-4 relative.
SOUND_TOL = 1e-3


@pytest.fixture(scope="module")
def scalar():
    return synthesize_tight(*SCALAR, h_max=10.0)


@pytest.fixture(scope="module")
def lin():
    p = NumericAdhesion.from_dict(DRY)
    return linearise_cruise(p, 70.0, p.cruise_lambda(70.0))


def test_certificate_recheck_passes_and_tampered_fails(scalar):
    A, B = SCALAR
    r = scalar
    assert r.bracket.outcome is Outcome.CERTIFIED
    ok = recheck_tight(A, B, r)
    assert min(ok.values()) >= 1e-7
    cert = dict(r.bracket.certificate.certificate)
    assert min(recheck_tight(A, B, r, {**cert, "V": 3.0 * cert["V"]}).values()) < 0
    assert min(recheck_tight(A, B, r, {**cert, "Y": -cert["Y"]}).values()) < 0
    assert min(recheck_tight(A, B, r, {**cert, "R": 0.0 * cert["R"]}).values()) < 0
    # the same certificate does not prove a much larger delay
    lmi = WirtingerSynthesis(A, B, r.eps)
    assert min(lmi.recheck(cert, 3 * r.h_certified).values()) < 0


def test_blocks_match_the_wirtinger_analysis_on_the_classic_example():
    """With K fixed (B = I, K = A_d) the descriptor LMI is the Wirtinger analysis
    with P2 restricted; at its best eps it must come within 1 % of
    :class:`WirtingerLMI` (SG13 Table 1: 6.059 s for Theorem 5) and never
    exceed it nor the exact margin (6.1726 s, issue 4)."""
    A, Ad = np.array([[-2.0, 0.0], [0.0, -0.9]]), np.array([[-1.0, 0.0], [-1.0, -1.0]])
    exact = delay_margin_eig(A, Ad).h
    wirt = certified_delay(WirtingerLMI(A, Ad), rel_tol=1e-4).h_certified
    lmi = WirtingerSynthesisFixedK(A, np.eye(2), 1.0, K=Ad)
    best = 0.0
    for eps in (0.3, 1.0, 3.0):
        lmi.set_eps(eps)
        best = max(best, bisect_delay(lmi.solve_at, h_lo=1e-3, h_hi=100.0,
                                      rel_tol=1e-4).h_certified)
    assert wirt == pytest.approx(6.059, abs=0.005)
    assert 0.99 * wirt <= best <= wirt * (1 + SOUND_TOL) <= exact


def test_both_sides_of_the_bracket(scalar):
    r = scalar
    lmi = WirtingerSynthesis(*SCALAR, r.eps)
    assert lmi.solve_at(r.h_certified).outcome is Outcome.CERTIFIED
    assert lmi.solve_at(r.bracket.h_refuted * 1.01).outcome is Outcome.REFUTED


@pytest.mark.parametrize("system", [SCALAR, FS02], ids=["scalar-a1", "fridman-shaked-02"])
def test_sound_on_textbook_examples(system, scalar):
    r = scalar if system is SCALAR else synthesize_tight(*system, h_max=10.0)
    A, B = system
    assert r.K is not None and not r.at_cap
    exact = delay_margin_eig(A, B @ r.K).h
    assert math.isfinite(exact)
    c = check_tight(A, B, r.K, h_hi=r.h_max)
    assert c.check.exact.h == pytest.approx(exact)
    assert c.exact_siso.h == pytest.approx(exact, rel=1e-6)      # two independent methods
    # synthesis LMI sound: the gain of the bisection's own certificate ...
    Tinv = np.diag(1.0 / np.diag(r.T))
    lmi = WirtingerSynthesis(Tinv @ A @ r.T, Tinv @ B, r.eps)
    K_bisection = lmi.gain(r.bracket.certificate.certificate) @ Tinv
    assert r.h_certified <= delay_margin_eig(A, B @ K_bisection).h * (1 + SOUND_TOL)
    # ... and the canonical gain, on its own and by the BL analysis
    assert r.gain.h_certified <= exact * (1 + SOUND_TOL)
    assert c.check.h_certified <= exact * (1 + SOUND_TOL)
    # The BL analysis (N = 2) of the same K is the tighter criterion in exact
    # arithmetic than the descriptor Wirtinger LMI with that K fixed; with
    # relative margins and the canonical gain this holds on every kernel.
    assert r.gain.h_certified >= r.gain.h_design
    assert c.check.h_certified >= r.gain.h_certified * (1 - SOUND_TOL)
    assert r.h_certified < 1.0                                     # 1/a: no static gain beyond
    assert r.h_certified > 0.9                                     # but close to it


def test_tighter_than_paper_003_criterion_on_textbook_example(scalar):
    rows = synthesize_delay_bound(*SCALAR, (0.1, 0.3, 1.0, 3.0),
                                  SynthesisSettings(h_max=10.0, rel_tol=1e-3))
    best_fw = max(r.h_certified for r in rows)
    assert best_fw > 0
    assert scalar.h_certified > 2 * best_fw       # ~0.97 s vs ~0.29 s


def test_tight_bound_exceeds_free_weighting_on_antiskid(lin):
    (fw,) = synthesize_delay_bound(lin.A, lin.B, (0.35,), SynthesisSettings(rel_tol=1e-3))
    r = synthesize_tight(lin.A, lin.B, h_max=1.0)
    assert fw.status is Outcome.CERTIFIED
    assert r.h_certified >= fw.h_certified
    # A is Hurwitz and the loop has no crossing: the bound is only the cap
    c = check_tight(lin.A, lin.B, r.K, h_hi=r.h_max)
    assert r.at_cap and math.isinf(c.check.exact.h)
    assert c.check.h_certified >= 1.0


def test_eps_search_stops_at_the_cap_and_refines_otherwise():
    calls = []

    def value(eps):
        calls.append(eps)
        return -(math.log(eps) - math.log(2.0)) ** 2        # peak at eps = 2
    best, seen = maximise_log_scalar(value, (0.1, 1.0, 10.0), golden_steps=12)
    assert best == pytest.approx(2.0, rel=0.02)
    assert len(calls) == len(seen)                           # each eps once
    best, seen = maximise_log_scalar(lambda e: 1.0, (0.1, 1.0, 10.0), stop_at=1.0)
    assert list(seen) == [0.1]


def test_bad_eps_is_rejected():
    with pytest.raises(ValueError, match="eps"):
        WirtingerSynthesis(*SCALAR, 0.0)


@pytest.mark.parametrize("line, key", [
    ("grid = [1.0, 0.1]", "tight.grid"),
    ("reference_eps = 0.33", "tight.reference_eps"),
    ("h_max = -1.0", "tight.h_max"),
    ("colour = 1", "tight.colour"),
])
def test_bad_tight_table_names_key(tmp_path, line, key):
    import re

    from workbench.design import load_design
    from workbench.errors import DesignError
    text = open("designs/antiskid-cruise-wet.toml").read()
    text, n = re.subn(r"\[tight\]\n(?:[^\n]+\n)+", f"[tight]\n{line}\n", text)
    assert n == 1
    bad = tmp_path / "antiskid-cruise-wet.toml"       # design.name must match
    bad.write_text(text)
    with pytest.raises(DesignError) as exc:
        load_design(bad)
    assert key in str(exc.value)
