"""Sliding-mode tracking law of paper 000 (eq 22 with a fixed mass estimate).

For the single-mass train theta x2' = u + Delta (eqs 13-14) tracking a target
position x_d(t), with e = x1 - x_d and the sliding variable z = c e + e'
(eq 18), the law is

    u = theta_hat (x_d'' - c e') - k_s z - eta s(z)                 (eq 22)

with x_d'' (the paper prints x_d'; SEEDS.md errata) and s(z) = sgn(z), or
sat(z / phi) with a boundary layer of width phi against chattering. Here u is
the force per unit *nominal* mass (m/s^2) and theta the true mass over the
nominal mass (dimensionless), so that the same gains serve any train; the
brake command (a demanded deceleration) is -u.

References
----------
.. [000] Yu, Zhang, Zhang, Urban Rapid Rail Transit 37(4), 2024, eqs 13-22.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def switching(z, phi: float) -> np.ndarray:
    """sgn(z) (phi = 0) or the boundary-layer saturation sat(z / phi) (phi > 0)."""
    z = np.asarray(z, float)
    return np.sign(z) if phi == 0 else np.clip(z / phi, -1.0, 1.0)


@dataclass(frozen=True)
class SlidingGains:
    """Gains of eq 22.

    Attributes
    ----------
    c : float
        Sliding-surface slope (1/s), z = c e + e'.
    k_s : float
        Reaching gain (1/s), > 0.
    eta : float
        Robust gain (m/s^2), must exceed the disturbance bound D / m_nominal.
    phi : float
        Boundary-layer width (m/s); 0 = the discontinuous sgn of the paper.
    """

    c: float
    k_s: float
    eta: float
    phi: float = 0.0

    def __post_init__(self):
        if not (self.c > 0 and self.k_s > 0 and self.eta >= 0 and self.phi >= 0):
            raise ValueError(f"sliding gains {self}: expected c > 0, k_s > 0, eta >= 0, phi >= 0")


def sliding_variable(e, de, c: float) -> np.ndarray:
    """z = c e + e' (eq 18); e in m, e' in m/s."""
    return c * np.asarray(e) + np.asarray(de)


def sliding_law(theta_hat, e, de, xdd, g: SlidingGains) -> np.ndarray:
    """u of eq 22 (m/s^2 per unit nominal mass); arrays broadcast."""
    z = sliding_variable(e, de, g.c)
    return theta_hat * (xdd - g.c * de) - g.k_s * z - g.eta * switching(z, g.phi)


class SlidingModeController:
    """Eq 22 with the fixed estimate theta_hat = theta0 (the paper's SMC)."""

    def __init__(self, gains: SlidingGains, theta0: float = 1.0):
        self.gains, self.theta0 = gains, float(theta0)

    def step(self, e, de, xdd) -> np.ndarray:
        """Control u (m/s^2) for position error e (m), speed error de (m/s),
        target acceleration xdd (m/s^2)."""
        return sliding_law(self.theta0, e, de, xdd, self.gains)
