"""A nonlinear delayed loop frozen at one state (issue 35): the linearisation
x' = A x + A_d x(t - h) at a state x0 where a law takes over (the state at a
phase switch of any phase-scheduled run), with its delay-free spectral
abscissa and its exact delay margin (Chen-Gu-Nett,
:func:`workbench.margins.delay_margin_eig`).

``A`` is the Jacobian of the undelayed part by central differences
(:func:`central_jacobian`): second order in the step, no symbolic model
needed; the caller chooses the steps (relative to each state's scale).

References
----------
J. Chen, G. Gu, C. N. Nett, Systems & Control Letters 26:107-117, 1995.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["FrozenLoop", "central_jacobian", "freeze"]


def central_jacobian(f, x0, steps) -> np.ndarray:
    """d f / d x at ``x0`` by central differences, ``steps[j]`` the step of
    state j; ``f(x) -> (n,) array``."""
    x0 = np.asarray(x0, float)
    A = np.zeros((len(f(x0)), x0.size))
    for j, step in enumerate(steps):
        e = np.zeros(x0.size)
        e[j] = step
        A[:, j] = (f(x0 + e) - f(x0 - e)) / (2 * step)
    return A


@dataclass(frozen=True)
class FrozenLoop:
    """``A``: Jacobian of the undelayed part; ``abscissa``: spectral abscissa
    of A + A_d (the loop without delay); ``margin``: exact delay margin of
    x' = A x + A_d x(t - h); ``x0``: the state it is frozen at."""

    A: np.ndarray
    abscissa: float
    margin: object
    x0: tuple = ()


def freeze(f, x0, steps, Ad) -> FrozenLoop:
    """The loop x' = f(x) + A_d x(t - h) frozen at ``x0`` (module docstring)."""
    from ..margins import delay_margin_eig
    A = central_jacobian(f, x0, steps)
    return FrozenLoop(A, float(np.max(np.linalg.eigvals(A + Ad).real)), delay_margin_eig(A, Ad),
                      tuple(float(x) for x in x0))
