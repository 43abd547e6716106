"""Quarter-train adhesion model with input delay (paper 003), written once.

Every numeric function, Jacobian and proof input of the antiskid studies is
derived from the sympy expressions built here; nothing is retyped in numpy.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3):539-548, 2026.
   Eqs (4)-(16): creep ratio, adhesion curve, traction and braking forms.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property, lru_cache

import sympy as sp
from scipy.optimize import brentq

from ..errors import ModelError
from .lambdify_cache import lambdify
from .units import ADHESION_003

#: Parameter names of the model with their SI units (the design loader checks
#: that a design states exactly these units; kept as data in
#: :mod:`workbench.plants.units`).
PARAMETER_UNITS: dict[str, str] = ADHESION_003


@dataclass(frozen=True)
class AdhesionModel:
    """Symbolic adhesion model of paper 003.

    Attributes
    ----------
    v, lam, u : sympy.Symbol
        Train speed (m/s), creep ratio (-), delayed wheel torque u(t-h) (N m).
    params : dict[str, sympy.Symbol]
        Model constants, keyed as in :data:`PARAMETER_UNITS`.
    """

    @cached_property
    def v(self) -> sp.Symbol:
        return sp.Symbol("v", positive=True)

    @cached_property
    def lam(self) -> sp.Symbol:
        return sp.Symbol("lambda", real=True)

    @cached_property
    def u(self) -> sp.Symbol:
        return sp.Symbol("u", real=True)

    @cached_property
    def params(self) -> dict[str, sp.Symbol]:
        return {k: sp.Symbol(k, positive=True) for k in PARAMETER_UNITS}

    @cached_property
    def grade(self) -> sp.Symbol:
        """Track slope (dimensionless, uphill positive; small-angle sin)."""
        return sp.Symbol("grade", real=True)

    # --- eq (6): adhesion coefficient -------------------------------------
    @cached_property
    def mu_traction(self) -> sp.Expr:
        """mu(lambda) for lambda >= 0, eq (6) first line."""
        p, lam = self.params, self.lam
        return p["a"] * (1 - sp.exp(-p["b"] * lam)) - lam / p["c"]

    @cached_property
    def mu_braking(self) -> sp.Expr:
        """mu(lambda) for lambda < 0, eq (6) second line."""
        p, lam = self.params, self.lam
        return -p["a"] * (1 - sp.exp(p["b"] * lam)) - lam / p["c"]

    @cached_property
    def mu(self) -> sp.Expr:
        """Adhesion coefficient, eq (6), both branches."""
        return sp.Piecewise((self.mu_traction, self.lam >= 0), (self.mu_braking, True))

    @cached_property
    def f_r(self) -> sp.Expr:
        """Running resistance (N), eq (9)."""
        p = self.params
        return p["c0"] + p["c1"] * self.v + p["c2"] * self.v**2

    @cached_property
    def f_graded(self) -> sp.Expr:
        """Running resistance plus the gradient force m g grade (N): the
        resistance of eq (9) on a slope (issue 17, item 6)."""
        p = self.params
        return self.f_r + p["m"] * p["g"] * self.grade

    # --- eqs (12)-(13): traction form, v_w > v ------------------------------
    @cached_property
    def traction(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """(y1, y2, y3) of eq (13): v' = y1, lambda' = y2 + y3 u(t-h)."""
        return self._traction(self.f_r)

    @cached_property
    def traction_graded(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """:attr:`traction` with the resistance :attr:`f_graded` (free symbol :attr:`grade`)."""
        return self._traction(self.f_graded)

    def _traction(self, f_r: sp.Expr) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        p, v, lam, mu = self.params, self.v, self.lam, self.mu_traction
        y1 = mu * p["g"] - f_r / p["m"]
        y2 = (mu * (lam - 1) * p["g"] / v - p["zeta"] * (1 - lam) / p["J"]
              - (lam - 1) * f_r / (p["m"] * v)
              - (1 - lam) ** 2 * mu * p["m"] * p["g"] * p["r"] ** 2 / (p["J"] * v))
        y3 = (1 - lam) ** 2 * p["r"] / (p["J"] * v)
        return y1, y2, y3

    # --- eqs (15)-(16): braking form, v_w < v -------------------------------
    @cached_property
    def braking(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """(z1, z2, z3) of eq (16): v' = z1, lambda' = z2 + z3 u(t-h)."""
        return self._braking(self.f_r)

    @cached_property
    def braking_graded(self) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        """:attr:`braking` with the resistance :attr:`f_graded`."""
        return self._braking(self.f_graded)

    def _braking(self, f_r: sp.Expr) -> tuple[sp.Expr, sp.Expr, sp.Expr]:
        p, v, lam, mu = self.params, self.v, self.lam, self.mu_braking
        z1 = mu * p["g"] - f_r / p["m"]
        z2 = (-mu * (lam + 1) * p["g"] / v - p["zeta"] * (1 + lam) / p["J"]
              + (lam + 1) * f_r / (p["m"] * v)
              - mu * p["m"] * p["g"] * p["r"] ** 2 / (p["J"] * v))
        z3 = p["r"] / (p["J"] * v)
        return z1, z2, z3

    def substitute(self, expr: sp.Expr, values: dict[str, float]) -> sp.Expr:
        """Replace the model constants of ``expr`` by numbers."""
        return expr.subs({self.params[k]: sp.Float(values[k]) for k in PARAMETER_UNITS})


@lru_cache(maxsize=1)
def adhesion_model() -> AdhesionModel:
    """The (single, cached) symbolic model of paper 003."""
    return AdhesionModel()


@dataclass(frozen=True)
class NumericAdhesion:
    """Numeric functions of the adhesion model for one parameter set.

    All functions are ``sympy.lambdify`` of :class:`AdhesionModel`.

    Parameters
    ----------
    values : dict[str, float]
        Model constants in SI units (keys of :data:`PARAMETER_UNITS`).
    """

    values: tuple[tuple[str, float], ...]

    @classmethod
    def from_dict(cls, values: dict[str, float]) -> "NumericAdhesion":
        return cls(tuple(sorted((k, float(values[k])) for k in PARAMETER_UNITS)))

    @cached_property
    def _subs(self) -> dict[str, float]:
        return dict(self.values)

    def _fn(self, expr: sp.Expr, args=None):
        mdl = adhesion_model()
        args = args or (mdl.v, mdl.lam)
        return lambdify(args, mdl.substitute(expr, self._subs), "numpy")

    @cached_property
    def mu(self):
        """mu(lambda), eq (6) (vectorised)."""
        return self._fn(adhesion_model().mu, (adhesion_model().lam,))

    @cached_property
    def traction(self):
        """Callables (y1, y2, y3)(v, lambda), eq (13)."""
        return tuple(self._fn(e) for e in adhesion_model().traction)

    @cached_property
    def braking(self):
        """Callables (z1, z2, z3)(v, lambda), eq (16)."""
        return tuple(self._fn(e) for e in adhesion_model().braking)

    def lambda_opt(self) -> float:
        """Creep ratio of peak adhesion, argmax of mu on lambda > 0.

        Solved from d mu / d lambda = 0 (derived symbolically) by bracketing
        root search on (0, 1).
        """
        mdl = adhesion_model()
        dmu = self._fn(sp.diff(mdl.mu_traction, mdl.lam), (mdl.lam,))
        if not dmu(1e-12) > 0:
            raise ModelError("adhesion curve has no creep region: d mu/d lambda <= 0 at 0")
        if dmu(1.0) > 0:
            raise ModelError("adhesion curve has no peak on (0, 1)")
        return float(brentq(dmu, 1e-12, 1.0, xtol=1e-15, rtol=1e-14))

    def cruise_lambda(self, v_d: float) -> float:
        """Cruise creep ratio: the root of y1(v_d, lambda) = 0 in (0, lambda_opt).

        Parameters
        ----------
        v_d : float
            Cruise speed (m/s).

        Raises
        ------
        ModelError
            When the resistance at ``v_d`` exceeds the peak adhesion (no
            creep-region equilibrium exists).
        """
        y1 = self.traction[0]
        lam_opt = self.lambda_opt()
        lo, hi = y1(v_d, 0.0), y1(v_d, lam_opt)
        if not hi > 0:
            raise ModelError(
                f"no cruise equilibrium at v_d = {v_d:g} m/s: the resistance "
                f"needs mu = {float(self._mu_needed(v_d)):.4g} but the peak adhesion is "
                f"mu(lambda_opt = {lam_opt:.4g}) = {float(self.mu(lam_opt)):.4g}")
        if not lo < 0:
            raise ModelError(f"no cruise equilibrium at v_d = {v_d:g} m/s: y1(v_d, 0) >= 0")
        return float(brentq(lambda x: y1(v_d, x), 0.0, lam_opt, xtol=1e-15, rtol=1e-14))

    def _mu_needed(self, v_d: float) -> float:
        mdl = adhesion_model()
        p = mdl.params
        return float(self._fn(mdl.f_r / (p["m"] * p["g"]), (mdl.v,))(v_d))
