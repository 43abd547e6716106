"""Scale-free synthesis to requirements (issue 31, item 4 of the brief): the
synthesis coordinates follow a diagonal state scaling (Gramian
normalisation), so the gain and its certified bound do not move."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.lmi.requirements import Loop
from workbench.lmi.requirements_synthesis import synthesize_requirements
from workbench.lmi.scaling import gramian_scaling

B = np.array([[0.0], [1.0]])
#: (A, B, delay): pendulum-type (x'' = x + u), double integrator (reducible A:
#: balancing from A alone cannot scale it), a 3-state lagged loop.
SYSTEMS = [
    (np.array([[0.0, 1.0], [1.0, 0.0]]), B, (0.0, 0.3)),
    (np.array([[0.0, 1.0], [0.0, 0.0]]), B, (0.0, 0.3)),
    (np.array([[0.0, 1.0, 0.0], [0.0, -0.1, 1.0], [0.0, 0.0, -1.5]]),
     np.array([[0.0], [0.0], [1.5]]), (0.1, 0.4)),
]
SCALES = [1e-3, 1e3, "mixed"]


def _scaling(n: int, s) -> np.ndarray:
    if s == "mixed":
        return np.diag(np.geomspace(1e-3, 1e3, n))
    return np.diag([s] + [1.0] * (n - 1))


def test_gramian_scaling_follows_a_diagonal_similarity():
    rng = np.random.default_rng(np.random.SeedSequence(31))
    for _ in range(20):
        n = int(rng.integers(2, 5))
        A = rng.normal(size=(n, n))
        Bm = rng.normal(size=(n, 1))
        d = 10.0 ** rng.uniform(-3, 3, n)
        T = gramian_scaling([(A, Bm)], 0.5)
        Th = gramian_scaling([(A / d[:, None] * d, Bm / d[:, None])], 0.5)
        # T^ = D^{-1} T: the scaled loop is normalised to the same matrix
        np.testing.assert_allclose(np.diag(Th) * d, np.diag(T), rtol=1e-9)


def _design(A, Bm, delay):
    # mu = 0: the descriptor certificates (fast); the synthesis is the same LMI.
    # No exact check here (its spectrum collocation is not the object of this test).
    return synthesize_requirements(Loop(((A, Bm),)), objective="decay", H=delay[1],
                                   h_min=delay[0], mu=0.0)


def _check(A, Bm, delay, s):
    r = _design(A, Bm, delay)
    assert r.certificate is not None
    D = _scaling(A.shape[0], s)
    Di = np.linalg.inv(D)
    rs = _design(Di @ A @ D, Di @ Bm, delay)
    assert r.K is not None and rs.K is not None
    # the gain in the original coordinates is the same to its printed digits
    np.testing.assert_allclose(rs.K @ Di, r.K, rtol=1e-3)
    a, a_s = r.certificate.alpha_certified, rs.certificate.alpha_certified
    assert a is not None and abs(a_s - a) <= 1e-3 * a
    g, g_s = r.optimum.h_certified, rs.optimum.h_certified
    assert abs(g_s - g) <= 1e-3 * g


def test_pendulum_synthesis_is_scale_free():
    _check(*SYSTEMS[0], "mixed")


@pytest.mark.slow
@pytest.mark.parametrize("system", range(len(SYSTEMS)))
@pytest.mark.parametrize("s", SCALES)
def test_synthesised_certified_bound_is_scale_free(system, s):
    _check(*SYSTEMS[system], s)
