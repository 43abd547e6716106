"""The cruise -> braking switch of paper 003's eq (75) against the braking law (69).

Law (69) tracks the *time-varying* desired creep speed v_s*(t) of eq (76):
it has no fixed equilibrium, so a fixed-equilibrium basin applies only to the
loop **frozen at the switch instant**. The assumptions, stated in the report:

* exact prediction: the delay-free loop, as paper 003's Theorem 3 argues
  (the predicted state replaces the state in the law);
* the train speed v frozen at its value at the switch (the creep ratio moves
  on a time scale of v / 4000 s, the speed by about 1 % a second);
* v_s* frozen at v_s*(t_brake) (eq 76 at the switch), with d v_s*/dt = 0;
* the controller's nominal model (eq 12 for lambda >= 0, eq 15 below).

The frozen loop is one-dimensional: lambda' = g(lambda), the traction form
for lambda >= 0 and the braking form below (as the plant), under law (69),
which is computed on the braking form (eq 16) whatever the sign of lambda.
Its verdict on [-0.9, 0.9] (|lambda| = 0.9: spin or lock) is the general
one-state verdict, :func:`workbench.features.basin_scalar.scalar_verdict`
(the result: a :class:`workbench.features.basin_scalar.FrozenSwitch`):
REFUTED when no equilibrium lies between the switch state and the end it
moves to (the sign of g proven), the level-set certificate of the nearest
stable equilibrium otherwise. Only the frozen loop (law (69) on the adhesion
plant), the limit and the time-varying loop below are paper 003's.

The verdict is checked against the **time-varying** delay-free loop
(v and lambda both integrated, v_s*(t) and d v_s*/dt of eq 76 as printed)
from the switch state: its fate (the general
:func:`workbench.features.basin_trajectory.time_varying_fate`).

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (12),
   (15), (16), (69), (75), (76); Theorem 3.
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ...features.basin_scalar import FrozenSwitch, scalar_verdict
from ...features.basin_trajectory import limit_event
from ...features.basin_trajectory import time_varying_fate as fate_from
from ...plants.adhesion import adhesion_model
from ...plants.lambdify_cache import lambdify
from ...sim.wheel_slip import ScalarOps, wheel_speed

#: |lambda| at which the wheel spins or locks (the runs' divergence test).
LAM_LIMIT = 0.9
#: Horizon (s) of the time-varying delay-free loop from the switch state.
T_FATE = 5.0
#: Relative tolerance of its Radau integration.
FATE_RTOL = 1e-8
#: |v lambda - v_s*| (m/s) under which the loop "tracks" at T_FATE.
TRACK_TOL = 0.01


@lru_cache(maxsize=4)
def _forms(values: tuple):
    """(traction, braking) sympy forms in (v, lambda) with the values in."""
    mdl = adhesion_model()
    vals = dict(values)
    sub = lambda e: mdl.substitute(e, vals)
    return (tuple(sub(e) for e in mdl.traction), tuple(sub(e) for e in mdl.braking),
            mdl.v, mdl.lam)


def frozen_loop(values: dict, v: float, vs: float, k_de: float):
    """(g, lambda symbol): lambda' of the frozen loop (module docstring)."""
    (y1, y2, y3), (z1, z2, z3), vs_, lam = _forms(tuple(sorted(values.items())))
    V = sp.Float(float(v))
    at = {vs_: V}
    y2, y3, z1, z2, z3 = (e.xreplace(at) for e in (y2, y3, z1, z2, z3))
    u = ((-sp.Float(float(k_de)) * (V * lam - sp.Float(float(vs))) + z1) / V
         - (1 + lam) / V * z1 - z2) / z3
    return sp.Piecewise((y2 + y3 * u, lam >= 0), (z2 + z3 * u, True)), lam


def brake_switch(values: dict, label: str, point, *, profile, k_de: float,
                 t: float | None = None, seed: int = 0) -> FrozenSwitch:
    """Verdict for the switch state ``point`` = (v, lambda) (module docstring):
    the reference is v_s*(t) frozen, the verdict that of the frozen loop on
    [-0.9, 0.9] (``star``: its equilibrium the state moves to; ``rate``: proven
    lower bound of |lambda'| on the way, 1/s), the fate that of the time-varying
    loop: "diverges" (|lambda| reaches 0.9 or a step fails, ``t_fate``: when,
    s after t_brake), "tracks" (lambda < 0 and |v lambda - v_s*| < 0.01 m/s at
    T_FATE), "undecided".

    Parameters
    ----------
    values : dict
        Nominal plant constants (SI).
    label : str
    point : (v, lambda)
        State at the switch.
    profile : CreepSpeedProfile
        Eq (76) (its t_brake is the switch instant).
    k_de : float
        Gain of law (69) (1/s).
    t : float, optional
        Instant the loop is frozen at (default: t_brake).
    seed : int
        Falsifier seed of the level-set case.
    """
    v, lam_s = float(point[0]), float(point[1])
    t = profile.t_brake if t is None else t
    r = dict(values)["r"]
    vs, _ = profile(t, v, 0.0, wheel_speed(v, lam_s, r, ScalarOps), ScalarOps)
    vs = float(vs)
    g, lam = frozen_loop(values, v, vs, k_de)
    fate, t_fate = time_varying_fate(values, (v, lam_s), profile, k_de)
    sv = scalar_verdict(g, lam, lam_s, -LAM_LIMIT, LAM_LIMIT, name="lambda", seed=seed)
    return FrozenSwitch(label, (v, lam_s), vs, sv, fate, t_fate)


def time_varying_fate(values: dict, x0, profile, k_de: float) -> tuple[str, float | None]:
    """Fate of the time-varying delay-free loop from x0 = (v, lambda) at t_brake
    (:func:`brake_switch`), and when it diverged."""
    (y1, y2, y3), (z1, z2, z3), vs_, lam = _forms(tuple(sorted(values.items())))
    fns = [lambdify((vs_, lam), e, "math") for e in (y1, y2, y3, z1, z2, z3)]
    Y1, Y2, Y3, Z1, Z2, Z3 = fns
    r = dict(values)["r"]

    def law(t, v, la):
        z1v = Z1(v, la)
        vs, dvs = profile(t, v, z1v, wheel_speed(v, la, r, ScalarOps), ScalarOps)
        return ((-k_de * (v * la - vs) + z1v + dvs) / v - (1 + la) / v * z1v
                - Z2(v, la)) / Z3(v, la), float(vs)

    def rhs(t, v, la):
        u, _ = law(t, v, la)
        if la >= 0:
            return [Y1(v, la), Y2(v, la) + Y3(v, la) * u]
        return [Z1(v, la), Z2(v, la) + Z3(v, la) * u]

    def tracks(t, x):
        v, la = x
        return la < 0 and abs(v * la - law(t, v, la)[1]) < TRACK_TOL
    return fate_from(rhs, x0, profile.t_brake, T_FATE, tracks,
                     events=[limit_event(1, LAM_LIMIT)], rtol=FATE_RTOL, max_step=0.05)
