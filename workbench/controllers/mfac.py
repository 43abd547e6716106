"""Compact-form dynamic-linearisation model-free adaptive control (CFDL-MFAC).

Paper 002, eqs 4-9. The extracted text lost the formulas but kept their
criteria and their roles: eq 4 is the data model dy(k+1) = phi(k) du(k) with
the pseudo-partial derivative (PPD) phi(k); eq 6 the control criterion
|y*(k+1) - y(k+1)|^2 + lambda |u(k) - u(k-1)|^2, whose minimiser is the
control law eq 7 (the paper's sentence "eq 8 is the control law" is a slip
for eq 7); eq 8 the estimation criterion |dy(k) - phi(k) du(k-1)|^2 +
mu |phi(k) - phi(k-1)|^2 (extracted as ``y*(k) - y(k-1)``: an I/O estimate
needs the measured increment, as in Hou & Jin), whose minimiser with the
step eta and the reset threshold epsilon is eq 9. These are the standard
CFDL-MFAC scheme of Hou and Jin, the paper's ref [11]:

* PPD estimate, eq 9 (:func:`ppd_update`)::

      phi(k) = phi(k-1) + eta du(k-1) (dy(k) - phi(k-1) du(k-1)) / (mu + du(k-1)^2)

* reset, eq 9 continued (:func:`reset_conditions`): phi(k) = phi(1) if
  |phi(k)| <= epsilon, or |du(k-1)| <= epsilon, or sign(phi(k)) != sign(phi(1));
* control law, eq 7::

      u(k) = u(k-1) + rho phi(k) (y*(k+1) - y(k)) / (lambda + phi(k)^2)

with 0 < rho, eta <= 1, lambda > 0, mu > 0. The command is limited to
[u_min, u_max] (an actuator limit, ours): u(k-1) and du(k-1) are what the
plant received, so a command held at a limit has du = 0 and triggers the
second reset condition. Every array operation is elementwise, so one
:class:`MFAC` steps a batch of independent loops (one per parameter set).

References
----------
.. [002] ATO target speed curve tracking with MFAC, Nanning Line 1, eqs 4-9.
.. [HJ11] Z. Hou, S. Jin, "A novel data-driven control approach for a class of
   discrete-time nonlinear systems", IEEE Trans. Control Syst. Technol. 19(6),
   1549-1558, 2011 (the CFDL-MFAC scheme and its reset rule).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The three reset conditions of eq 9, in the order the rule lists them.
RESET_CONDITIONS = ("small_phi", "small_du", "sign_change")


@dataclass(frozen=True)
class MFACGains:
    """CFDL-MFAC parameters (scalars or arrays broadcastable to the batch).

    Attributes
    ----------
    lam : float
        lambda > 0, weight on control moves in eq 6.
    rho : float
        Step size of the control law, in (0, 1].
    eta : float
        Step size of the PPD estimate, in (0, 1].
    mu : float
        Weight on PPD changes in eq 8, > 0.
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


def ppd_update(phi_prev, du, dy, eta, mu):
    """The PPD estimate of eq 9 before the reset (elementwise).

    Parameters
    ----------
    phi_prev : array_like
        phi(k-1).
    du : array_like
        du(k-1) = u(k-1) - u(k-2).
    dy : array_like
        dy(k) = y(k) - y(k-1).
    eta, mu : array_like
        Step size and weight of eq 8.
    """
    return phi_prev + eta * du * (dy - phi_prev * du) / (mu + du * du)


def reset_conditions(phi, du, phi1, epsilon) -> dict[str, np.ndarray]:
    """Each reset condition of eq 9 on the fresh estimate ``phi`` (elementwise):
    |phi| <= epsilon, |du(k-1)| <= epsilon, sign(phi) != sign(phi(1))."""
    phi, du = np.asarray(phi, float), np.asarray(du, float)
    return {"small_phi": np.abs(phi) <= epsilon, "small_du": np.abs(du) <= epsilon,
            "sign_change": np.sign(phi) != np.sign(phi1)}


class MFAC:
    """Sampled CFDL-MFAC for a batch of loops, with a record of its estimates.

    Parameters
    ----------
    gains : MFACGains
    n : int
        Batch size.
    u_min, u_max : float
        Output limits (the stored u(k-1) is the limited one, so du is what
        the plant actually received).

    Attributes
    ----------
    resets : numpy.ndarray
        Number of resets per loop.
    history : dict[str, list]
        Per sample from k = 2 on (the first sample has no estimate): ``"phi"``
        the estimate in use, ``"reset"`` and one boolean per condition of
        :data:`RESET_CONDITIONS`, each an array over the batch.
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
        self.history: dict[str, list] = {k: [] for k in ("phi", "reset", *RESET_CONDITIONS)}

    def step(self, y: np.ndarray, y_target_next: np.ndarray) -> np.ndarray:
        """One sample: measured output y(k), target y*(k+1) -> u(k)."""
        g = self.g
        y = np.asarray(y, float)
        if self.y_prev is not None:
            du = self.du_prev
            phi = ppd_update(self.phi, du, y - self.y_prev, g.eta, g.mu)
            cond = reset_conditions(phi, du, self.phi1, g.epsilon)
            reset = cond["small_phi"] | cond["small_du"] | cond["sign_change"]
            self.phi = np.where(reset, self.phi1, phi)
            self.resets += reset
            for k, val in (("phi", self.phi), ("reset", reset), *cond.items()):
                self.history[k].append(val)
        u = self.u_prev + g.rho * self.phi * (y_target_next - y) / (g.lam + self.phi ** 2)
        u = np.clip(u, self.u_min, self.u_max)
        self.du_prev = u - self.u_prev
        self.u_prev = u
        self.y_prev = y
        return u

    def record(self, name: str) -> np.ndarray:
        """A history entry as an array of shape (n, samples)."""
        rows = self.history[name]
        return np.array(rows).T if rows else np.zeros((len(self.phi), 0))


def frozen_ppd_poles(gains: MFACGains, phi: float, Ts: float) -> np.ndarray:
    """Closed-loop poles of the MFAC law with its PPD frozen at ``phi`` on a
    sampled pure integrator y(k+1) = y(k) + Ts u(k) (a train's speed, lag and
    delay neglected).

    The law is then integral action u(k) = u(k-1) + G e(k), G = rho phi /
    (lambda + phi^2), and the loop's characteristic polynomial is
    (z - 1)^2 + G Ts z = z^2 - (2 - G Ts) z + 1. Its roots multiply to 1: for
    0 < G Ts < 4 both lie ON the unit circle — no damping at all — and
    G Ts = 4 is a double pole at z = -1. Returns the two roots (complex).
    """
    G = gains.rho * phi / (gains.lam + phi * phi)
    return np.roots([1.0, -(2.0 - G * Ts), 1.0])


def frozen_loop_poles(G: float, num, den) -> np.ndarray:
    """Poles of the eq 7 law with a frozen PPD, u(k) = u(k-1) + G (y*(k+1) - y(k)),
    around a sampled plant y = (num(z) / den(z)) u (polynomials in z, highest
    power first, den monic or not): the roots of (z - 1) den(z) + G z num(z).

    Parameters
    ----------
    G : float
        rho phi / (lambda + phi^2) ((command) per (output)).
    num, den : array_like
        Plant numerator and denominator; deg num < deg den.
    """
    num, den = np.atleast_1d(np.asarray(num, float)), np.atleast_1d(np.asarray(den, float))
    char = np.polyadd(np.polymul([1.0, -1.0], den), G * np.polymul([1.0, 0.0], num))
    return np.roots(np.trim_zeros(char, "f"))
