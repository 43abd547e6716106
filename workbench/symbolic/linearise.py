"""Linearisation of the adhesion model at a cruise point (paper 003, eqs 17-32).

The coefficients a1..a3, b1..b6 (eq 18) and d1..d6 (eq 23) are first-order
Taylor terms of y1, y2, y3 taken symbolically from
:class:`workbench.plants.adhesion.AdhesionModel`; the error system is
E' = A E + B u~(t-h) with A = [[a1, a2], [d1, d2]], B = [0, 1]^T (eq 32).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..plants.adhesion import NumericAdhesion, adhesion_model
from ..plants.lambdify_cache import lambdify


@dataclass(frozen=True)
class Linearisation:
    """Cruise linearisation of paper 003 at (v_d, lambda_d).

    Attributes
    ----------
    v_d : float
        Cruise speed (m/s).
    lambda_d : float
        Creep ratio used as the linearisation point (-).
    coefficients : dict[str, float]
        a1..a3, b1..b6, d1..d6 of eqs (18) and (23).
    A, B : numpy.ndarray
        Error-system matrices of eq (32); states [v_e (m/s), lambda_e (-)].
    y1_residual : float
        y1(v_d, lambda_d) (m/s^2); zero at a solved equilibrium, so eq (25)
        holds exactly only then.
    """

    v_d: float
    lambda_d: float
    coefficients: dict
    A: np.ndarray
    B: np.ndarray
    y1_residual: float

    def state_space(self) -> control.StateSpace:
        """The error system as a ``control.StateSpace`` (output = state)."""
        import control
        return control.ss(self.A, self.B, np.eye(2), np.zeros((2, 1)))


def taylor_coefficients() -> dict[str, sp.Expr]:
    """Symbolic a1..a3, b1..b6 (eq 18) and d1..d6 (eq 23), with the model's
    symbols v, lambda standing for the linearisation point (v_d, lambda_d)."""
    mdl = adhesion_model()
    v, lam = mdl.v, mdl.lam
    out: dict[str, sp.Expr] = {}
    for prefix, idx, y in (("a", 1, mdl.traction[0]), ("b", 1, mdl.traction[1]),
                           ("b", 4, mdl.traction[2])):
        dv, dl = sp.diff(y, v), sp.diff(y, lam)
        out[f"{prefix}{idx}"] = dv
        out[f"{prefix}{idx + 1}"] = dl
        out[f"{prefix}{idx + 2}"] = y - v * dv - lam * dl
    b = out
    out["d1"], out["d2"] = b["b1"], b["b2"]
    out["d3"] = b["b1"] * v + b["b2"] * lam + b["b3"]
    out["d4"], out["d5"] = b["b4"], b["b5"]
    out["d6"] = b["b4"] * v + b["b5"] * lam + b["b6"]
    return out


def linearise_cruise(plant: NumericAdhesion, v_d: float, lambda_d: float) -> Linearisation:
    """Linearise the traction form (eq 12) at (v_d, lambda_d), eqs (17)-(32).

    Parameters
    ----------
    plant : NumericAdhesion
        Numeric parameter set.
    v_d : float
        Cruise speed (m/s).
    lambda_d : float
        Creep ratio at the linearisation point (-).

    Returns
    -------
    Linearisation
    """
    mdl = adhesion_model()
    subs = dict(plant.values)
    coeffs = {}
    for name, expr in taylor_coefficients().items():
        f = lambdify((mdl.v, mdl.lam), mdl.substitute(expr, subs), "numpy")
        coeffs[name] = float(f(v_d, lambda_d))
    A = np.array([[coeffs["a1"], coeffs["a2"]], [coeffs["d1"], coeffs["d2"]]])
    B = np.array([[0.0], [1.0]])
    y1 = float(plant.traction[0](v_d, lambda_d))
    return Linearisation(v_d, lambda_d, coeffs, A, B, y1)
