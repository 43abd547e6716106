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
one-state verdict, :func:`workbench.features.basin_scalar.scalar_verdict`:
REFUTED when no equilibrium lies between the switch state and the end it
moves to (the sign of g proven), the level-set certificate of the nearest
stable equilibrium otherwise.

The verdict is checked against the **time-varying** delay-free loop
(v and lambda both integrated, v_s*(t) and d v_s*/dt of eq 76 as printed)
from the switch state: its fate. Both come from the general
:func:`workbench.features.basin_scalar.frozen_switch` (the result: a
:class:`workbench.features.basin_scalar.FrozenSwitch`), given the loop with
v_s* and d v_s*/dt as symbols; only that loop (law (69) on the adhesion
plant), eq (76) as its reference, the limit and the "tracks" test are paper 003's.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (12),
   (15), (16), (69), (75), (76); Theorem 3.
"""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ...features.basin_scalar import FrozenSwitch, frozen_switch
from ...features.basin_trajectory import limit_event
from ...plants.adhesion import adhesion_model
from ...plants.lambdify_cache import lambdify
from ...sim.wheel_slip import ScalarOps, wheel_speed
from .antiskid_basin import LAM_DIVERGED as LAM_LIMIT      # the wheel spins or locks

#: Horizon (s) of the time-varying delay-free loop from the switch state.
T_FATE = 5.0
#: Relative tolerance of its Radau integration.
FATE_RTOL = 1e-8
#: |v lambda - v_s*| (m/s) under which the loop "tracks" at T_FATE.
TRACK_TOL = 0.01


@lru_cache(maxsize=4)
def brake_loop(values: tuple, k_de: float) -> tuple:
    """(field, (v, lambda), (v_s*, d v_s*/dt), z1) of the delay-free loop under
    law (69) with the plant constants ``values`` (sorted (name, value) pairs)
    in: the traction form for lambda >= 0, the braking form below, the law on
    the braking form (module docstring); z1: the braking form's v', which
    eq (76) needs."""
    mdl = adhesion_model()
    sub = lambda e: mdl.substitute(e, dict(values))
    (y1, y2, y3), (z1, z2, z3) = ([sub(e) for e in form] for form in (mdl.traction, mdl.braking))
    v, lam = mdl.v, mdl.lam
    vs, dvs = sp.symbols("v_s dv_s", real=True)
    u = ((-sp.Float(float(k_de)) * (v * lam - vs) + z1 + dvs) / v - (1 + lam) / v * z1 - z2) / z3
    trac = lam >= 0
    return ([sp.Piecewise((y1, trac), (z1, True)),
             sp.Piecewise((y2 + y3 * u, trac), (z2 + z3 * u, True))], (v, lam), (vs, dvs), z1)


def brake_switch(values: dict, label: str, point, *, profile, k_de: float,
                 t: float | None = None, seed: int = 0) -> FrozenSwitch:
    """Verdict for the switch state ``point`` = (v, lambda) (module docstring):
    the reference is v_s*(t) frozen, the verdict that of the frozen loop on
    [-0.9, 0.9] (``star``: its equilibrium the state moves to; ``rate``: proven
    lower bound of |lambda'| on the way, 1/s), the fate that of the time-varying
    loop from t_brake: "diverges" (|lambda| reaches 0.9 or a step fails,
    ``t_fate``: when, s after t_brake), "tracks" (lambda < 0 and |v lambda -
    v_s*| < 0.01 m/s at T_FATE), "undecided".

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
    field, states, refs, z1 = brake_loop(tuple(sorted(values.items())), float(k_de))
    Z1, r = lambdify(states, z1, "math"), dict(values)["r"]
    reference = lambda t_, x: profile(t_, x[0], Z1(*x), wheel_speed(x[0], x[1], r, ScalarOps),
                                      ScalarOps)
    tracks = lambda x, vs: x[1] < 0 and abs(x[0] * x[1] - vs) < TRACK_TOL
    return frozen_switch(label, field, states, refs, point, 1, reference, profile.t_brake,
                         -LAM_LIMIT, LAM_LIMIT, T=T_FATE, settled=tracks,
                         events=[limit_event(1, LAM_LIMIT)], rtol=FATE_RTOL, max_step=0.05,
                         t_frozen=t, name="lambda", seed=seed)
