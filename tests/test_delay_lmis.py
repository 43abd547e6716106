"""Analysis LMIs for x' = A x + A_d x(t-h): reference bounds, both sides of
the boundary, exact re-check, soundness over random systems, CLI."""
import json
import math

import numpy as np
import pytest

from workbench.cli import main
from workbench.lmi.analysis import (BesselLegendreLMI, JensenLMI, certified_delay, legendre_derivative_coefficients,
                                    make_criterion)
from workbench.lmi.core import Outcome
from workbench.lmi.hierarchy import bessel_legendre_auto
from workbench.lmi.exact_check import exact_check, first_nonpositive_pivot, to_rational
from workbench.margins import delay_margin_eig

A = np.array([[-2.0, 0.0], [0.0, -0.9]])      # the classic example (issue 4)
AD = np.array([[-1.0, 0.0], [-1.0, -1.0]])
EXACT = 6.172581371221277                     # delay_margin_eig; 6.1726 to 4 decimals
MARGIN = 1e-10                                 # as in designs/delay-benchmarks.toml


@pytest.fixture(scope="module")
def classic():
    out = {}
    for m in ("delay-independent", "jensen", "free-weighting", "wirtinger"):
        lmi = make_criterion(m, A, AD, margin=MARGIN)
        out[m] = (lmi, certified_delay(lmi))
    return out


@pytest.mark.parametrize("method, printed, source", [
    ("jensen", 4.472, "Seuret & Gouaisbaut 2013, Table 1"),
    ("free-weighting", 4.472, "issue 4; He et al. 2004 Example 1"),
    ("wirtinger", 6.059, "Seuret & Gouaisbaut 2013, Table 1 (Theorem 5)"),
])
def test_classic_reference_bounds(classic, method, printed, source):
    b = classic[method][1]
    assert b.bracket.outcome is Outcome.CERTIFIED
    assert round(b.h_certified, 3) == printed, source       # 3 printed decimals
    assert b.h_certified <= EXACT


def test_delay_independent_test(classic):
    b = classic["delay-independent"][1]
    assert b.h_certified == 0.0 and b.bracket.outcome is Outcome.REFUTED
    di = certified_delay(make_criterion("delay-independent", [[-2.0]], [[-1.0]]))
    assert di.h_certified == math.inf                         # |b| < -a (Hayes 1950)


def test_both_sides_of_the_boundary(classic):
    lmi, b = classic["wirtinger"]
    assert lmi.solve_at(b.h_certified).outcome is Outcome.CERTIFIED
    assert lmi.solve_at(b.bracket.h_refuted).outcome is Outcome.REFUTED
    assert b.bracket.h_refuted / b.h_certified <= 1 + 1e-5


def test_jensen_equals_bessel_legendre_order_zero(classic):
    b0 = certified_delay(BesselLegendreLMI(A, AD, 0, margin=MARGIN))
    assert b0.h_certified == pytest.approx(classic["jensen"][1].h_certified, rel=2e-5)


def test_bessel_legendre_auto_reaches_target():
    auto = bessel_legendre_auto(A, AD, EXACT, gap_tol=1e-4, N_max=8, margin=MARGIN)
    assert auto.N_reached is not None and auto.N_reached <= 5
    assert auto.best.h_certified / EXACT >= 0.9999             # issue 4 target
    assert auto.best.h_certified <= EXACT
    hs = [b.h_certified for b in auto.bounds]
    assert all(b >= a * (1 - 1e-5) for a, b in zip(hs, hs[1:]))
    assert [b.N for b in auto.bounds] == list(range(auto.N_reached + 1))


def test_auto_stops_at_the_cap_when_the_gap_cannot_close():
    auto = bessel_legendre_auto(A, AD, math.inf, N_max=1, margin=MARGIN)
    assert auto.N_reached is None and [b.N for b in auto.bounds] == [0, 1]


def test_legendre_coefficients_match_numpy():
    # l_k(u) = P_k(2u - 1); l_k' = sum_j c_kj l_j, checked with numpy's Legendre series
    from numpy.polynomial import legendre as L
    c = legendre_derivative_coefficients(5)
    u = np.linspace(0, 1, 7)
    for k in range(6):
        dk = 2 * L.legval(2 * u - 1, L.legder(np.eye(6)[k]))
        assert np.allclose(dk, sum(c[k, j] * L.legval(2 * u - 1, np.eye(6)[j])
                                   for j in range(k)) if k else 0 * u)


def test_exact_check_certifies_and_refutes(classic):
    lmi, b = classic["free-weighting"]
    step = b.bracket.certificate
    assert exact_check(lmi, step.certificate, step.h).outcome is Outcome.CERTIFIED
    beyond = exact_check(lmi, step.certificate, b.bracket.h_refuted * 1.01)
    assert beyond.outcome is Outcome.REFUTED
    tampered = dict(step.certificate, P=-step.certificate["P"])
    assert exact_check(lmi, tampered, step.h).outcome is Outcome.REFUTED


def test_exact_check_bessel_legendre():
    lmi = BesselLegendreLMI(A, AD, 3, margin=MARGIN)
    step = lmi.solve_at(6.0)
    assert step.outcome is Outcome.CERTIFIED
    assert exact_check(lmi, step.certificate, 6.0).outcome is Outcome.CERTIFIED


def test_ldl_pivots():
    assert first_nonpositive_pivot(to_rational([[2.0, 1.0], [1.0, 2.0]])) is None
    k, d = first_nonpositive_pivot(to_rational([[1.0, 2.0], [2.0, 1.0]]))
    assert k == 1 and d == -3


def test_bad_arguments():
    with pytest.raises(ValueError):
        BesselLegendreLMI(A, AD, -1)
    with pytest.raises(ValueError):
        make_criterion("jensen-ish", A, AD)
    with pytest.raises(ValueError):
        JensenLMI(A, np.eye(3))


# -- soundness suite ------------------------------------------------------------
def _random_systems(count: int, seed: int):
    """Seeded random stable systems (n = 1, 2) with finite exact margins in (0.01, 30) s."""
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    out = []
    while len(out) < count:
        n = int(rng.integers(1, 3))
        Am, Adm = rng.normal(size=(n, n)), rng.normal(size=(n, n)) * rng.uniform(0.5, 2)
        Am -= (np.max(np.linalg.eigvals(Am + Adm).real) + rng.uniform(0.05, 1.0)) * np.eye(n)
        h = delay_margin_eig(Am, Adm).h
        if math.isfinite(h) and 1e-2 < h < 30:
            out.append((Am, Adm, h, rng.uniform(0.3, 1.0)))
    return out


#: Soundness tolerance: no certificate at h = h* (1 + SOUND_TOL).
SOUND_TOL = 1e-4


@pytest.mark.slow
def test_soundness_random_systems():
    """200 seeded systems. No criterion certifies h* (1 + 1e-4) (free-weighting,
    Bessel-Legendre N = 0 (Jensen), 1 (Wirtinger), 2). At a random h < h*,
    a Bessel-Legendre certificate of order N is never followed by a REFUTED
    order N + 1 (the hierarchy, SG15 Theorem 4); an INCONCLUSIVE solve
    (solver inaccuracy, not a refutation) is tolerated in at most 1 % of cases."""
    unsound, refuted_up, inconclusive_up, certified = [], [], 0, [0, 0, 0]
    for i, (Am, Adm, h, frac) in enumerate(_random_systems(200, 20260421)):
        fw = make_criterion("free-weighting", Am, Adm, margin=MARGIN)
        if fw.solve_at(h * (1 + SOUND_TOL)).outcome is Outcome.CERTIFIED:
            unsound.append((i, "free-weighting"))
        prev = False
        for N in range(3):
            lmi = BesselLegendreLMI(Am, Adm, N, margin=MARGIN)
            if lmi.solve_at(h * (1 + SOUND_TOL)).outcome is Outcome.CERTIFIED:
                unsound.append((i, N))
            out = lmi.solve_at(h * frac).outcome
            certified[N] += out is Outcome.CERTIFIED
            if prev and out is Outcome.REFUTED:
                refuted_up.append((i, N))
            inconclusive_up += prev and out is Outcome.INCONCLUSIVE
            prev = out is Outcome.CERTIFIED
    assert not unsound
    assert not refuted_up
    assert inconclusive_up <= 2
    assert certified[0] <= certified[1] <= certified[2] and certified[2] >= 180  # not vacuous


# -- CLI ---------------------------------------------------------------------------
def _small_design(tmp_path, matrix="[[-1.0]]"):
    (tmp_path / "ex").mkdir()
    (tmp_path / "ex" / "pure.toml").write_text(
        '[example]\nname = "pure"\ntitle = "x\' = -x(t-h)"\nsource = "Hayes 1950"\n'
        f"A = [[0.0]]\nAd = {matrix}\n")
    d = tmp_path / "small-bench.toml"
    d.write_text('[design]\nname = "small-bench"\nkind = "delay-benchmark"\n'
                 'title = "t"\nsource = "test"\n[benchmark]\nexamples = "ex"\n'
                 'methods = ["free-weighting", "bessel-legendre"]\norders = 2\nN_max = 3\n'
                 "rel_tol = 1e-3\n")
    return d


def test_cli_benchmark_json_schema(tmp_path, capsys):
    code = main(["benchmark", "delay", str(_small_design(tmp_path)), "--json", "--exact-check"])
    assert code == 0
    data = json.loads(capsys.readouterr().out)
    (ex,) = data["examples"]
    assert ex["name"] == "pure" and ex["exact_margin"] == pytest.approx(math.pi / 2)
    keys = {"method", "N", "h_certified", "h_refuted", "outcome", "at_cap", "ratio", "solves",
            "seconds", "certified_interval", "interval_ratio", "interval_solves"}
    assert all(keys <= set(m) for m in ex["methods"])
    # issue 13: the exact windows and an interval certificate per method
    assert ex["stable_windows"] == [[0.0, pytest.approx(math.pi / 2)]] and ex["sound"]
    for m in ex["methods"]:
        lo, hi = m["certified_interval"]
        assert lo == 0.0 and 0 < hi < math.pi / 2
    assert [(m["method"], m["N"]) for m in ex["methods"]] == [
        ("free-weighting", None), ("bessel-legendre", 0), ("bessel-legendre", 1),
        ("bessel-legendre", 2), ("bessel-legendre-auto", 2)]
    assert all(0 < m["ratio"] <= 1 and m["exact_check"] == "certified" for m in ex["methods"])
    assert set(ex) == {"name", "exact_margin", "exact_margin_sweep", "exact_agreement",
                       "exact_methods_agree", "stable_windows", "sound", "methods"}


def test_cli_benchmark_json_exact_schema(tmp_path, capsys):
    assert main(["benchmark", "delay", str(_small_design(tmp_path)), "--json"]) == 0
    (ex,) = json.loads(capsys.readouterr().out)["examples"]
    assert all(set(m) == {"method", "N", "h_certified", "h_refuted", "outcome", "at_cap",
                          "ratio", "solves", "seconds", "certified_interval",
                          "certified_intervals", "interval_ratio", "interval_solves"}
               for m in ex["methods"])


def test_cli_benchmark_bad_input(tmp_path, capsys):
    assert main(["benchmark", "delay", str(_small_design(tmp_path, '[[-1.0, 2.0]]'))]) == 2
    assert "Ad" in capsys.readouterr().err
    assert main(["benchmark", "delay", str(tmp_path / "missing.toml")]) == 2


# -- robust synthesis and decay rate ----------------------------------------------------
def test_robust_synthesis_is_sound_at_every_point():
    from workbench.crosscheck import check_gain
    from workbench.lmi.robust import synthesize_robust
    # two double-integrator-like points with different input gains (synthetic)
    pts = [(np.array([[0.0, 1.0], [0.0, -0.5]]), np.array([[0.0], [b]])) for b in (0.8, 1.2)]
    syn = synthesize_robust(pts, eps_grid=(0.3, 1.0, 3.0), golden_steps=1, rel_tol=1e-2,
                            h_hi=10.0)
    assert syn.bracket.outcome is Outcome.CERTIFIED and syn.K is not None
    for c in check_gain(pts, syn.K, N=2):
        assert c.stable_at_zero
        assert c.exact.h >= syn.bracket.h_certified          # certificate below exact margin
        assert c.h_certified <= c.exact.h * (1 + 1e-4)


def test_check_gain_reports_an_unstable_point():
    from workbench.crosscheck import check_gain
    pts = [(np.array([[-1.0]]), np.array([[1.0]])), (np.array([[-1.0]]), np.array([[-1.0]]))]
    good, bad = check_gain(pts, [[-0.5]])                      # A + B K = -1.5 and -0.5
    assert good.stable_at_zero and good.exact.h == math.inf
    assert bad.stable_at_zero                                  # -1 + 0.5
    worse = check_gain(pts, [[2.0]])                           # -1 + 2 = 1 > 0 at point 0
    assert not worse[0].stable_at_zero and worse[0].h_certified == 0.0


def test_decay_rate_cross_checked_with_spectral_abscissa():
    from workbench.crosscheck import decay_rate_bound
    from workbench.margins import spectral_abscissa
    d = decay_rate_bound([[0.0]], [[-1.0]], 0.2, N=2, rel_tol=1e-3)
    h = d.bracket.h_certified
    assert 0 < h < math.pi / 2
    assert d.abscissa <= -0.2 + 1e-9
    assert spectral_abscissa([[0.0]], [[-1.0]], h * 1.01) > -0.2   # tight: rate lost just above


@pytest.mark.parametrize("old, new, key", [
    ('rails = ["dry", "wet"]', 'rails = ["dry", "icy"]', "operating_points.rails"),
    ("v_d = [50.0, 70.0]", "v_d = [50.0, 80.0]", "operating_points.v_d"),   # no wet equilibrium
    ("alpha = 0.05", "alpha = -0.05", "synthesis.alpha"),
])
def test_robust_design_bad_input(tmp_path, capsys, old, new, key):
    src = open("designs/antiskid-robust.toml", encoding="utf-8").read()
    assert old in src
    path = tmp_path / "antiskid-robust.toml"
    path.write_text(src.replace(old, new), encoding="utf-8")
    assert main(["verify", str(path)]) == 2
    assert key in capsys.readouterr().err


def test_hierarchy_never_goes_backwards(monkeypatch):
    """An order whose own search fails (as after an inaccurate solve) reports
    the lower order's certificate, which proves it feasible (SG15 Thm 4)."""
    import workbench.lmi.analysis as an
    import workbench.lmi.hierarchy as hi
    real = an.certified_delay

    def flaky(lmi, **kw):
        b = real(lmi, **kw)
        if lmi.N == 2:                       # order 2's search "lost" its bound
            return an.DelayBound(b.method, 2, an.Bracket(0.0, math.inf, Outcome.INCONCLUSIVE,
                                                         None, b.bracket.steps))
        return b
    monkeypatch.setattr(hi, "certified_delay", flaky)
    auto = hi.bessel_legendre_auto(A, AD, EXACT, N_max=2, N_through=2, rel_tol=1e-3,
                                   margin=MARGIN)
    h = [b.h_certified for b in auto.bounds]
    assert h == sorted(h) and h[2] == h[1] > 0
    assert auto.bounds[2].certified_by == 1 and auto.bounds[1].certified_by is None


def test_make_criterion_rejects_an_order_it_would_ignore():
    with pytest.raises(ValueError, match="N = 3; expected None"):
        make_criterion("jensen", A, AD, N=3)
