"""Train platoon of paper 001: point masses with Davis resistance, gradient and
bounded disturbances (eqs 1-6), for leader-follower virtual coupling.

Train i: x_i' = v_i, m_i v_i' = u_i - f_u(v_i) - f_v + w_i(t) + d_i(t), with
f_u = c0 + c1 v + c2 v^2 (the Davis expression of
:mod:`workbench.plants.train002`, here with force coefficients) and
f_v = m g sin(phi). The controller knows only the nominal m, c0, c1, c2; the
true trains differ by seeded factors (their effect is the d(t) of eq 5) and
feel a seeded external force w(t) with |w| <= G_w.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .train002 import davis, gradient_accel

#: Parameters and SI units (checked by the design loader).
PARAMETER_UNITS: dict[str, str] = {"m": "kg", "c0": "N", "c1": "N s/m", "c2": "N s^2/m^2",
                                   "g": "m/s^2"}


@dataclass(frozen=True)
class TrainParams:
    """Mass (kg) and Davis force coefficients (N, N s/m, N s^2/m^2) — scalars
    (nominal) or arrays over the trains (true values); g (m/s^2)."""

    m: np.ndarray | float
    c0: np.ndarray | float
    c1: np.ndarray | float
    c2: np.ndarray | float
    g: float

    def resistance(self, v):
        """f_u (N), eq 2 (with c2 v^2: the paper's c2 x''^2 is a typo)."""
        return davis(v, self.c0, self.c1, self.c2)

    def grade_force(self, i):
        """f_v = m g sin(phi) (N) for gradient i = tan(phi), eq 3."""
        return self.m * gradient_accel(i, self.g)


def perturbed(nominal: TrainParams, n: int, rng: np.random.Generator, *, mass_spread: float,
              davis_spread: float) -> TrainParams:
    """True parameters of ``n`` trains: each nominal value times (1 + delta),
    delta uniform in +/- spread (seeded)."""
    f = lambda spread: 1.0 + rng.uniform(-spread, spread, n)
    return TrainParams(nominal.m * f(mass_spread), nominal.c0 * f(davis_spread),
                       nominal.c1 * f(davis_spread), nominal.c2 * f(davis_spread), nominal.g)


def external_force(n: int, steps: int, T: float, bound: float, hold: float,
                   rng: np.random.Generator) -> np.ndarray:
    """Bounded external force w(t) (N), shape (steps, n): piecewise linear
    between knots every ``hold`` seconds drawn uniformly in [-bound, bound]
    (so |w| <= bound and w is continuous)."""
    n_knots = int(np.ceil(steps * T / hold)) + 2
    knots = rng.uniform(-bound, bound, (n_knots, n))
    tk = np.arange(n_knots) * hold
    t = np.arange(steps) * T
    return np.stack([np.interp(t, tk, knots[:, i]) for i in range(n)], axis=1)
