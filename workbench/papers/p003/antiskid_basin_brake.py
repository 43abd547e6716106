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
A 1-D trajectory moves monotonically towards the nearest equilibrium in the
direction of g; so, from the switch state lambda_s:

* no equilibrium between lambda_s and |lambda| = 0.9 in that direction, with
  the sign of g proven by interval arithmetic on the whole interval: REFUTED
  -- lambda_s lies in the basin of no equilibrium of the frozen loop, which
  reaches |lambda| = 0.9 (spin or lock) within the time the proven bound of
  |g| gives;
* a stable equilibrium lambda* in that direction: the level-set certificate
  of :mod:`workbench.roa` (V = p (lambda - lambda*)^2, p from the Lyapunov
  equation) and the switch state's verdict;
* otherwise INCONCLUSIVE.

The verdict is checked against the **time-varying** delay-free loop
(v and lambda both integrated, v_s*(t) and d v_s*/dt of eq 76 as printed)
from the switch state: its fate.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (12),
   (15), (16), (69), (75), (76); Theorem 3.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ...features.basin_trajectory import escaped, integrate
from ...outcome import Outcome
from ...plants.adhesion import NumericAdhesion, adhesion_model
from ...plants.lambdify_cache import lambdify
from ...roa import BasinProblem, estimate_basin, lyapunov_P
from ...roa.interval import IntervalFunction
from ...sim.wheel_slip import ScalarOps, wheel_speed

#: |lambda| at which the wheel spins or locks (the runs' divergence test).
LAM_LIMIT = 0.9
#: Horizon (s) of the time-varying delay-free loop from the switch state.
T_FATE = 5.0
#: Relative tolerance of its Radau integration.
FATE_RTOL = 1e-8
#: |v lambda - v_s*| (m/s) under which the loop "tracks" at T_FATE.
TRACK_TOL = 0.01


@dataclass(frozen=True)
class BrakeSwitch:
    """Verdict for the state where law (69) takes over.

    Attributes
    ----------
    label : str
    v, lam : float
        The state at t_brake.
    vs_frozen : float
        v_s*(t_brake) (m/s), frozen.
    outcome : Outcome
    why : str
        "no equilibrium up to spin" / "no equilibrium down to lock" /
        "level set" / what left it INCONCLUSIVE.
    lam_star : float or None
        Equilibrium of the frozen loop the state moves to (None: none).
    rate : float or None
        REFUTED: proven lower bound of |lambda'| between lambda_s and the limit (1/s).
    level : (float, float) or None
        Level-set case: (V at the state (upper bound), c_certified).
    fate : str
        Time-varying delay-free loop: "diverges" (|lambda| reaches 0.9 or a step
        fails), "tracks" (lambda < 0 and |v lambda - v_s*| < 0.01 m/s at T_FATE),
        "undecided".
    t_fate : float or None
        When it diverged (s after t_brake).
    """

    label: str
    v: float
    lam: float
    vs_frozen: float
    outcome: Outcome
    why: str
    lam_star: float | None
    rate: float | None
    level: tuple | None
    fate: str
    t_fate: float | None


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


def _prove_sign(g, lam, a: float, b: float, sign: float, *, max_boxes: int = 20_000):
    """A lower bound m > 0 of sign * g on [a, b] (interval bisection), or None."""
    fn = IntervalFunction([sign * g], (lam,))
    lo, hi, m = np.array([[a]]), np.array([[b]]), math.inf
    boxes = 0
    while len(lo):
        boxes += len(lo)
        if boxes > max_boxes:
            return None
        (iv,), _ = fn(lo, hi)
        ok = iv.lo > 0
        if ok.any():
            m = min(m, float(iv.lo[ok].min()))
        lo, hi = lo[~ok], hi[~ok]
        if len(lo) and (hi - lo).min() < 1e-12:
            return None
        mid = 0.5 * (lo + hi)
        lo, hi = np.concatenate([lo, mid]), np.concatenate([mid, hi])
    return m


def _equilibria(gn, a: float, b: float) -> list:
    """Sign changes of g on a fine grid of [a, b], refined by brentq."""
    from scipy.optimize import brentq
    x = np.linspace(a, b, 3601)
    with np.errstate(all="ignore"):
        y = np.array([float(gn(t)) for t in x])
    out = []
    for i in np.nonzero(np.sign(y[:-1]) * np.sign(y[1:]) <= 0)[0]:
        if np.isfinite(y[i]) and np.isfinite(y[i + 1]):
            out.append(float(brentq(gn, x[i], x[i + 1], xtol=1e-15)) if y[i] != y[i + 1]
                       else float(x[i]))
    return out


def brake_switch(values: dict, label: str, point, *, profile, k_de: float,
                 t: float | None = None, seed: int = 0) -> BrakeSwitch:
    """Verdict for the switch state ``point`` = (v, lambda) (module docstring).

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
    gn = lambdify(lam, g, "math")
    fate, t_fate = time_varying_fate(values, (v, lam_s), profile, k_de)
    common = dict(label=label, v=v, lam=lam_s, vs_frozen=vs, fate=fate, t_fate=t_fate)
    g0 = gn(lam_s)
    d = 1.0 if g0 > 0 else -1.0
    ends = (lam_s, LAM_LIMIT) if d > 0 else (-LAM_LIMIT, lam_s)
    eqs = [e for e in _equilibria(gn, *ends) if abs(e - lam_s) > 1e-12]
    if not eqs:
        m = _prove_sign(g, lam, ends[0], ends[1], d)
        if m is not None:
            why = "no equilibrium up to spin" if d > 0 else "no equilibrium down to lock"
            return BrakeSwitch(outcome=Outcome.REFUTED, why=why, lam_star=None, rate=m,
                               level=None, **common)
        return BrakeSwitch(outcome=Outcome.INCONCLUSIVE, why="sign of lambda' not proven",
                           lam_star=None, rate=None, level=None, **common)
    star = min(eqs, key=lambda e: abs(e - lam_s))
    slope = (gn(star + 1e-7) - gn(star - 1e-7)) / 2e-7
    if not slope < 0:
        return BrakeSwitch(outcome=Outcome.INCONCLUSIVE, why="nearest equilibrium unstable",
                           lam_star=star, rate=None, level=None, **common)
    P = lyapunov_P([[slope]])
    prob = BasinProblem([g], (lam,), (star,), P, P_source="lyapunov", names=("lambda",))
    cap = float(P[0, 0]) * min(star + LAM_LIMIT, LAM_LIMIT - star) ** 2 * (1 - 1e-6)
    c = min(4.0 * float(P[0, 0]) * (lam_s - star) ** 2, cap)
    est = estimate_basin(prob, c, seed=seed)
    pv = est.point_verdict((lam_s,))
    if pv.outcome is not Outcome.CERTIFIED and est.c_certified > 0:
        # monotone approach: d g > 0 proven from lambda_s to the certified level's edge
        edge = star - d * math.sqrt(est.c_certified / float(P[0, 0])) * (1 - 1e-9)
        m = _prove_sign(g, lam, *sorted((lam_s, edge)), d)
        if m is not None:
            return BrakeSwitch(outcome=Outcome.CERTIFIED, why="monotone approach, level set",
                               lam_star=star, rate=m, level=(pv.level, est.c_certified),
                               **common)
    return BrakeSwitch(outcome=pv.outcome, why="level set", lam_star=star, rate=None,
                       level=(pv.level, est.c_certified), **common)


def time_varying_fate(values: dict, x0, profile, k_de: float) -> tuple[str, float | None]:
    """Fate of the time-varying delay-free loop from x0 = (v, lambda) at t_brake
    (class :class:`BrakeSwitch`, ``fate``), and when it diverged."""
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

    def spin(t, x):
        return LAM_LIMIT - abs(x[1])
    spin.terminal = True
    t0 = profile.t_brake
    sol = integrate(rhs, x0, T_FATE, events=[spin], rtol=FATE_RTOL, max_step=0.05, t0=t0)
    if escaped(sol):
        return "diverges", float(sol.t[-1] - t0)
    v, la = sol.y[:, -1]
    _, vs = law(sol.t[-1], v, la)
    return ("tracks" if la < 0 and abs(v * la - vs) < TRACK_TOL else "undecided"), None
