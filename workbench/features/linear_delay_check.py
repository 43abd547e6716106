"""The linear cross-check of a delay bound, for any loop x' = A x + B K x(t - h).

An LMI (Lyapunov-Krasovskii) bound on the input delay is sufficient, not
necessary. This check simulates the linear delayed loop where its exact
answer is known (issue 35): a gain ``K_finite`` with a finite exact delay
margin h* (Chen-Gu-Nett, :func:`workbench.margins.delay_margin_eig`) at
chosen multiples of h* (decay below, growth above), and the design's gain
``K`` at chosen delays far above the bound; each run's envelope ratio
(:func:`workbench.sim.delay.envelope_ratio`) says whether it decays. The
integrator (Heun, :func:`workbench.sim.delay.simulate_linear_dde`) is checked
by step halving on the scalar test problem :data:`TEST_PROBLEM`, whose
method-of-steps solution is exact.

The design's ``[linear_check]`` table (:func:`load_linear_check`)::

    finite_gain = [k1, ..., kn]   # a gain with a finite exact margin on A, B
    factors     = [0.98, 1.05]    # simulate at these multiples of its margin
    far_delays  = [0.1, 1.0]      # s, delays for the design's gain
    periods     = 40.0            # crossing periods simulated

The rendering is :func:`workbench.report.delay_cross_check.delay_cross_check`.

References
----------
J. Chen, G. Gu, C. N. Nett, Systems & Control Letters 26:107-117, 1995.
A. Bellen, M. Zennaro, Numerical Methods for Delay Differential Equations,
Oxford, 2003 (method of steps).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["LinearCheckSpec", "LinearDelayCheck", "MAX_STEPS", "TEST_PROBLEM",
           "linear_delay_check", "load_linear_check"]

#: (a, h, t_end) of the step-halving check x' = -a x(t - h), x = 1 on [-h, 0], over t_end s.
TEST_PROBLEM = (1.0, 0.7, 10.0)
#: Most steps of one far-delay run of the design's gain (three windows).
MAX_STEPS = 2_000_000
#: Steps (s) of the step-halving check.
HALVING_STEPS = (0.1, 0.05, 0.025, 0.0125)


@dataclass(frozen=True)
class LinearCheckSpec:
    """The ``[linear_check]`` table (module docstring)."""

    finite_gain: tuple
    factors: tuple
    far_delays: tuple
    periods: float


def load_linear_check(root) -> LinearCheckSpec:
    """Read and check ``[linear_check]`` of a design (:class:`workbench.reader.Reader`)."""
    lc = root.table("linear_check")
    spec = LinearCheckSpec(tuple(lc.numbers("finite_gain", min_len=2)),
                           lc.numbers("factors", positive=True),
                           lc.numbers("far_delays", positive=True),
                           lc.number("periods", positive=True, hi=200.0))
    lc.finish()
    return spec


@dataclass(frozen=True)
class LinearDelayCheck:
    """The runs of :func:`linear_delay_check`.

    ``finite_margin`` / ``margin``: exact delay margins (``h``, ``omega``) of
    ``K_finite`` / ``K``; ``ratios_finite``: (factor, h, envelope ratio) per
    factor; ``ratios``: (h, envelope ratio) per far delay; ``runs``: the
    SimResult of each factor (for the figure); ``halving``: the
    :class:`~workbench.sim.delay.HalvingRow` of :data:`TEST_PROBLEM`.
    """

    A: np.ndarray
    B: np.ndarray
    K: tuple
    K_finite: tuple
    finite_margin: object
    ratios_finite: tuple
    margin: object
    ratios: tuple
    runs: tuple
    halving: tuple = ()


def linear_delay_check(spec: LinearCheckSpec, A, B, K, x0,
                       max_steps: int = MAX_STEPS) -> LinearDelayCheck:
    """Simulate x' = A x + B K x(t - h) from the constant history ``x0``.

    Parameters
    ----------
    spec : LinearCheckSpec
    A : (n, n) array_like
    B : (n, m) array_like
    K : (n,) sequence
        The design's gain (one input row).
    x0 : (n,) array_like
    max_steps : int, optional
        Most steps of one far-delay run of ``K`` (default :data:`MAX_STEPS`).

    Returns
    -------
    LinearDelayCheck
        The ``K_finite`` runs last ``spec.periods`` crossing periods 2 pi / omega*
        (step min(period, h) / 50); the ``K`` runs three windows of
        max(10 h, 3 / |abscissa of A + B K|) (step min(h, 1 / spectral radius of A) / 5),
        the window cut to ``max_steps`` / 3 steps (a gain whose abscissa is
        0 or nearly 0 would otherwise ask for an unbounded run).
    """
    from ..margins import delay_margin_eig
    from ..sim.delay import envelope_ratio, simulate_linear_dde, step_halving
    A, B = np.asarray(A, float), np.asarray(B, float)
    Bf = B @ np.array([spec.finite_gain])
    fin = delay_margin_eig(A, Bf)
    ratios_f, runs = [], []
    if math.isfinite(fin.h) and fin.h > 0:
        period = 2 * math.pi / fin.omega
        for fac in spec.factors:
            h = fac * fin.h
            r = simulate_linear_dde(A, Bf, h, x0, spec.periods * period, min(period, h) / 50)
            ratios_f.append((fac, h, envelope_ratio(r, period)))
            runs.append(r)
    BK = B @ np.array([K])
    margin = delay_margin_eig(A, BK)
    ratios = []
    rate = max(abs(np.linalg.eigvals(A)).max(), 1.0)
    slow = abs(np.max(np.linalg.eigvals(A + BK).real))
    for h in spec.far_delays:
        step = min(h, 1 / rate) / 5
        window = min(max(10 * h, 3 / slow if slow > 0 else math.inf), max_steps * step / 3)
        r = simulate_linear_dde(A, BK, h, x0, 3 * window, step)
        ratios.append((h, envelope_ratio(r, window)))
    return LinearDelayCheck(A, B, tuple(K), tuple(spec.finite_gain), fin, tuple(ratios_f),
                            margin, tuple(ratios), tuple(runs),
                            step_halving(*TEST_PROBLEM, HALVING_STEPS))
