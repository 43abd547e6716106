"""Sliding-mode adaptive robust control (SMARC) of paper 000, eqs 22, 26-27.

The sliding law of :mod:`workbench.controllers.smc` with the mass estimate
adapted by the projected gradient law

    theta_hat' = Proj(-lambda z (x_d'' - c e'))                     (eq 26)
    Proj(s) = 0 if theta_hat >= theta_max and s > 0,
              0 if theta_hat <= theta_min and s < 0, else s          (eq 27)

With the corrected Lyapunov function V = theta z^2 / 2 + theta_tilde^2 /
(2 lambda) (the paper's eq 19 prints theta_tilde z^2) this gives
V' <= -k_s z^2 for |Delta| <= D < eta. Eq 27 prints strict inequalities; we
use >= / <= and also clip after each Euler step of the discrete update, so
theta_hat never leaves [theta_min, theta_max].

References
----------
.. [000] Yu, Zhang, Zhang, Urban Rapid Rail Transit 37(4), 2024, eqs 19-27.
"""
from __future__ import annotations

import numpy as np

from .smc import SlidingGains, sliding_law, sliding_variable


def projection(s, theta_hat, theta_min: float, theta_max: float) -> np.ndarray:
    """Proj of eq 27 (with non-strict bounds); arrays broadcast."""
    s = np.asarray(s, float)
    block = ((theta_hat >= theta_max) & (s > 0)) | ((theta_hat <= theta_min) & (s < 0))
    return np.where(block, 0.0, s)


class AdaptiveSlidingModeController:
    """SMARC: eq 22 with theta_hat adapted by eqs 26-27 (vectorised over runs).

    Parameters
    ----------
    gains : SlidingGains
    lam : float
        Adaptation gain lambda (1 / m^2 in the per-unit form), > 0.
    theta_min, theta_max : float
        Bounds of the per-unit mass (assumption 1, eq 15).
    theta0 : float or ndarray
        Initial estimate.
    dt : float
        Update period (s) of the Euler step of eq 26.
    """

    def __init__(self, gains: SlidingGains, *, lam: float, theta_min: float,
                 theta_max: float, theta0=1.0, dt: float):
        if not (lam > 0 and 0 < theta_min < theta_max and dt > 0):
            raise ValueError("expected lam > 0, 0 < theta_min < theta_max, dt > 0")
        self.gains, self.lam, self.dt = gains, float(lam), float(dt)
        self.theta_min, self.theta_max = float(theta_min), float(theta_max)
        self.theta_hat = np.clip(np.asarray(theta0, float), theta_min, theta_max)

    def step(self, e, de, xdd, *, adapt=True) -> np.ndarray:
        """Control u (m/s^2) of eq 22, then one update of eq 26 where ``adapt``."""
        g = self.gains
        u = sliding_law(self.theta_hat, e, de, xdd, g)
        z = sliding_variable(e, de, g.c)
        s = projection(-self.lam * z * (xdd - g.c * de), self.theta_hat,
                       self.theta_min, self.theta_max)
        new = np.clip(self.theta_hat + self.dt * s, self.theta_min, self.theta_max)
        self.theta_hat = np.where(adapt, new, self.theta_hat)
        return u
