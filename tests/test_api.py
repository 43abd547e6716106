"""Python API (workbench/api.py): delay_bound and simulate_delay on python-control objects."""
from __future__ import annotations

import json
import math
import subprocess
import sys

import control
import numpy as np
import pytest

import workbench

# x1' = x2, x2' = 2 x1 - x2 + u(t - h): open-loop unstable (eigenvalues 1, -2).
UNSTABLE = control.ss([[0, 1], [2, -1]], [[0], [1]], [[1, 0]], [[0]])


def test_import_is_light():
    """``import workbench`` loads no solver, symbolic or control library."""
    code = ("import sys, workbench; heavy = [m for m in ('cvxpy', 'sympy', 'control', "
            "'scipy', 'matplotlib') if m in sys.modules]; print(heavy)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == "[]"


def test_lazy_names():
    assert callable(workbench.delay_bound) and callable(workbench.simulate_delay)
    assert "delay_bound" in dir(workbench)
    with pytest.raises(AttributeError):
        workbench.no_such_name


def test_analysis_anchor_pi_over_2():
    """x' = -x(t - h): exact margin pi/2 (analytic anchor); the Bessel-Legendre
    bracket of order 2 contains it to its width and the certificate re-checks."""
    r = workbench.delay_bound([[0.0]], Ad=[[-1.0]], method="bessel-legendre", N=2)
    assert r.status == "certified" and r.recheck_passed
    assert r.h_certified <= math.pi / 2 <= r.h_refuted * (1 + 1e-9) or \
        r.h_certified <= math.pi / 2 * (1 + 1e-3)
    assert r.h_certified == pytest.approx(math.pi / 2, rel=2e-3)
    assert r.exact_margin == pytest.approx(math.pi / 2, rel=1e-9)
    assert r.windows[0][0] == 0 and r.windows[0][1] == pytest.approx(math.pi / 2, rel=1e-9)
    assert r.K is None and r.certificate_kind == "at h"


@pytest.fixture(scope="module")
def bl3():
    return workbench.delay_bound(UNSTABLE, method="bessel-legendre", N=3)


def test_synthesis_on_statespace(bl3):
    r = bl3
    assert r.status == "certified" and r.recheck_passed and r.K.shape == (1, 2)
    # the certificate is sound: never above the exact margin of the loop it certifies
    assert 0 < r.h_certified <= r.exact_margin
    # and the delay-free loop is stable (A + BK Hurwitz)
    assert np.max(np.linalg.eigvals(r.A + r.Ad).real) < 0
    assert r.exact_agreement == "agree"


def test_result_renders_and_serialises(bl3):
    md = bl3._repr_markdown_()
    assert "bessel-legendre (N = 3)" in md and "certified" in md and "exact margin" in md
    assert isinstance(bl3.to_json(), str) and isinstance(bl3.to_dict(), dict)
    js = json.loads(bl3.to_json())
    assert js == json.loads(json.dumps(bl3.to_dict()))
    assert js["K"] == bl3.K.tolist() and js["N"] == 3 and js["recheck_passed"] is True


def test_arrays_and_free_weighting_003():
    A, B = UNSTABLE.A, UNSTABLE.B
    r = workbench.delay_bound(A, B, method="free-weighting-003", eps=(0.35,), h_max=5.0)
    assert r.certificate_kind == "every delay in [0, h]"
    assert r.status == "certified" and 0 < r.h_certified <= r.exact_margin
    assert r.recheck_passed and set(r.recheck) >= {"eq54", "eq59", "L_pos"}


def test_simulate_delay_returns_time_response(bl3):
    resp = workbench.simulate_delay(UNSTABLE, bl3.K, h=0.5, x0=[1, 0], t_end=40, dt=0.01)
    assert isinstance(resp, control.TimeResponseData)
    assert resp.states.shape == (2, 4001) and resp.inputs.shape == (1, 4001)
    x = np.asarray(resp.states)
    # 0.5 s < h*: decays (slowly: A + BK has a slow eigenvalue near -0.0094 1/s)
    assert np.linalg.norm(x[:, -1]) < np.linalg.norm(x[:, 2000]) < np.max(np.abs(x[0]))
    np.testing.assert_allclose(np.asarray(resp.inputs)[0, 60:], (bl3.K @ x)[0, 10:-50],
                               rtol=1e-12, atol=1e-12)     # u(t - h) = K x(t - h)
    # beyond the exact margin the same loop grows
    bad = workbench.simulate_delay(UNSTABLE, bl3.K, h=1.2 * bl3.exact_margin, x0=[1, 0],
                                   t_end=40, dt=0.01)
    assert np.max(np.abs(np.asarray(bad.states)[:, -1])) > 1.0


@pytest.mark.parametrize("call, word", [
    (lambda: workbench.delay_bound([[0, 1], [2, -1]], [[0], [1], [2]]), "shape"),
    (lambda: workbench.delay_bound([[0, 1]], [[1]]), "square"),
    (lambda: workbench.delay_bound([[np.nan]], [[1]]), "non-finite"),
    (lambda: workbench.delay_bound([[1j]], [[1]]), "complex"),
    (lambda: workbench.delay_bound([["a"]], [[1]]), "real numeric"),
    (lambda: workbench.delay_bound([[0.0]]), "exactly one of B"),
    (lambda: workbench.delay_bound([[0.0]], [[1.0]], Ad=[[1.0]]), "exactly one of B"),
    (lambda: workbench.delay_bound([[0.0]], [[1.0]], method="jensen"), "method"),
    (lambda: workbench.delay_bound([[0.0]], Ad=[[-1.0]], method="free-weighting-003"), "method"),
    (lambda: workbench.delay_bound([[0.0]], [[1.0]], N=-1), "N = -1"),
    (lambda: workbench.delay_bound([[0.0]], [[1.0]], h_max=float("inf")), "h_max"),
    (lambda: workbench.delay_bound(control.ss([[0.5]], [[1]], [[1]], [[0]], 0.1)), "continuous"),
    (lambda: workbench.simulate_delay(UNSTABLE, [[1, 2, 3]], h=0.1, x0=[0, 0], t_end=1),
     "shape"),
    (lambda: workbench.simulate_delay(UNSTABLE, [[1, 2]], h=-1.0, x0=[0, 0], t_end=1), "h = -1"),
    (lambda: workbench.simulate_delay(UNSTABLE, [[1, 2]], h=0.1, x0=[0], t_end=1), "x0"),
])
def test_bad_input_is_a_value_error(call, word):
    with pytest.raises(ValueError, match=word):
        call()
