"""Electro-pneumatic metro brake of paper 000 (eqs 1-10), written once in sympy.

Per unit of train mass, decelerations positive, SI units (m, s, m/s, m/s^2).
States: position ``x``, speed ``v``, achieved electric brake ``b_e`` and
achieved air brake ``b_a``. Input: the brake command ``c`` (demanded
deceleration, m/s^2; negative values are traction demands served by the
electric drive), which reaches the electric stage after the transmission
delay T1 and the air stage after T3::

    x' = v
    v' = -kappa (P1 b_e + b_a) - a_res(v)                     (eqs 5, 10)
    b_e' = (e(t - T1) - b_e) / T2                             (eq 2)
    b_a' = (G_air(v) d_air(t - T3) - b_a) / T4                 (eqs 7, 9)
    a_res = (d0 + d1 V + d2 V^2 + theta) g / 1000             (eqs 3-4)
    G_air = (K1 / K2) (V + 150) / (2 V + 150) / 100           (eq 7)

with V = 3.6 v the speed in km/h. Hand-over (eq 8): while v > v_ho the
electric stage takes the whole command (e = c, d_air = 0); once the speed
falls below v_ho the electric share is capped by a ramp that falls at
k_bra (m/s^3) from its value at hand-over, and the air stage takes the rest
(d_air = c - e).

Unit slips of the paper resolved here (documented choices)
--------------------------------------------------------------
* Eq 3 is the Chinese per-kN Davis form (N/kN) with V in km/h; the paper
  writes V in cm/s. We use km/h, so a_res = w0 g / 1000 in m/s^2.
* Eq 7's (V + 150)/(2V + 150) is the composite brake-shoe speed factor with V
  in km/h; the paper applies it to cm/s. We use km/h.
* Eq 7 divides by the mass m, but with K1/K2 = 85.16 (Table 1) the result is
  only plausible as cm/s^2 for a unit mass: 85 cm/s^2 at standstill for the
  paper's full 1 m/s^2 stop brake. We therefore read K1/K2 as the air-brake
  deceleration (cm/s^2) of a full 1 m/s^2 demand at V = 0, i.e. the
  dimensionless air gain G_air above. K1 and K2 enter **only as their
  ratio**: they are not separately identifiable (see workbench/fit.py).
* The paper's "maximum braking deceleration -10 cm/s^2" of the existing model
  is read as -100 cm/s^2 = 1 m/s^2 (a factor-10 slip).
* Eq 2's "t > T2" is "t > T1" (typo); eqs 1-10 are stepped with the log
  interval Td = 0.2 s in the paper; we integrate the same ODE with a small
  fixed step (see workbench/sim/stopping.py).
* kappa = (estimated mass)/(true mass): the load-weighing error of the brake
  control unit, which turns a deceleration demand into a force.

The paper's "existing" delay + lag model (fig 4, eq 28: delay 0.3 s, time
constant 0.65 s) is the special case P1 = 1, T1 = 0.3 s, T2 = 0.65 s, no
hand-over (v_ho = 0): :func:`existing_model`.

References
----------
.. [000] Yu K., Zhang X., Zhang H., "Key issues in real-time optimization of
   braking performance for urban rail transit trains", Urban Rapid Rail
   Transit 37(4):52-59, 2024. Eqs (1)-(10), Table 1, eq (28).
"""
from __future__ import annotations

from dataclasses import dataclass, fields, replace
from functools import lru_cache

import numpy as np
import sympy as sp

#: Parameters of the brake model with their SI units (designs state exactly these).
PARAMETER_UNITS: dict[str, str] = {
    "T1": "s", "T2": "s", "P1": "1", "T3": "s", "T4": "s", "K1": "1", "K2": "1",
    "k_bra": "m/s^3", "v_ho": "m/s", "d0": "N/kN", "d1": "N/kN per km/h",
    "d2": "N/kN per (km/h)^2", "g": "m/s^2",
}

#: cm/s^2 per m/s^2: the paper's K1/K2 is in cm/s^2 (see module docstring).
CM_PER_M = 100.0
KMH_PER_MS = 3.6


@dataclass(frozen=True)
class BrakeParams:
    """Numeric parameters of the brake model (SI; see :data:`PARAMETER_UNITS`).

    Attributes
    ----------
    T1, T2 : float
        Electric stage: transmission delay and lag time constant (s), eq 2.
    P1 : float
        Electric brake coefficient (motor efficiency etc.), eq 5 (fraction).
    T3, T4 : float
        Air stage: transmission delay and lag time constant (s), eq 9.
    K1, K2 : float
        Air brake numerator / denominator coefficients, eq 7 (only K1/K2 matters).
    k_bra : float
        Electric fade-out slope (m/s^3), eq 8.
    v_ho : float
        Hand-over speed below which the electric brake fades out (m/s);
        0 disables the air stage.
    d0, d1, d2 : float
        Davis coefficients of eq 3 (N/kN, V in km/h).
    g : float
        Gravity (m/s^2).
    """

    T1: float
    T2: float
    P1: float
    T3: float
    T4: float
    K1: float
    K2: float
    k_bra: float
    v_ho: float
    d0: float
    d1: float
    d2: float
    g: float = 9.8

    @classmethod
    def from_dict(cls, d: dict) -> "BrakeParams":
        return cls(**{f.name: float(d[f.name]) for f in fields(cls) if f.name in d})

    def as_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


def existing_model(p: BrakeParams, *, delay: float, lag: float) -> BrakeParams:
    """The paper's existing delay + lag model (eq 28, fig 4) on the same resistance.

    Parameters
    ----------
    p : BrakeParams
        Supplies the Davis coefficients and g.
    delay, lag : float
        Input delay and time constant (s); the paper uses 0.3 s and 0.65 s.
    """
    return replace(p, T1=delay, T2=lag, P1=1.0, v_ho=0.0, T3=delay, T4=lag)


@dataclass(frozen=True)
class BrakeModel:
    """The symbolic model: expressions of eqs 3-10 in the symbols below."""

    v: sp.Symbol
    b_e: sp.Symbol
    b_a: sp.Symbol
    e_in: sp.Symbol
    air_in: sp.Symbol
    theta: sp.Symbol
    kappa: sp.Symbol
    params: dict
    speed_kmh: sp.Expr
    a_res: sp.Expr
    shoe_factor: sp.Expr
    air_gain: sp.Expr
    rhs: tuple  # (v', b_e', b_a')


@lru_cache(maxsize=1)
def brake_model() -> BrakeModel:
    """Build the sympy model of paper 000 (eqs 2-10) once."""
    v = sp.Symbol("v", nonnegative=True)
    b_e, b_a, e_in, air_in, theta = sp.symbols("b_e b_a e_in d_air theta", real=True)
    kappa = sp.Symbol("kappa", positive=True)
    p = {k: sp.Symbol(k, positive=True) for k in PARAMETER_UNITS}
    V = KMH_PER_MS * v
    a_res = (p["d0"] + p["d1"] * V + p["d2"] * V**2 + theta) * p["g"] / 1000   # eqs 3-4
    shoe = (V + 150) / (2 * V + 150)                                          # eq 7 factor
    air_gain = p["K1"] / p["K2"] * shoe / CM_PER_M                            # eq 7
    rhs = (-kappa * (p["P1"] * b_e + b_a) - a_res,                            # eqs 5, 10
           (e_in - b_e) / p["T2"],                                            # eq 2
           (air_gain * air_in - b_a) / p["T4"])                               # eq 9
    return BrakeModel(v, b_e, b_a, e_in, air_in, theta, kappa, p, V, a_res, shoe, air_gain, rhs)


@lru_cache(maxsize=1)
def _lambdified():
    m = brake_model()
    args = [m.v, m.b_e, m.b_a, m.e_in, m.air_in, m.theta, m.kappa] + list(m.params.values())
    rhs = sp.lambdify(args, list(m.rhs), "numpy")
    ares = sp.lambdify([m.v, m.theta] + list(m.params.values()), m.a_res, "numpy")
    gain = sp.lambdify([m.v] + list(m.params.values()), m.air_gain, "numpy")
    return rhs, ares, gain


def _pvals(p) -> list:
    """Parameter values in the order of :data:`PARAMETER_UNITS` (floats or arrays)."""
    if isinstance(p, dict):
        return [p[k] for k in PARAMETER_UNITS]
    return [getattr(p, k) for k in PARAMETER_UNITS]


def brake_rhs(v, b_e, b_a, e_in, air_in, theta, kappa, p) -> list:
    """Numeric right-hand side (v', b_e', b_a') of eqs 2-10 (lambdified).

    All arguments may be numpy arrays of one batch shape; ``p`` is a
    :class:`BrakeParams` or a dict of (possibly array) parameter values.
    """
    return _lambdified()[0](v, b_e, b_a, e_in, air_in, theta, kappa, *_pvals(p))


def resistance(v, theta, p) -> np.ndarray:
    """Davis resistance + gradient as a deceleration (m/s^2), eqs 3-4."""
    return _lambdified()[1](v, theta, *_pvals(p))


def air_gain(v, p) -> np.ndarray:
    """Air-brake gain G_air(v) of eq 7 (dimensionless, see module docstring)."""
    return _lambdified()[2](v, *_pvals(p))
