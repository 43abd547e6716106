"""Stepping kernel of paper 003's wheel-slip plant (adhesion model, eqs 12-16).

One step of (v, lambda) under a held wheel torque u, knowing no controller:
v by explicit Euler; the creep ratio, whose dynamics are stiff at low speed
(d lambda'/d lambda ~ -m g r^2 mu'(lambda) / (J v), a time constant of about
v / 4000 s on dry rail), by the exponential Euler step
lambda+ = lambda + dt phi1(dt J) lambda', J = d lambda'/d lambda from the
sympy Jacobian, phi1(z) = (e^z - 1)/z: exact for the linear part, stable for
any dt J < 0; a step that would move lambda by more than
:data:`MAX_DLAMBDA` is halved (adaptive sub-stepping, :func:`stiff_step`,
per run in a batch, so a run of a batch follows its single-run trajectory).

Everything numeric is ``sympy.lambdify`` of
:func:`workbench.plants.adhesion.adhesion_model`; the parameters are
lambdify arguments (in :data:`PARAM_ORDER`), so one compiled function serves
a single run (``math`` backend, floats, :class:`ScalarOps`) and a batch of
parameter samples (``numpy`` backend, arrays, :class:`ArrayOps`) alike. The
controllers of :mod:`workbench.controllers.antiskid003` use the same kernel
for their predictors.
"""
from __future__ import annotations

import math
from functools import lru_cache
from typing import Literal

import numpy as np
import sympy as sp

from ..plants.adhesion import PARAMETER_UNITS, adhesion_model
from ..plants.lambdify_cache import lambdify

#: Order of the plant parameters as lambdify arguments.
PARAM_ORDER = tuple(PARAMETER_UNITS)


@lru_cache(maxsize=4)
def model_functions(backend: Literal["math", "numpy"], graded: bool = False) -> dict:
    """Lambdified (y1, y2, y3, dy2/dlambda, dy3/dlambda) of eq (13) and the
    (z...) of eq (16), each as one function of (v, lambda, *params) with
    params in :data:`PARAM_ORDER`; ``graded``: the forms on a slope
    (:attr:`~workbench.plants.adhesion.AdhesionModel.traction_graded`), the
    slope an extra last parameter (``params = (*params, grade)``), evaluated
    as the level forms plus :func:`grade_terms` (so a zero slope gives the
    level forms' values bit for bit)."""
    mdl = adhesion_model()
    args = (mdl.v, mdl.lam, *[mdl.params[k] for k in PARAM_ORDER])
    out = {}
    for name, (f1, f2, f3) in (("traction", mdl.traction), ("braking", mdl.braking)):
        exprs = (f1, f2, f3, sp.diff(f2, mdl.lam), sp.diff(f3, mdl.lam))
        out[name] = lambdify(args, exprs, modules=backend, cse=True)
    if not graded:
        return out
    level, terms = out, grade_terms(backend)

    def on_slope(name):
        f, g = level[name], terms[name]
        return lambda v, lam, *p: tuple(a + b for a, b in zip(f(v, lam, *p[:-1]), g(v, lam, *p)))
    return {name: on_slope(name) for name in level}


@lru_cache(maxsize=4)
def grade_terms(backend: Literal["math", "numpy"]) -> dict:
    """The slope's terms of each form, (graded form) - (level form) of
    :class:`~workbench.plants.adhesion.AdhesionModel` simplified by sympy
    (-g grade in v', -(lambda - 1) g grade / v in lambda' of eq 13, ...), as
    functions of (v, lambda, *params, grade)."""
    mdl = adhesion_model()
    args = (mdl.v, mdl.lam, *[mdl.params[k] for k in PARAM_ORDER], mdl.grade)
    out = {}
    for name, lev, gr in (("traction", mdl.traction, mdl.traction_graded),
                          ("braking", mdl.braking, mdl.braking_graded)):
        d = [sp.simplify(a - b) for a, b in zip(gr, lev)]
        exprs = (d[0], d[1], d[2], sp.diff(d[1], mdl.lam), sp.diff(d[2], mdl.lam))
        out[name] = sp.lambdify(args, exprs, modules=backend, cse=True)
    return out


class ScalarOps:
    """The few array functions the loop needs, for floats."""
    where = staticmethod(lambda c, a, b: a if c else b)
    maximum, minimum, abs = staticmethod(max), staticmethod(min), staticmethod(abs)
    expm1, sqrt = staticmethod(math.expm1), staticmethod(math.sqrt)
    any, logical_not = staticmethod(bool), staticmethod(lambda x: not x)
    batch = False


def _any_of(x) -> bool:
    """``np.any`` of a mask, by the array's own method when it is one (the
    loop asks this several times a step; the function form's dispatch costs
    more than the test)."""
    return x.any() if isinstance(x, np.ndarray) else bool(np.any(x))


class ArrayOps:
    """The same functions for numpy arrays (a batch of runs)."""
    where, maximum, minimum, abs = np.where, np.maximum, np.minimum, np.abs
    expm1, sqrt, logical_not = np.expm1, np.sqrt, np.logical_not
    any = staticmethod(_any_of)
    batch = True


def plant_forms(v, lam, p, fns, xp):
    """(v', lambda'_0, lambda'_u, J_0, J_u) of the form that applies (eq 12 for
    lambda >= 0, eq 15 otherwise): lambda' = lambda'_0 + lambda'_u u."""
    if not xp.batch:
        return fns["traction" if lam >= 0 else "braking"](v, lam, *p)
    pos = lam >= 0
    if pos.all() or not pos.any():     # one form for the whole batch (NaN: "braking")
        return fns["traction" if pos.all() else "braking"](v, lam, *p)
    tr = fns["traction"](v, lam, *p)
    br = fns["braking"](v, lam, *p)
    return tuple(np.where(pos, a, b) for a, b in zip(tr, br))


def held_torque_rhs(p, v_floor: float = 1e-3):
    """``rhs(u)`` -> ``f(t, (v, lambda))``: the plant's right-hand side with
    parameters ``p`` under the constant torque u (the form by the sign of
    lambda, :func:`plant_forms`; the speed floored as :func:`plant_step`
    floors it), floats, for an ODE solver (e.g. scipy's ``solve_ivp``)."""
    fns = model_functions("math")

    def rhs(u):
        def f(t, x):
            y = plant_forms(max(x[0], v_floor), x[1], p, fns, ScalarOps)
            return (y[0], y[1] + y[2] * u)
        return f
    return rhs


def holding_torque(v: float, lam: float, p) -> float:
    """The torque that holds the creep ratio at ``lam`` at speed ``v``
    (lambda' = 0 on the traction form, eq 13, lambda >= 0)."""
    y = model_functions("math")["traction"](v, lam, *p)
    return -y[1] / y[2]


def wheel_speed(v, lam, r, xp):
    """omega (rad/s) from v and lambda, eqs (4)-(5)."""
    return xp.where(lam >= 0, v / (1.0 - xp.minimum(lam, 0.999)), v * (1.0 + lam)) / r


def creep_speed(v, lam, xp):
    """v_s = v_w - v (m/s)."""
    return xp.where(lam >= 0, lam * v / (1.0 - xp.minimum(lam, 0.999)), lam * v)


def phi1(z, xp):
    """phi1(z) = (e^z - 1) / z (1 + z/2 near 0)."""
    if not xp.batch:
        return math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z
    big = xp.abs(z) > 1e-8
    if big.all():          # the usual case: the same values, fewer array passes
        return np.expm1(z) / z
    zs = xp.where(big, z, 1.0)
    return xp.where(big, xp.expm1(zs) / zs, 1.0 + 0.5 * z)


def exp_euler(v, lam, f1, f2, z, dt, xp):
    """(v + dt f1, lambda + dt phi1(z) f2), z = dt d lambda'/d lambda."""
    return v + dt * f1, lam + dt * phi1(z, xp) * f2


#: Largest creep-ratio change of one exponential-Euler step; larger steps are
#: halved (the adhesion curve is far from linear over such a change).
MAX_DLAMBDA = 0.02


#: Halvings :func:`stiff_step` may make (smallest sub-step dt / 2**MAX_HALVINGS).
MAX_HALVINGS = 8


def stiff_step(v, lam, u, dt, evalf, xp, mask=True, depth=0):
    """Explicit Euler in v, exponential Euler in the stiff creep ratio, with
    ``evalf(v, lam) -> (v', lambda'_0, lambda'_u, J_0, J_u)``; halved
    recursively (up to MAX_HALVINGS times) while the creep ratio would move by
    more than MAX_DLAMBDA; in a batch, per run (runs where ``mask`` is false
    are never halved), so each run follows its single-run trajectory."""
    return stiff_step_flagged(v, lam, u, dt, evalf, xp, mask, depth)[:2]


def stiff_step_flagged(v, lam, u, dt, evalf, xp, mask, depth):
    """:func:`stiff_step` plus ``unresolved``: true (per run) when a sub-step
    of dt / 2**MAX_HALVINGS still moved the creep ratio by more than
    MAX_DLAMBDA, i.e. the step could not be resolved."""
    f1, f20, f2u, j0, ju = evalf(v, lam)
    out = exp_euler(v, lam, f1, f20 + f2u * u, (j0 + ju * u) * dt, dt, xp)
    big = ~(xp.abs(out[1] - lam) <= MAX_DLAMBDA) & mask if xp.batch else \
        not abs(out[1] - lam) <= MAX_DLAMBDA
    if depth < MAX_HALVINGS and xp.any(big):
        sub = mask & big if xp.batch else mask
        hv, hl, bad1 = stiff_step_flagged(v, lam, u, dt / 2, evalf, xp, sub, depth + 1)
        nv, nl, bad2 = stiff_step_flagged(hv, hl, u, dt / 2, evalf, xp, sub, depth + 1)
        if not xp.batch:
            return nv, nl, bad1 or bad2
        # per run: only the runs that need it take the half steps, so a run
        # of a batch follows exactly its single-run trajectory
        return np.where(big, nv, out[0]), np.where(big, nl, out[1]), big & (bad1 | bad2)
    return out[0], out[1], big


def plant_step(x, u, p, dt, fns, xp, v_floor=1e-3, mask=True, with_flag=False):
    """One step of the adhesion plant (module docstring), the form (eq 12 or
    15) chosen by the sign of lambda; ``with_flag``: also return the
    ``unresolved`` flag of :func:`_stiff_step`."""
    if not xp.batch:
        out = _scalar_plant_step(x[0], x[1], u, dt, p, fns, v_floor, 0)
        return out if with_flag else out[:2]
    out = stiff_step_flagged(x[0], x[1], u, dt,
                      lambda v, lam: plant_forms(xp.maximum(v, v_floor), lam, p, fns, xp), xp, mask, 0)
    return out if with_flag else out[:2]


def _scalar_plant_step(v, lam, u, dt, p, fns, v_floor, depth):
    """:func:`plant_step` of a single run (floats, ``with_flag``): the
    operations of :func:`stiff_step_flagged` with :func:`plant_forms` and
    :func:`exp_euler`, in the same order (bit for bit), written out (every
    case run calls it once a step)."""
    f1, f20, f2u, j0, ju = fns["traction" if lam >= 0 else "braking"](max(v, v_floor), lam, *p)
    z = (j0 + ju * u) * dt
    nv = v + dt * f1
    nl = lam + dt * (math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z) * (f20 + f2u * u)
    big = not abs(nl - lam) <= MAX_DLAMBDA
    if depth < MAX_HALVINGS and big:
        hv, hl, bad1 = _scalar_plant_step(v, lam, u, dt / 2, p, fns, v_floor, depth + 1)
        nv, nl, bad2 = _scalar_plant_step(hv, hl, u, dt / 2, p, fns, v_floor, depth + 1)
        return nv, nl, bad1 or bad2
    return nv, nl, big


@lru_cache(maxsize=1)
def creep_rate_coefficient():
    """S(params) with S / v the creep-ratio rate |d lambda'/d lambda| at
    lambda = 0, the steepest point of the adhesion curve: m g r^2 mu'(0) / J
    (eq 13, dominant term; the rest is O(zeta / J))."""
    mdl = adhesion_model()
    p = mdl.params
    S = sp.diff(mdl.mu_traction, mdl.lam).subs(mdl.lam, 0) * p["m"] * p["g"] * p["r"] ** 2 / p["J"]
    return sp.lambdify([p[k] for k in PARAM_ORDER], S, "math")
