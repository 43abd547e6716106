"""Damping of the linearised PID loops of the stopping studies, and a
deterministic tuner on it.

A PID "does not oscillate" here when the dominant characteristic roots of its
linearised loop, with the brake's dead time, are well damped: every root
whose real part is at least twice the spectral abscissa alpha (the modes that
decay at most twice as slowly as the slowest one) has damping ratio
zeta = -Re s / |s| >= ``zeta_min`` (0.7 in the designs). The roots are the
exact ones of the delay equation x' = A x + A_d x(t - h)
(:func:`workbench.margins.rightmost_roots`: collocation, Newton-polished;
no Pade approximation), h the dead time plus the sample-and-hold delay.

Two loops (deviations from a steady braking, kappa = 1, resistance slope
neglected):

* :func:`speed_loop` — paper 000's speed PID with the target deceleration as
  feed-forward: e = v - v_d, command c = kp e + ki int e + kd e', electric
  brake b' = (c(t - h) - b) / T2, v' = -P1 b. States (e, b, int e).
* :func:`deceleration_loop` — paper 004's deceleration PID: the achieved
  deceleration b' = (P1 c(t - h) - b) / T2 is measured through a first-order
  filter f' = (b - f) / tau, e = a_req - f, c = kp e + ki int e. States
  (b, f, int e).

:func:`tune_pid` searches a fixed log-spaced (kp, ki) grid (kd = 0), then
refines it around its best point, for the largest decay rate -alpha subject
to zeta >= zeta_min: deterministic, no random numbers.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..margins import rightmost_roots


def speed_loop(kp: float, ki: float, kd: float, *, P1: float, T2: float):
    """(A, A_d) of the linearised speed PID loop of paper 000 (see module)."""
    A = np.array([[0.0, -P1, 0.0], [0.0, -1.0 / T2, 0.0], [1.0, 0.0, 0.0]])
    Ad = np.array([[0.0, 0.0, 0.0], [kp / T2, -kd * P1 / T2, ki / T2], [0.0, 0.0, 0.0]])
    return A, Ad


def deceleration_loop(kp: float, ki: float, *, P1: float, T2: float, tau: float):
    """(A, A_d) of the linearised deceleration PID loop of paper 004 (see module)."""
    A = np.array([[-1.0 / T2, 0.0, 0.0], [1.0 / tau, -1.0 / tau, 0.0], [0.0, -1.0, 0.0]])
    Ad = np.array([[0.0, -P1 * kp / T2, P1 * ki / T2], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    return A, Ad


@dataclass(frozen=True)
class Damping:
    """Dominant roots of a loop.

    Attributes
    ----------
    alpha : float
        Spectral abscissa (1/s); < 0 iff the loop is stable.
    zeta : float
        Smallest damping ratio among the roots with Re s >= 2 alpha (-1 when
        the loop is not stable).
    root : complex
        The least damped of those roots (1/s), upper half plane.
    """

    alpha: float
    zeta: float
    root: complex

    @property
    def period(self) -> float:
        """Period (s) of the least damped root; inf when it is real."""
        return 2 * np.pi / abs(self.root.imag) if self.root.imag else np.inf


def damping(A, Ad, h: float) -> Damping:
    """:class:`Damping` of x' = A x + A_d x(t - h) (see the module docstring)."""
    sp = rightmost_roots(A, Ad, h)
    if not sp.alpha < 0:
        r = sp.roots[0]
        return Damping(sp.alpha, -1.0, complex(r.real, abs(r.imag)))
    band = [r for r in sp.roots if r.real >= 2 * sp.alpha]
    r = min(band, key=lambda s: -s.real / abs(s))
    return Damping(sp.alpha, float(-r.real / abs(r)), complex(r.real, abs(r.imag)))


def tune_pid(loop, h: float, *, zeta_min: float, kp=(0.05, 3.0), ki=(0.005, 3.0),
             points: int = 25, refine: int = 3) -> tuple[float, float, Damping]:
    """(kp, ki, damping) with the largest decay rate and zeta >= ``zeta_min``.

    A log-spaced grid of ``points`` x ``points`` gains, then ``refine`` rounds
    of a 9 x 9 log grid spanning one step of the previous grid on each side
    of its best point (the step shrinks by 4 each round); deterministic.

    Parameters
    ----------
    loop : callable
        ``loop(kp, ki) -> (A, A_d)``.
    h : float
        Dead time of the loop (s).
    zeta_min : float
        Required damping ratio of the dominant roots.
    kp, ki : (float, float)
        Ranges of the first grid.

    Raises
    ------
    ValueError
        No grid point meets the damping requirement.
    """
    def search(kps, kis, best):
        for p in kps:
            for i in kis:
                d = damping(*loop(float(p), float(i)), h)
                if d.zeta >= zeta_min and (best is None or d.alpha < best[2].alpha):
                    best = (float(p), float(i), d)
        return best

    best = search(np.geomspace(*kp, points), np.geomspace(*ki, points), None)
    if best is None:
        raise ValueError(f"no (kp, ki) on the grid reaches zeta >= {zeta_min}")
    step = np.array([np.log(kp[1] / kp[0]), np.log(ki[1] / ki[0])]) / (points - 1)
    for _ in range(refine):
        centre = np.log([best[0], best[1]])
        grids = [np.exp(np.linspace(c - s, c + s, 9)) for c, s in zip(centre, step)]
        best = search(*grids, best)
        step = step / 4
    return best
