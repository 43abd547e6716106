"""Issue 31 item 4: certified delay bounds do not depend on the state coordinates
or the time unit, and the Bessel-Legendre hierarchy is monotone in N.

Every analysis LMI is built on the loop balanced by an exact power-of-two
Osborne scaling of |A| + |A_d| (:func:`workbench.lmi.scaling.balance_loop`),
solved in the canonical modal coordinates of :mod:`workbench.lmi.coordinates`
(re-checked against the caller's own matrices), its search starts from the
similarity-invariant time scale 1 / (rho(A) + rho(A_d)), and its blocks are
written in the time unit 4 / (rho(A) + rho(A_d)).
"""
from __future__ import annotations

import glob
import math
import tomllib

import numpy as np
import pytest

import workbench
from workbench.lmi.analysis import BesselLegendreLMI, certified_delay
from workbench.lmi.hierarchy import bessel_legendre_auto
from workbench.margins import exact_margin, stability_windows

#: Largest relative change of a certified bound under a change of coordinates (issue 31).
RTOL = 1e-3


def emu_loop():
    """An EMU speed loop with the gain of issue 31, K = [-47.45, -0.117] (our
    reconstruction: the issue does not give the plant). States: speed deviation
    (m/s), traction force deviation (kN); v' = -0.01 v + F / 214 (214 t with
    rotating masses, resistance 0.01 1/s), F' = (u - F) / 0.5 (0.5 s traction
    lag). Exact delay margin of the loop: 7.2757 s (issue: 7.29 s)."""
    A = np.array([[-0.01, 1 / 214.0], [0.0, -2.0]])
    B = np.array([[0.0], [2.0]])
    return A, B @ np.array([[-47.45, -0.117]])


def benchmark_systems():
    out = []
    for f in sorted(glob.glob("designs/benchmarks/*.toml")):
        with open(f, "rb") as fh:
            d = tomllib.load(fh)["example"]
        out.append((d["name"], np.atleast_2d(np.array(d["A"], float)),
                    np.atleast_2d(np.array(d["Ad"], float))))
    return out


def random_systems(count: int, seed: int = 31):
    """Derandomised 2x2 and 3x3 loops, stable at h = 0 with a finite exact
    margin (for a loop stable at every delay the criterion's bound is where
    its relative margin decays below 1e-7 at large h, not a delay of the
    system), and loops with a stability window that does not start at 0."""
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    out, windows = [], 0
    while len(out) < count:
        n = int(rng.integers(2, 4))
        A, Ad = rng.normal(size=(n, n)), 0.7 * rng.normal(size=(n, n))
        w = stability_windows(A, Ad, 20.0)
        if not w or math.isinf(w[0][1]):
            continue
        if w[0][0] > 0:
            windows += 1
        elif len(out) - windows >= count - 3:       # keep room for three window systems
            continue
        out.append((f"rand{len(out)}", A, Ad))
    return out


def _bound(A, Ad, guess):
    return certified_delay(BesselLegendreLMI(A, Ad, 1), rel_tol=1e-5, h_hi=50.0,
                           guess=guess).h_certified


def _guess(A, Ad):
    """Inside the first exact window when it does not start at 0 (as the benchmark)."""
    w = stability_windows(A, Ad, 50.0)
    return math.sqrt(w[0][0] * w[0][1]) if w and w[0][0] > 0 else None




def _cases():
    systems = benchmark_systems() + [("emu", *emu_loop())] + random_systems(15)
    systems = [s for s in systems if s[0] != "scalar-delay-independent"]  # no finite bound
    return systems


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["diagonal", "similarity"])
def test_bounds_do_not_depend_on_state_coordinates(kind):
    rng = np.random.default_rng(np.random.SeedSequence(3104))
    cases = _cases()
    assert len(cases) >= 20 and sum(_guess(A, Ad) is not None for _, A, Ad in cases) >= 3
    bad, compared, worst = {}, 0, 0.0
    for name, A, Ad in cases:
        n = A.shape[0]
        if kind == "diagonal":
            T = np.diag(10.0 ** rng.uniform(-4, 4, size=n))
        else:
            Q1, _ = np.linalg.qr(rng.normal(size=(n, n)))
            Q2, _ = np.linalg.qr(rng.normal(size=(n, n)))
            T = Q1 @ np.diag(np.geomspace(1, rng.uniform(2, 100), n)) @ Q2
            assert np.linalg.cond(T) <= 100 * (1 + 1e-9)
        Ti = np.linalg.inv(T)
        g = _guess(A, Ad)
        h0, h1 = _bound(A, Ad, g), _bound(Ti @ A @ T, Ti @ Ad @ T, g)
        if h0 == 0:                  # order 1 certifies no point of this window
            assert h1 == 0, name
            continue
        compared += 1
        worst = max(worst, abs(h1 - h0) / h0)
        if abs(h1 - h0) > RTOL * h0:
            bad[name] = abs(h1 - h0) / h0
    print(f"{kind}: {compared} systems, largest relative change {worst:.2e}")
    assert compared >= 20
    assert not bad, bad


def test_diagonal_scaling_fast():
    """Two loops whose bound moved by up to 12x under a state scaling before balancing."""
    for A, Ad in (emu_loop(), (np.array([[0.0, 1.0], [-2.0, 0.1]]),
                               np.array([[0.0, 0.0], [1.0, 0.0]]))):
        g = _guess(A, Ad)
        h0 = _bound(A, Ad, g)
        for d in (1e-4, 3.7e2, 1e4):
            T = np.diag([1.0, d])
            Ti = np.diag([1.0, 1 / d])
            assert abs(_bound(Ti @ A @ T, Ti @ Ad @ T, g) - h0) <= RTOL * h0


@pytest.mark.parametrize("name", ["classic-2x2", "oscillator", "pocket-2x2"])
def test_time_scaling_brackets_overlap(name):
    _, A, Ad = next(s for s in benchmark_systems() if s[0] == name)
    rng = np.random.default_rng(np.random.SeedSequence(77))
    g = _guess(A, Ad)
    los, his = [], []
    for c in [1.0, 1e-4, 1e4] + list(10.0 ** rng.uniform(-4, 4, size=2)):
        br = certified_delay(BesselLegendreLMI(c * A, c * Ad, 2), rel_tol=1e-4,
                             guess=None if g is None else g / c).bracket
        assert br.h_certified > 0
        los.append(br.h_certified * c)
        his.append(br.h_refuted * c)
    assert max(los) <= min(his), (los, his)


def test_hierarchy_monotone_and_tight_on_the_emu_loop():
    """Issue 31: N = 0..3 gave 0.0660 / 0.0481 / 0.0456 / 0.0444 s on the issue's
    EMU loop (exact 7.29 s); on our reconstruction main gave 1.032 / 0.923 /
    0.951 / 0.951 s against 7.2757 s. Balanced, the hierarchy is monotone and
    order 2 is within 0.1 % of the exact margin."""
    A, Ad = emu_loop()
    h_star = exact_margin(A, Ad).h
    assert h_star == pytest.approx(7.2757, abs=1e-4)
    hs = [workbench.delay_bound(A, Ad=Ad, method="bessel-legendre", N=N, h_max=100,
                                rel_tol=1e-4).h_certified for N in range(4)]
    assert all(b >= a for a, b in zip(hs, hs[1:])), hs
    assert hs[-1] < h_star and hs[2] >= 0.999 * h_star, (hs, h_star)


# issue 36: the first member runs in `make test`; the rest of the random family in `make test-full`
@pytest.mark.parametrize("k", [0] + [pytest.param(k, marks=pytest.mark.slow) for k in (1, 2)])
def test_hierarchy_monotone_random(k):
    rng = np.random.default_rng(np.random.SeedSequence([311, k]))
    while True:
        A, Ad = rng.normal(size=(3, 3)), 0.7 * rng.normal(size=(3, 3))
        if np.max(np.linalg.eigvals(A + Ad).real) < -0.05:
            break
    auto = bessel_legendre_auto(A, Ad, math.inf, N_max=3, N_through=3, rel_tol=1e-4,
                                guess=_guess(A, Ad))
    hs = [b.h_certified for b in auto.bounds]
    assert all(b >= a for a, b in zip(hs, hs[1:])), hs
    assert hs[0] > 0


def test_interval_rows_monotone():
    from dataclasses import dataclass

    from workbench.benchmark_windows import monotone

    @dataclass(frozen=True)
    class Row:
        interval: tuple | None
        intervals: tuple = ()
        interval_sound: bool | None = None
        interval_ratio: float | None = None
    prev = Row((0.0, 0.162282), ((0.0, 0.162282),), True, 0.9)
    shrunk = Row((0.0, 0.162251), ((0.0, 0.162251),), True, 0.8)
    assert monotone(prev, shrunk) == Row(prev.interval, prev.intervals, True, 0.9)
    grown = Row((0.0, 0.2), ((0.0, 0.2),), True, 0.95)
    assert monotone(prev, grown) is grown
    assert monotone(None, shrunk) is shrunk
