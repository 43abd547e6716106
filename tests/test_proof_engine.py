"""The proof engine itself: three verdicts, counterexamples that fail, hypotheses that matter."""
import dataclasses

import pytest
import sympy as sp

from workbench.symbolic.proof import (Claim, Verdict, check_claim, hyp, prove_nonnegative,
                                      time_derivative)

x, y, z, Dl = sp.symbols("x y z Delta", real=True)
k, eta, D, t = sp.symbols("k eta D t", positive=True)


def claim(kind, lhs, rhs, **kw):
    return Claim("t-" + kind, "test", "-", "test claim", kind, lhs, rhs, **kw)


def value_at(expr, cex):
    """Evaluate ``expr`` at a counterexample (names are LaTeX of the symbols)."""
    subs = {s: dict(cex)[sp.latex(s)] for s in expr.free_symbols}
    return float(expr.subs(subs))


def test_known_true_identity_is_proved():
    r = check_claim(claim("identity", (x + y) ** 2, x**2 + 2 * x * y + y**2))
    assert r.verdict is Verdict.PROVED and r.ok and r.counterexample is None
    assert r.samples > 0


def test_identity_with_sign_cases_is_proved():
    r = check_claim(claim("identity", sp.sign(x) * sp.Abs(x) * sp.Abs(y), sp.Abs(y) * x))
    assert r.verdict is Verdict.PROVED


def test_false_identity_is_refuted_with_a_counterexample():
    lhs, rhs = (x + y) ** 2, x**2 + y**2
    r = check_claim(claim("identity", lhs, rhs))
    assert r.verdict is Verdict.REFUTED and not r.ok
    assert abs(value_at(lhs - rhs, r.counterexample)) > 1e-6


def test_known_false_inequality_is_refuted_and_its_counterexample_fails():
    # x y <= (x^2 + y^2)/4 is false (x = y = 1: 1 > 1/2)
    lhs, rhs = x * y, (x**2 + y**2) / 4
    r = check_claim(claim("inequality", lhs, rhs))
    assert r.verdict is Verdict.REFUTED
    assert value_at(lhs, r.counterexample) > value_at(rhs, r.counterexample)
    assert r.violation > 0


def test_true_inequality_by_decomposition_is_proved():
    # x y <= (x^2 + y^2)/2 because the margin is (x - y)^2/2
    r = check_claim(claim("inequality", x * y, (x**2 + y**2) / 2, terms=((x - y) ** 2 / 2,)))
    assert r.verdict is Verdict.PROVED


def test_wrong_decomposition_is_not_a_proof():
    r = check_claim(claim("inequality", x * y, (x**2 + y**2) / 2, terms=((x + y) ** 2 / 2,)))
    assert r.verdict is Verdict.INCONCLUSIVE and "add up" in r.remaining


def test_assumption_dependent_claim_inconclusive_without_proved_with():
    # x y^2 >= 0 holds on the sampled box x in [0, 5] but needs x >= 0 to be shown
    base = claim("inequality", 0, x * y**2, sample=((x, 0.0, 5.0),))
    without = check_claim(base)
    assert without.verdict is Verdict.INCONCLUSIVE
    assert "x y^{2}" in without.remaining
    with_ = check_claim(dataclasses.replace(base, hypotheses=(hyp(x, ">=", 0),)))
    assert with_.verdict is Verdict.PROVED


def test_sliding_mode_bound_needs_its_hypotheses():
    lhs, rhs = -k * z**2 - eta * sp.Abs(z) + Dl * z, -k * z**2
    bare = check_claim(claim("inequality", lhs, rhs))
    assert bare.verdict is Verdict.REFUTED
    cex = dict(bare.counterexample)
    assert abs(cex[r"\Delta"]) > cex[r"\eta"]          # it breaks |Delta| < eta
    full = check_claim(claim("inequality", lhs, rhs,
                             hypotheses=(hyp(eta, ">", D), hyp(D, ">=", sp.Abs(Dl)))))
    assert full.verdict is Verdict.PROVED


def test_counterexamples_are_deterministic():
    c = claim("inequality", x * y, (x**2 + y**2) / 4)
    assert check_claim(c).counterexample == check_claim(c).counterexample


def test_minimiser_derived_and_wrong_law_refuted():
    u, a = sp.symbols("u a", real=True)
    J = (u - a) ** 2 + k * u**2
    good = check_claim(claim("minimiser", J, a / (1 + k), variable=u))
    assert good.verdict is Verdict.PROVED
    bad = check_claim(claim("minimiser", J, a, variable=u))
    assert bad.verdict is Verdict.REFUTED


def test_minimiser_of_a_concave_criterion_is_not_proved():
    u, a = sp.symbols("u a", real=True)
    r = check_claim(claim("minimiser", -(u - a) ** 2, a, variable=u))
    assert r.verdict is not Verdict.PROVED


def test_closed_form_solution():
    x0 = sp.Symbol("x_0", positive=True)
    s = sp.Symbol("s", real=True)
    ok = check_claim(claim("solution", x0 * sp.exp(-k * t), -k * s, variable=t, state=s,
                           initial=(0, x0)))
    assert ok.verdict is Verdict.PROVED
    wrong = check_claim(claim("solution", x0 * sp.exp(-2 * k * t), -k * s, variable=t,
                              state=s, initial=(0, x0)))
    assert wrong.verdict is Verdict.REFUTED


@pytest.mark.parametrize("printed, verdict", [(96.466, Verdict.PROVED),
                                              (96.465, Verdict.REFUTED)])
def test_worked_value_at_printed_digits(printed, verdict):
    v = sp.Rational(1389, 100)
    assert check_claim(claim("value", v**2 / 2, printed, digits=3)).verdict is verdict


def test_expected_refuted_is_ok_only_when_refuted():
    false = claim("identity", x, x + 1, expect="refuted")
    assert check_claim(false).ok
    true = claim("identity", x, x, expect="refuted")
    assert not check_claim(true).ok


def test_prove_nonnegative_reports_what_remains():
    ok, rest = prove_nonnegative(x * y)
    assert not ok and "x y" in rest
    assert prove_nonnegative(1 - sp.exp(-t)) == (True, "")


def test_time_derivative_is_the_chain_rule():
    assert sp.expand(time_derivative(x**2 * y, {x: y, y: 1}) - (2 * x * y**2 + x**2)) == 0


def test_bad_hypothesis_operator_rejected():
    with pytest.raises(ValueError):
        hyp(x, "=>", 0)
