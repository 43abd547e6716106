"""Issue 21, exact half: every eigenvalue branch, scale-free tolerances, stability
windows, the adaptive spectral abscissa, the two-method cross-check and input checks."""
import json
import math

import mpmath
import numpy as np
import pytest

from workbench import benchmark
from workbench.cli import main
from workbench.margins import (AGREEMENT_RTOL, Agreement, SpectrumNotConverged, delay_margin_eig,
                               delay_margin_siso, delay_margin_sweep, exact_margin, is_hurwitz,
                               relative_difference, rightmost_roots, spectral_abscissa,
                               stability_windows)

EXACT = [delay_margin_eig, delay_margin_sweep]


def oscillator(a: float, k: float):
    """x'' + a x = -k x'(t - h) as x' = A x + A_d x(t - h), x = (x, x')."""
    return np.array([[0.0, 1.0], [-a, 0.0]]), np.array([[0.0, 0.0], [0.0, -k]])


def oscillator_crossings(a: float, k: float):
    """Analytic crossings of s^2 + k s e^{-s h} + a = 0 (a > 0): |k w| = |w^2 - a|
    gives w+ = (|k| + sqrt(k^2 + 4a))/2 and w- = (-|k| + sqrt(k^2 + 4a))/2; the
    phase j k w e^{-j w h} = w^2 - a fixes theta. Returns (w, theta, direction)."""
    r = math.sqrt(k * k + 4 * a)
    wp, wm = (abs(k) + r) / 2, (-abs(k) + r) / 2
    if k > 0:      # e^{-j theta} = -j at w+, = +j at w-
        return [(wp, math.pi / 2, +1), (wm, 3 * math.pi / 2, -1)]
    return [(wp, 3 * math.pi / 2, +1), (wm, math.pi / 2, -1)]


def analytic_windows(a: float, k: float, h_max: float):
    """Stability set from the analytic crossings: 2 roots in the RHP at h = 0 when
    k < 0, none when k > 0; +-2 at each crossing delay (theta + 2 pi m)/w. Each
    sequence runs one period past h_max, so every window starting below h_max closes."""
    events = sorted(((th + 2 * math.pi * m) / w, d) for w, th, d in oscillator_crossings(a, k)
                    for m in range(int(h_max * w / (2 * math.pi)) + 2))
    count, start, out = (0, 0.0, []) if k > 0 else (2, None, [])
    for h, d in events:
        count += 2 * d
        if start is not None and count > 0:
            out.append((start, h))
            start = None
        elif start is None and count == 0:
            start = h
    return tuple(w for w in out if w[0] <= h_max)


# -- item 1: the oscillator family, both methods -------------------------------------------
def test_anchor_oscillator_both_branches():
    # issue 21 item 1: x'' + x = -0.5 x'(t-h); at theta = pi/2 both eigenvalues of
    # A + A_d e^{-j theta} are on the axis (j 1.28078 and -j 0.78078); h* = (pi/2)/1.28078
    A, Ad = oscillator(1.0, 0.5)
    wp = (0.5 + math.sqrt(4.25)) / 2
    assert round(wp, 5) == 1.28078
    for method in EXACT:
        dm = method(A, Ad)
        assert round(dm.h, 6) == 1.226441                       # issue 21 (6 decimals)
        assert relative_difference(dm.h, (math.pi / 2) / wp) <= 1e-12
        assert relative_difference(dm.omega, wp) <= 1e-12
        assert len(dm.crossings) == 2                          # both branches found


@pytest.mark.parametrize("a, k", [(1.0, 0.5), (1.0, 0.1), (1.0, 1.0), (1.0, 2.0), (4.0, 0.5),
                                  (0.25, 1.0), (9.0, 0.3), (1e-2, 3.0)])
def test_oscillator_family(a, k):
    # analytic: h* = (pi/2)/w+ with w+ = (k + sqrt(k^2 + 4a))/2 (derived in oscillator_crossings)
    A, Ad = oscillator(a, k)
    expected = (math.pi / 2) / ((k + math.sqrt(k * k + 4 * a)) / 2)
    for method in EXACT:
        assert relative_difference(method(A, Ad).h, expected) <= 1e-12, method.__name__
    assert relative_difference(delay_margin_siso(A, [[0.0], [1.0]], [[0.0, -k]]).h,
                               expected) <= 1e-12
    for method in ("sweep", "kronecker"):
        got = stability_windows(A, Ad, 40.0, method=method)
        want = analytic_windows(a, k, 40.0)
        assert len(got) == len(want)
        for (g0, g1), (w0, w1) in zip(got, want):
            assert relative_difference(g0, w0) <= 1e-12 and relative_difference(g1, w1) <= 1e-12


def test_pure_delay_pi_over_two():
    # x' = -x(t-h): pi/2 (Hayes 1950), crossing at w = 1
    for method in EXACT:
        dm = method([[0.0]], [[-1.0]])
        assert relative_difference(dm.h, math.pi / 2) <= 1e-15 and dm.omega == 1.0
    assert stability_windows([[0.0]], [[-1.0]], 100.0) == ((0.0, math.pi / 2),)


# -- item 3: scale-free tolerances ---------------------------------------------------------
@pytest.mark.parametrize("c", [1e-6, 1e-3, 1e3, 1e6])
def test_classic_example_in_other_time_units(c):
    # issue 21 item 2: (c A, c A_d) has h* / c (6.1726 s at c = 1, Seuret & Gouaisbaut 2015
    # Example 1, 4 decimals) and the crossing at c sqrt(0.19) rad/s (4.4e-7 at c = 1e-6)
    A = c * np.array([[-2.0, 0.0], [0.0, -0.9]])
    Ad = c * np.array([[-1.0, 0.0], [-1.0, -1.0]])
    h1 = delay_margin_eig(np.array([[-2.0, 0.0], [0.0, -0.9]]),
                          np.array([[-1.0, 0.0], [-1.0, -1.0]])).h
    assert round(h1, 4) == 6.1726
    for method in EXACT:
        dm = method(A, Ad)
        assert dm.reason == "crossing"
        assert relative_difference(dm.h, h1 / c) <= 1e-12
        assert relative_difference(dm.omega, c * math.sqrt(0.19)) <= 1e-12


def _scalar_margin(a: float) -> float:
    """x' = a x - x(t - h), |a| < 1: cos theta = a, w = sin theta, h* = theta / w
    (Hayes 1950), in 50-digit arithmetic from the double a."""
    with mpmath.workdps(50):
        a = mpmath.mpf(a)
        return float(mpmath.acos(a) / mpmath.sqrt(1 - a * a))


@pytest.mark.parametrize("a", [1 - 1e-13, 1 - 1e-6, 1 - 1e-3, 0.5])
def test_near_singular_scalar(a):
    # issue 21 item 2: a = 1 - 1e-13 (eig said inf) and a = 1 - 1e-6 (the sweep said inf:
    # the crossing theta = 1.4e-3 lies in its first grid interval)
    expected = _scalar_margin(a)
    for method in EXACT:
        dm = method([[a]], [[-1.0]])
        assert dm.reason == "crossing"
        assert relative_difference(dm.h, expected) <= 1e-10, method.__name__
    # python-control's crossover: its own accuracy (7e-10 at a = 1 - 1e-13), not ours
    assert relative_difference(delay_margin_siso([[a]], [[1.0]], [[-1.0]]).h, expected) <= 1e-8


# -- item 4: stability windows ------------------------------------------------------------
def _check_windows_with_spectrum(A, Ad, windows, h_max, rng, n_points=12):
    """Spectral abscissa < 0 inside every window, > 0 between them (seeded h)."""
    edges = sorted({0.0, h_max} | {e for w in windows for e in w if e < h_max})
    for lo, hi in zip(edges, edges[1:]):
        for h in lo + (hi - lo) * rng.uniform(0.05, 0.95, n_points // max(1, len(edges) - 1) + 1):
            inside = any(a < h < b for a, b in windows)
            assert (spectral_abscissa(A, Ad, h) < 0) == inside, (h, windows)


def test_unstable_at_zero_then_stable_window():
    # x'' + x = 0.5 x'(t - h): unstable at h = 0 (s^2 - 0.5 s + 1), stabilised on
    # ((pi/2)/w-, (3 pi/2)/w+) by the delayed velocity feedback (analytic crossings,
    # the stability switches of Cooke & Grossman 1982)
    A, Ad = oscillator(1.0, -0.5)
    assert not is_hurwitz(A + Ad)
    r = math.sqrt(4.25)
    want = ((math.pi / 2) / ((r - 0.5) / 2), (3 * math.pi / 2) / ((r + 0.5) / 2))
    for method in ("sweep", "kronecker"):
        (w,) = stability_windows(A, Ad, 50.0, method=method)
        assert relative_difference(w[0], want[0]) <= 1e-12
        assert relative_difference(w[1], want[1]) <= 1e-12
    assert delay_margin_sweep(A, Ad).h == 0.0
    _check_windows_with_spectrum(A, Ad, (want,), 12.0, np.random.default_rng(21))


def test_three_state_triangular_two_windows():
    # x'' + x = -0.5 x'(t-h) driving y' = -y + x(t-h): block-triangular, so the
    # windows are the oscillator's: [0, h*) and ((3 pi/2)/w-, (5 pi/2)/w+)
    A2, Ad2 = oscillator(1.0, 0.5)
    A = np.zeros((3, 3))
    Ad = np.zeros((3, 3))
    A[:2, :2], Ad[:2, :2] = A2, Ad2
    A[2, 2], Ad[2, 0] = -1.0, 1.0
    want = analytic_windows(1.0, 0.5, 30.0)
    assert len(want) == 2
    for method in ("sweep", "kronecker"):
        got = stability_windows(A, Ad, 30.0, method=method)
        assert len(got) == 2
        assert all(relative_difference(g, w) <= 1e-12 for gw, ww in zip(got, want)
                   for g, w in zip(gw, ww))


# A coupled 3 x 3 system with two windows, found by a seeded search over matrices with
# one-decimal entries (rng seed 3, draw 1169); the windows are checked against the
# spectral abscissa below, not taken from a publication.
COUPLED_A = [[-0.6, -1.4, -0.1], [1.0, -0.3, 0.3], [-0.4, -0.6, -0.9]]
COUPLED_AD = [[-0.7, 0.5, 0.0], [-0.2, -0.3, -0.1], [0.1, 0.2, -0.7]]


def test_three_state_coupled_two_windows():
    A, Ad = np.array(COUPLED_A), np.array(COUPLED_AD)
    w_sweep = stability_windows(A, Ad, 10.0)
    w_kron = stability_windows(A, Ad, 10.0, method="kronecker")
    assert len(w_sweep) == 2 and w_sweep[0][0] == 0.0 and w_sweep[1][0] > w_sweep[0][1]
    assert all(relative_difference(a, b) <= AGREEMENT_RTOL
               for wa, wb in zip(w_sweep, w_kron) for a, b in zip(wa, wb))
    _check_windows_with_spectrum(A, Ad, w_sweep, 10.0, np.random.default_rng(1169), 30)


def test_windows_special_cases():
    assert stability_windows([[-2.0]], [[-1.0]], 10.0) == ((0.0, math.inf),)  # every delay
    assert stability_windows([[1.0]], [[-0.5]], 10.0) == ()                    # never
    assert stability_windows([[1.0]], [[-1.0]], 10.0) == ()                    # s = 0 always
    A, Ad = oscillator(1.0, 0.5)
    # the last window's end is the next destabilising crossing, beyond the horizon
    assert stability_windows(A, Ad, 6.1) == stability_windows(A, Ad, 7.0)


# -- item 5: the spectral abscissa ---------------------------------------------------------
def test_spectral_abscissa_reports_order_and_roots():
    A, Ad = oscillator(1.0, 0.5)
    sp = rightmost_roots(A, Ad, 50.0)
    assert sp.order >= math.ceil(np.linalg.norm(A, 2) * 50 / 3)
    s = sp.roots[0]
    det = np.linalg.det(s * np.eye(2) - A - Ad * np.exp(-s * 50.0))
    assert abs(det) <= 1e-12 * (abs(s) + 1.5) ** 2
    assert sp.alpha == s.real == spectral_abscissa(A, Ad, 50.0)
    assert rightmost_roots(A, Ad, 0.0).order == 0


def test_spectral_abscissa_unconverged_is_an_error():
    A, Ad = oscillator(1.0, 0.5)
    with pytest.raises(SpectrumNotConverged, match="not converged"):
        rightmost_roots(A, Ad, 50.0, max_size=60)


def test_spectral_abscissa_against_the_exact_set_at_random_delays():
    # issue 21 item 3: CI cross-check at seeded random h, including long delays
    rng = np.random.default_rng(np.random.SeedSequence(21))
    for a, k in [(1.0, 0.1), (4.0, 0.5), (1.0, -0.5)]:
        A, Ad = oscillator(a, k)
        windows = stability_windows(A, Ad, 60.0)
        edges = [e for w in windows for e in w]
        checked = 0
        for h in rng.uniform(0.0, 60.0, 15):
            if any(abs(h - e) <= 1e-3 * e for e in edges):
                continue
            inside = any(lo < h < hi for lo, hi in windows)
            assert (spectral_abscissa(A, Ad, h) < 0) == inside, (a, k, h)
            checked += 1
        assert checked >= 12


# -- item 2: the two methods --------------------------------------------------------------
def test_exact_margin_outcomes(monkeypatch):
    A, Ad = [[-2.0, 0.0], [0.0, -0.9]], [[-1.0, 0.0], [-1.0, -1.0]]
    em = exact_margin(A, Ad)
    assert em.outcome is Agreement.AGREE and em.ok and em.rel_diff <= AGREEMENT_RTOL
    assert round(em.h, 4) == 6.1726
    single = exact_margin(A, Ad, cross_check="never")
    assert single.outcome is Agreement.SINGLE and single.kronecker is None and single.ok
    from workbench.margins import delay as delay_mod
    wrong = delay_mod.DelayMargin(6.035517, 0.78, "crossing", "broken")
    monkeypatch.setattr(delay_mod, "delay_margin_eig", lambda A, Ad: wrong)
    bad = exact_margin(A, Ad)
    assert bad.outcome is Agreement.DISAGREE and not bad.ok


def _design(tmp_path, A="[[0.0]]", Ad="[[-1.0]]", extra=""):
    (tmp_path / "ex").mkdir()
    (tmp_path / "ex" / "one.toml").write_text(
        '[example]\nname = "one"\ntitle = "t"\nsource = "s"\n'
        f"A = {A}\nAd = {Ad}\n")
    d = tmp_path / "bench.toml"
    d.write_text('[design]\nname = "bench"\nkind = "delay-benchmark"\ntitle = "t"\n'
                 'source = "test"\n[benchmark]\nexamples = "ex"\nmethods = ["jensen"]\n'
                 f"rel_tol = 1e-3\n{extra}")
    return d


def test_cli_fails_when_the_exact_methods_disagree(tmp_path, monkeypatch, capsys):
    d = _design(tmp_path)
    assert main(["benchmark", "delay", str(d)]) == 0
    capsys.readouterr()
    broken = benchmark.DelayMargin(6.035517, 0.78, "crossing", "broken")
    monkeypatch.setattr(benchmark, "delay_margin_sweep", lambda A, Ad: broken)
    assert main(["benchmark", "delay", str(d)]) == 1
    assert "EXACT METHODS DISAGREE" in capsys.readouterr().out
    assert main(["benchmark", "delay", str(d), "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    assert data["exact_methods_agree"] is False
    assert data["examples"][0]["exact_methods_agree"] is False


def test_verify_fails_when_the_exact_methods_disagree(monkeypatch):
    from workbench.design import load_design
    from workbench.kinds.delay_benchmark import STUDY
    design = load_design("designs/delay-benchmarks.toml")
    assert "suite.exact_methods_agree" in STUDY.quantity_names(design.spec)
    claim = next(c for c in design.claims if c.quantity == "suite.exact_methods_agree")
    assert claim.value == "yes"
    fake = benchmark.ExampleResult(design.spec.examples[0],
                                   benchmark.DelayMargin(1.0, 1.0, "crossing", "a"),
                                   benchmark.DelayMargin(1.1, 1.0, "crossing", "b"), ())
    res = benchmark.BenchmarkResult(design.spec.settings, (fake,))
    assert STUDY.quantities(res)["suite.exact_methods_agree"] == "no"


# -- item 9: JSON and the text table --------------------------------------------------------
def test_json_and_text_mark_the_cap(tmp_path, capsys):
    # x' = -2x - x(t-h) is stable for every delay: the Jensen bound reaches the cap h_max
    d = _design(tmp_path, "[[-2.0]]", "[[-1.0]]", "h_max = 5.0\n")
    assert main(["benchmark", "delay", str(d), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    (m,) = data["examples"][0]["methods"]
    assert m["at_cap"] is True and m["h_certified"] >= 5.0
    assert m["outcome"] in ("certified", "refuted", "inconclusive")
    assert m["h_refuted"] == "inf"
    assert main(["benchmark", "delay", str(d)]) == 0
    assert "(>= cap)" in capsys.readouterr().out
    (tmp_path / "b").mkdir()
    d2 = _design(tmp_path / "b")                   # x' = -x(t-h): a finite bound
    assert main(["benchmark", "delay", str(d2), "--json"]) == 0
    (m,) = json.loads(capsys.readouterr().out)["examples"][0]["methods"]
    assert m["at_cap"] is False and m["outcome"] == "certified"
    assert m["h_certified"] <= m["h_refuted"] and m["h_certified"] <= math.pi / 2


# -- item 6: input checks -------------------------------------------------------------------
GOOD = np.array([[-1.0, 0.0], [0.0, -2.0]])
BAD_SYSTEMS = [
    ([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]], GOOD, r"A has shape \(2, 3\); expected a square matrix"),
    (GOOD, np.eye(3), r"Ad has shape \(3, 3\); expected \(2, 2\) like A"),
    (np.zeros((0, 0)), np.zeros((0, 0)), r"A has shape \(0, 0\); expected a non-empty matrix"),
    ([[np.nan, 0.0], [0.0, -1.0]], GOOD, r"A\[0, 0\] = nan; expected finite numbers"),
    (GOOD, [[0.0, np.inf], [0.0, -1.0]], r"Ad\[0, 1\] = inf; expected finite numbers"),
    (GOOD + 1j, GOOD, r"A has complex entries .*; expected a real matrix"),
    ([1.0, 2.0], GOOD, r"A has shape \(2,\); expected a 2-D matrix"),
    ([["a", "b"], ["c", "d"]], GOOD, r"A has entries of type <U1; expected real numbers"),
    ([[1.0], [2.0, 3.0]], GOOD, r"A = .*; expected a real matrix"),
]


@pytest.mark.parametrize("A, Ad, message", BAD_SYSTEMS)
@pytest.mark.parametrize("call", [
    delay_margin_eig, delay_margin_sweep, exact_margin,
    lambda A, Ad: stability_windows(A, Ad, 10.0),
    lambda A, Ad: spectral_abscissa(A, Ad, 1.0),
    lambda A, Ad: rightmost_roots(A, Ad, 1.0)])
def test_bad_systems(call, A, Ad, message):
    with pytest.raises(ValueError, match=message):
        call(A, Ad)


@pytest.mark.parametrize("call, message", [
    (lambda: spectral_abscissa(GOOD, GOOD, -1.0), r"h = -1.0; expected a delay >= 0 \(s\)"),
    (lambda: spectral_abscissa(GOOD, GOOD, math.nan), r"h = nan; expected a delay >= 0"),
    (lambda: spectral_abscissa(GOOD, GOOD, math.inf), r"h = inf; expected a finite delay"),
    (lambda: spectral_abscissa(GOOD, GOOD, "1"), r"h = '1'; expected a real number"),
    (lambda: rightmost_roots(GOOD, GOOD, 1.0, order=2), r"order = 2; expected an integer >= 4"),
    (lambda: stability_windows(GOOD, GOOD, 0.0), r"h_max = 0.0; expected a positive delay"),
    (lambda: stability_windows(GOOD, GOOD, 1.0, method="x"), r"method = 'x'; expected"),
    (lambda: delay_margin_sweep(GOOD, GOOD, grid=2), r"grid = 2; expected an integer >= 4"),
    (lambda: delay_margin_sweep(GOOD, GOOD, grid=8.5), r"grid = 8.5; expected an integer"),
    (lambda: exact_margin(GOOD, GOOD, rtol=0.0), r"rtol = 0.0; expected a number in \(0, 1\)"),
    (lambda: exact_margin(GOOD, GOOD, cross_check="x"), r"cross_check = 'x'; expected"),
    (lambda: delay_margin_siso(GOOD, [[1.0], [0.0], [0.0]], [[1.0, 0.0]]),
     r"B has shape \(3, 1\); expected \(2, 1\) \(one input\)"),
    (lambda: delay_margin_siso(GOOD, [[1.0], [0.0]], [[1.0, 0.0, 0.0]]),
     r"K has shape \(1, 3\); expected \(1, 2\) \(one input\)"),
    (lambda: delay_margin_siso(GOOD, [[1j], [0.0]], [[1.0, 0.0]]), r"B has complex entries"),
    (lambda: delay_margin_siso(GOOD, [[1.0], [0.0]], [[np.nan, 0.0]]),
     r"K\[0, 0\] = nan; expected finite numbers"),
    (lambda: is_hurwitz([[1.0, 2.0]]), r"M has shape \(1, 2\); expected a square matrix"),
])
def test_bad_arguments(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_no_complex_warning():
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(ValueError, match="complex"):
            delay_margin_eig([[-1.0 + 0j]], [[0.5 + 1e-3j]])
        with pytest.raises(ValueError, match="complex"):
            delay_margin_eig([[-1.0]], [[0.5 + 1e-3j]])


def test_horizon_with_too_many_crossings_is_refused():
    # x' = -1e6 x(t-h) crosses at 1e6 rad/s: 1.6e7 crossing delays below h_max = 100 s
    with pytest.raises(ValueError, match=r"h_max = 100.0; expected a horizon with at most"):
        stability_windows([[0.0]], [[-1e6]], 100.0)
    ((a, b),) = stability_windows([[0.0]], [[-1e6]], 1e-3)
    assert a == 0.0 and relative_difference(b, math.pi / 2 * 1e-6) <= 1e-15


def test_repeated_eigenvalues_cross_together():
    # three identical copies of x' = -x - 2 x(t-h): h* = 2 pi/(3 sqrt 3) (Hayes 1950); the
    # triple crossing moves 6 roots, so no later window can open
    A, Ad = -np.eye(3), -2 * np.eye(3)
    for method in EXACT:
        dm = method(A, Ad)
        assert relative_difference(dm.h, 2 * math.pi / (3 * math.sqrt(3))) <= 1e-12
        assert [c.multiplicity for c in dm.crossings] == [3]
    for method in ("sweep", "kronecker"):
        (w,) = stability_windows(A, Ad, 50.0, method=method)
        assert w[0] == 0.0 and relative_difference(w[1], 2 * math.pi / (3 * math.sqrt(3))) <= 1e-12


@pytest.mark.parametrize("c", [1e-6, 1.0, 1e6])
def test_siso_in_other_time_units(c):
    # x' = -c x(t-h): pi/(2c); the anchor oscillator in units scaled by c: h* / c
    assert relative_difference(delay_margin_siso([[0.0]], [[1.0]], [[-c]]).h,
                               math.pi / 2 / c) <= 1e-12
    A, Ad = oscillator(1.0, 0.5)
    expected = (math.pi / 2) / ((0.5 + math.sqrt(4.25)) / 2) / c
    assert relative_difference(delay_margin_siso(c * A, [[0.0], [c]], [[0.0, -0.5]]).h,
                               expected) <= 1e-12


def test_spectral_abscissa_four_states_long_delays():
    # issue 21 item 3 (a 4-state system at h = 50 was under-resolved at order 40): the
    # oscillator x'' + x = -0.1 x'(t-h) driving two stable states, at seeded h in [40, 60]
    A2, Ad2 = oscillator(1.0, 0.1)
    A, Ad = np.zeros((4, 4)), np.zeros((4, 4))
    A[:2, :2], Ad[:2, :2] = A2, Ad2
    A[2:, 2:] = [[-1.0, 0.5], [0.0, -2.0]]
    A[2:, :2] = [[0.3, -0.2], [0.1, 0.4]]
    Ad[2:, :2] = [[0.5, 0.0], [-0.3, 0.2]]
    windows = stability_windows(A, Ad, 60.0)          # block-triangular: the oscillator's
    assert len(windows) == len(stability_windows(A2, Ad2, 60.0)) >= 5
    assert all(relative_difference(a, b) <= 1e-12 for wa, wb in
               zip(windows, stability_windows(A2, Ad2, 60.0)) for a, b in zip(wa, wb))
    rng = np.random.default_rng(np.random.SeedSequence(50))
    for h in rng.uniform(40.0, 60.0, 6):
        sp = rightmost_roots(A, Ad, h)
        assert (sp.alpha < 0) == any(a < h < b for a, b in windows), (h, sp.order)
