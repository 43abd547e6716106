"""Point-mass train models of papers 002 and 001, written once in sympy.

Paper 002 (after Yu & Chen 2011, its ref [2]): the ATO command u maps
statically to a demanded acceleration A = f u + e (eq 1), which reaches the
train through a pure delay T_d and a first-order lag T_l (eq 2, lost in the
extracted text); running resistance (Davis, per unit mass) and gradient act
on the speed::

    T_l a'(t) = A(t - T_d) - a(t)
    v'(t)     = a(t) - r(v) - g sin(atan(i(s)))
    s'(t)     = v(t)

Table 1 of 002, which held eq 2's parameters, is lost, and the text supports
two readings of the chain. The paper calls ``A`` a *demanded acceleration*
(eq 1) — the reading above, where speed integrates the lagged demand
(``"delay-lag-002"``, *integrating*). It also calls ``u`` the *ATO's desired
output speed*; read so, the delay and the lag of eq 2 act on speed itself,
the usual first-order-plus-dead-time ATO model (``"first-order-002"``, *our
reading*, non-integrating), with the traction/brake acceleration limited to
``[a_min, a_max]``::

    v'(t) = sat((A(t - T_d) - v(t)) / T_l) - r(v) - g sin(atan(i(s)))

whose DC gain from ``u`` is finite: dv/du = f / (1 + T_l r'(v)) on level
track (:func:`dc_gain`), against f / r'(v) (a time constant 1 / r'(v) of
several hundred seconds, far beyond a run) for the integrating reading.

Paper 001 uses the same Davis law as a force, m v' = u - f_u - f_v + w + d
(eqs 1-5; the paper's ``c2 x''^2`` is a typo for ``c2 x'^2``). Both studies
take their numeric functions from the expressions below.

References
----------
.. [002] ATO target speed curve tracking with MFAC, Nanning Line 1, eqs 1-2.
.. [001] Fan L., virtual coupling with NTSM, Urban Mass Transit 2024(10), eqs 1-5.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

#: Parameters of the 002 train model and their SI units (checked by the loader).
PARAMETER_UNITS: dict[str, str] = {
    "f": "1", "e": "m/s^2", "delay": "s", "lag": "s",
    "c0": "m/s^2", "c1": "1/s", "c2": "1/m", "g": "m/s^2",
}

v, u, a, A, grad = sp.symbols("v u a A i", real=True)
f, e, T_l = sp.symbols("f e T_l", positive=True)
c0, c1, c2, g = sp.symbols("c_0 c_1 c_2 g", positive=True)

#: eq (1) of 002: static command map (m/s^2).
STATIC_MAP = f * u + e
#: Davis running resistance per unit mass (m/s^2); times m it is f_u of 001 eq (2).
DAVIS = c0 + c1 * v + c2 * v ** 2
#: Gradient acceleration (m/s^2) for gradient i (rise over run, up-hill > 0); 001 eq (3).
GRADIENT = g * sp.sin(sp.atan(grad))
#: Lag (eq 2 of 002, reconstructed): a' with the delayed demand A.
LAG_RATE = (A - a) / T_l
#: Speed rate of the 002 train (m/s^2).
SPEED_RATE = a - DAVIS - GRADIENT
#: Speed rate of the first-order reading (m/s^2), A the delayed demanded speed,
#: inside the acceleration limits.
FIRST_ORDER_RATE = (A - v) / T_l - DAVIS - GRADIENT
#: Plant models of the two readings (names used in design files).
MODELS = ("delay-lag-002", "first-order-002")


@lru_cache(maxsize=None)
def _numeric() -> dict[str, callable]:
    """numpy functions lambdified once from the expressions above."""
    return {"davis": sp.lambdify((v, c0, c1, c2), DAVIS, "numpy"),
            "gradient": sp.lambdify((grad, g), GRADIENT, "numpy"),
            "map": sp.lambdify((u, f, e), STATIC_MAP, "numpy")}


def davis(vel, c0_: float, c1_: float, c2_: float):
    """Davis resistance per unit mass (m/s^2) at speed ``vel`` (m/s); vectorised."""
    return _numeric()["davis"](vel, c0_, c1_, c2_)


def gradient_accel(i, g_: float):
    """Gradient acceleration g sin(atan(i)) (m/s^2) for gradient ``i`` (-)."""
    return _numeric()["gradient"](i, g_)


def static_map(cmd, f_: float, e_: float):
    """Demanded acceleration A = f u + e (m/s^2), eq (1) of 002."""
    return _numeric()["map"](cmd, f_, e_)


@dataclass(frozen=True)
class Train002:
    """Parameters of the 002 train model (SI units, see :data:`PARAMETER_UNITS`).

    Attributes
    ----------
    f, e : float
        Static map gain (-) and offset (m/s^2), eq (1).
    delay, lag : float
        Pure delay T_d and lag time constant T_l (s), eq (2).
    c0, c1, c2 : float
        Davis coefficients per unit mass (m/s^2, 1/s, 1/m).
    g : float
        Gravity (m/s^2).
    u_min, u_max : float
        Command limits (the ATO command is a demanded acceleration, m/s^2).
    """

    f: float
    e: float
    delay: float
    lag: float
    c0: float
    c1: float
    c2: float
    g: float
    u_min: float = -1.0
    u_max: float = 1.0

    def demand(self, cmd):
        """Demanded acceleration (m/s^2) of a clipped command."""
        return static_map(np.clip(cmd, self.u_min, self.u_max), self.f, self.e)

    def resistance(self, vel):
        """Davis resistance per unit mass (m/s^2)."""
        return davis(vel, self.c0, self.c1, self.c2)

    def grade(self, i):
        """Gradient acceleration (m/s^2)."""
        return gradient_accel(i, self.g)


@dataclass(frozen=True)
class FirstOrderTrain002(Train002):
    """The first-order (non-integrating) reading of the 002 train: the lagged
    demand ``A = f u + e`` is the speed the traction/brake control settles at
    (``f`` in (m/s) per unit command, ``e`` in m/s); see the module docstring.

    Attributes
    ----------
    a_min, a_max : float
        Limits of the realised traction/brake acceleration (m/s^2).
    """

    a_min: float = -1.0
    a_max: float = 1.0


def _steady_rate(model: str):
    """The speed rate at rest of the lag (a = A for the integrating reading),
    level track, as a sympy expression in v and u."""
    demand = STATIC_MAP
    rate = SPEED_RATE.subs(a, demand) if model == "delay-lag-002" else \
        FIRST_ORDER_RATE.subs(A, demand)
    return rate.subs(grad, 0)


def dc_gain(train: Train002, vel: float) -> float:
    """Steady-state gain dv/du ((m/s) per unit command) at speed ``vel`` on
    level track, by implicit differentiation of the speed rate F(v, u) = 0:
    dv/du = -F_u / F_v. Finite for both readings; for the integrating one it
    is f / r'(v), reached with the time constant :func:`speed_time_constant`."""
    rate = _steady_rate(_model(train))
    subs = _subs(train) | {v: vel}
    return float((-sp.diff(rate, u) / sp.diff(rate, v)).subs(subs))


def speed_time_constant(train: Train002, vel: float) -> float:
    """Time constant (s) of the slowest speed mode, -1 / (dF/dv) at ``vel``
    with the lag settled (level track)."""
    rate = _steady_rate(_model(train))
    return float((-1 / sp.diff(rate, v)).subs(_subs(train) | {v: vel}))


def linear_model(train: Train002, vel: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(A, B, C) of the model linearised at speed ``vel`` on level track,
    input the undelayed command u, output v (the delay is applied by the
    caller). States (a, v) for the integrating reading, (v,) for the
    first-order one (acceleration limits inactive)."""
    subs = _subs(train) | {v: vel, grad: 0}
    if _model(train) == "delay-lag-002":
        f_ = sp.Matrix([LAG_RATE.subs(A, STATIC_MAP), SPEED_RATE])
        x = sp.Matrix([a, v])
    else:
        f_ = sp.Matrix([FIRST_ORDER_RATE.subs(A, STATIC_MAP)])
        x = sp.Matrix([v])
    Am = np.array(f_.jacobian(x).subs(subs), dtype=float)
    Bm = np.array(f_.jacobian(sp.Matrix([u])).subs(subs), dtype=float)
    Cm = np.zeros((1, len(x)))
    Cm[0, -1] = 1.0
    return Am, Bm, Cm


def _model(train: Train002) -> str:
    return "first-order-002" if isinstance(train, FirstOrderTrain002) else "delay-lag-002"


def _subs(train: Train002) -> dict:
    return {f: train.f, e: train.e, T_l: train.lag, c0: train.c0, c1: train.c1,
            c2: train.c2, g: train.g}


def latex_equations(model: str = "delay-lag-002") -> list[str]:
    """A reading's equations, rendered from the sympy expressions (for reports)."""
    a_d = sp.Function("A")(sp.Symbol("t") - sp.Symbol("T_d"))
    if model == "first-order-002":
        return [r"A = " + sp.latex(STATIC_MAP) + r" \qquad \text{(002 eq 1, A a demanded speed)}",
                r"\dot v = " + sp.latex(FIRST_ORDER_RATE.subs(A, a_d))
                + r" \qquad \text{(first term within } [a_{\min}, a_{\max}]\text{)}"]
    return [r"A = " + sp.latex(STATIC_MAP) + r" \qquad \text{(002 eq 1)}",
            r"\dot a = " + sp.latex(LAG_RATE.subs(A, a_d))
            + r" \qquad \text{(002 eq 2, reconstructed)}",
            r"\dot v = " + sp.latex(SPEED_RATE) + r", \qquad \dot s = v"]
