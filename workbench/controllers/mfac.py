"""Compact-form dynamic-linearisation model-free adaptive control (CFDL-MFAC).

Paper 002, eqs 3-9 (the extracted text lost the formulas; these are the
standard ones of Hou & Jin, the paper's ref [11]). With the pseudo-partial
derivative (PPD) phi(k) of the dynamic linearisation dy(k+1) = phi(k) du(k):

* PPD estimate (minimiser of eq 6)::

      phi(k) = phi(k-1) + eta du(k-1) (dy(k) - phi(k-1) du(k-1)) / (mu + du(k-1)^2)

  reset phi(k) = phi(1) when |phi(k)| <= epsilon, or |du(k-1)| <= epsilon,
  or sign(phi(k)) != sign(phi(1));
* control law (minimiser of eq 8)::

      u(k) = u(k-1) + rho phi(k) (y*(k+1) - y(k)) / (lambda + phi(k)^2)

with 0 < rho, eta <= 1, lambda > 0, mu > 0. Every array operation is
elementwise, so one :class:`MFAC` steps a batch of independent loops (one per
parameter set) at once.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class MFACGains:
    """CFDL-MFAC parameters (scalars or arrays broadcastable to the batch).

    Attributes
    ----------
    lam : float
        lambda > 0, weight on control moves in eq 8 (the most sensitive one).
    rho : float
        Step size of the control law, in (0, 1].
    eta : float
        Step size of the PPD estimate, in (0, 1].
    mu : float
        Weight on PPD changes in eq 6, > 0.
    phi1 : float
        Initial PPD phi(1) (also the reset value).
    epsilon : float
        Reset threshold, > 0.
    """

    lam: float
    rho: float
    eta: float
    mu: float
    phi1: float
    epsilon: float = 1e-5


class MFAC:
    """Sampled CFDL-MFAC for a batch of loops.

    Parameters
    ----------
    gains : MFACGains
    n : int
        Batch size.
    u_min, u_max : float
        Output limits (the stored u(k-1) is the limited one, so du is what
        the plant actually received).
    """

    def __init__(self, gains: MFACGains, n: int = 1, *, u_min: float = -np.inf,
                 u_max: float = np.inf):
        self.g = gains
        shape = (n,)
        self.phi1 = np.broadcast_to(np.asarray(gains.phi1, float), shape).copy()
        self.phi = self.phi1.copy()
        self.u_prev = np.zeros(shape)
        self.du_prev = np.zeros(shape)
        self.y_prev: np.ndarray | None = None
        self.u_min, self.u_max = u_min, u_max
        self.resets = np.zeros(shape, dtype=int)

    def step(self, y: np.ndarray, y_target_next: np.ndarray) -> np.ndarray:
        """One sample: measured output y(k), target y*(k+1) -> u(k)."""
        g = self.g
        y = np.asarray(y, float)
        if self.y_prev is not None:
            dy = y - self.y_prev
            du = self.du_prev
            phi = self.phi + g.eta * du * (dy - self.phi * du) / (g.mu + du * du)
            reset = ((np.abs(phi) <= g.epsilon) | (np.abs(du) <= g.epsilon)
                     | (np.sign(phi) != np.sign(self.phi1)))
            self.phi = np.where(reset, self.phi1, phi)
            self.resets += reset
        u = self.u_prev + g.rho * self.phi * (y_target_next - y) / (g.lam + self.phi ** 2)
        u = np.clip(u, self.u_min, self.u_max)
        self.du_prev = u - self.u_prev
        self.u_prev = u
        self.y_prev = y
        return u


def frozen_ppd_poles(gains: MFACGains, phi: float, Ts: float) -> np.ndarray:
    """Closed-loop poles of the MFAC law with its PPD frozen at ``phi`` on a
    sampled pure integrator y(k+1) = y(k) + Ts u(k) (a train's speed, lag and
    delay neglected).

    The law is then integral action u(k) = u(k-1) + G e(k), G = rho phi /
    (lambda + phi^2), and the loop's characteristic polynomial is
    (z - 1)^2 + G Ts z = z^2 - (2 - G Ts) z + 1. Its roots multiply to 1: for
    0 < G Ts < 4 both lie ON the unit circle — no damping at all; lag and delay
    then make the loop unstable. Returns the two roots (complex).
    """
    G = gains.rho * phi / (gains.lam + phi * phi)
    return np.roots([1.0, -(2.0 - G * Ts), 1.0])
