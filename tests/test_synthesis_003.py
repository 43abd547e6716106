"""Certified synthesis of paper 003 (problem 60): Table 3, certificates,
brackets, and the evidence for rows that do not reproduce."""
import math
from decimal import ROUND_DOWN, Decimal

import numpy as np
import pytest

from workbench.lmi.core import Outcome
from workbench.lmi.freeweighting003 import FreeWeighting003
from workbench.margins import delay_margin_eig
from workbench.plants.adhesion import NumericAdhesion
from workbench.symbolic.linearise import linearise_cruise
from workbench.synthesis import (SynthesisSettings, balancing, certify_given_gain,
                                 eps_for_bound, synthesize_delay_bound)

DRY = dict(a=0.3315, b=40.19, c=5.392, J=80.0, r=0.445, m=12000.0, zeta=0.01, c0=180.9,
           c1=112.2, c2=2.6, g=9.8)   # 003 Tables 1-2


@pytest.fixture(scope="module")
def lin():
    p = NumericAdhesion.from_dict(DRY)
    return linearise_cruise(p, 70.0, p.cruise_lambda(70.0))


@pytest.fixture(scope="module")
def rows(lin):
    return {r.eps: r for r in synthesize_delay_bound(lin.A, lin.B, (0.35, 0.30, 0.25, 0.20, 0.10))}


def _truncated(x, digits=4):
    return float(Decimal(repr(x)).quantize(Decimal(1).scaleb(-digits), rounding=ROUND_DOWN))


# 003 Table 3: (eps, printed h_m, printed K); h_m printed with 4 decimals,
# consistent with truncation for the rows that reproduce.
TABLE3 = [(0.35, 0.0433, (-0.0049, 10.5080)), (0.30, 0.0387, (-0.0052, 11.2833)),
          (0.25, 0.0340, (-0.0057, 12.1618)), (0.20, 0.0255, (-0.0065, 13.9104)),
          (0.10, 0.0179, (-0.0073, 15.7619))]
REPRODUCES = {0.35: True, 0.30: True, 0.25: True, 0.20: False, 0.10: False}


@pytest.mark.parametrize("eps, h_m, K", TABLE3)
def test_table3(rows, lin, eps, h_m, K):
    r = rows[eps]
    assert r.status is Outcome.CERTIFIED
    assert r.h_certified <= r.h_refuted <= r.h_certified * (1 + 2e-4)
    if REPRODUCES[eps]:
        assert _truncated(r.h_certified) == h_m
        # K is not unique at the optimum (a face of optimal points; the
        # printed K is one of them). Ours is the canonical gain, taken at
        # 0.99 h_certified, rounded, and certified on its own by at least that:
        assert r.gain.h_design <= r.h_gain <= r.h_certified * (1 + 2e-4)
        # it lies near the printed point (the 1 % step back in h moves k2 by
        # about 2 %; a 1 % tolerance applied to the old, arbitrary optimum)
        assert r.K[1] == pytest.approx(K[1], rel=0.03)
        assert r.K[0] == pytest.approx(K[0], abs=0.0006)
    else:
        # Not reproduced: our bound is higher, and the printed gain itself
        # certifies more than the printed bound under the same LMI.
        assert _truncated(r.h_certified) != h_m
        assert r.h_certified > h_m
        br = certify_given_gain(lin.A, lin.B, np.array([K]), eps)
        assert br.h_certified > h_m
        print(f"eps={eps}: printed {h_m}, ours {r.h_certified:.5f}, printed K certifies "
              f"{br.h_certified:.5f}")


def test_eps_matching_the_printed_0255(lin):
    eps = eps_for_bound(lin.A, lin.B, 0.0255, 0.05, 0.35)
    assert eps is not None and 0.1 < eps < 0.2     # a different eps than printed (0.20)


def test_exact_margins_of_synthesised_gains_are_infinite(rows, lin):
    for r in rows.values():
        assert math.isinf(r.exact.h) and math.isinf(r.exact_siso.h)


def _certificate(lin, eps=0.35, h=0.04):
    T = balancing(lin.A)
    Ti = np.diag(1 / np.diag(T))
    crit = FreeWeighting003(Ti @ lin.A @ T, Ti @ lin.B, eps)
    return crit, crit.solve_at(h)


def test_certificate_recheck_and_tampering(lin):
    crit, step = _certificate(lin)
    assert step.outcome is Outcome.CERTIFIED
    assert min(crit.recheck(step.certificate, step.h).values()) >= crit.margin
    # the same certificate does not prove a much larger delay (eq 58 fails)
    assert min(crit.recheck(step.certificate, 10 * step.h).values()) < 0
    # tampering with one decision variable breaks it
    bad = dict(step.certificate)
    bad["V"] = bad["V"] * 5.0
    assert min(crit.recheck(bad, step.h).values()) < 0
    bad = dict(step.certificate)
    bad["L"] = -bad["L"]
    assert min(crit.recheck(bad, step.h).values()) < 0
    # a non-symmetric "symmetric" block is rejected outright
    bad = dict(step.certificate)
    bad["W"] = bad["W"] + np.array([[0.0, 1e-3], [0.0, 0.0]])
    assert crit.recheck(bad, step.h)["W_pos"] == -math.inf


def test_both_sides_of_the_bracket(rows, lin):
    r = rows[0.35]
    crit, _ = _certificate(lin)
    assert crit.solve_at(r.h_certified).outcome is Outcome.CERTIFIED
    assert crit.solve_at(r.h_refuted * 1.01).outcome is Outcome.REFUTED


def test_unstable_gain_is_refuted_not_certified(lin):
    # K pushing lambda upwards: A + B K unstable, no delay can be certified
    br = certify_given_gain(lin.A, lin.B, np.array([[0.0, 40.0]]), 0.35,
                            SynthesisSettings(max_solves=12))
    assert delay_margin_eig(lin.A, lin.B @ np.array([[0.0, 40.0]])).h == 0.0
    assert br.h_certified == 0.0 and br.outcome is not Outcome.CERTIFIED


def _bits(r):
    """Every field of a row but its seconds, certificate arrays as bytes."""
    cert = {k: v.tobytes() for k, v in r.certificate.items()}
    return ({k: v for k, v in r.to_json().items() if k != "seconds"}, r.statuses,
            r.recheck, cert, r.gain.point.h, [s.h for s in r.gain.analysis.steps])


def test_pipelined_sweep_is_the_serial_one_bit_for_bit(rows, lin, monkeypatch):
    # the fixture ran with the tie-breaks in a forked worker (where fork exists);
    # one process, one eps after the other, gives the same bits
    from workbench import synthesis
    monkeypatch.setattr(synthesis, "PIPELINE", False)
    serial = synthesize_delay_bound(lin.A, lin.B, (0.35, 0.30, 0.25, 0.20, 0.10))
    assert [_bits(r) for r in serial] == [_bits(rows[r.eps]) for r in serial]


def test_gain_stage_rows_it_could_not_return_are_computed_here():
    import os

    from workbench.forked_stage import ForkedStage
    parent = os.getpid()

    def work(x):
        if x == 2 and os.getpid() != parent:
            os._exit(3)                      # the worker dies on the second item
        return x * x
    stage = ForkedStage.start(work, 3)
    if stage is None:
        pytest.skip("no fork or a single CPU: the sweep runs serially")
    for x in (1, 2, 3):
        stage.submit(x)
    assert stage.results(work) == (1, 4, 9)

    def fails(x):
        raise ValueError(f"bad item {x}")
    stage = ForkedStage.start(fails, 2)
    stage.submit(1)
    with pytest.raises(ValueError, match="bad item 1"):   # raised here, as serially
        stage.results(fails)
