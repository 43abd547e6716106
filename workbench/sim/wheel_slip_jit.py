"""The wheel-slip stepping kernel of :mod:`workbench.sim.wheel_slip`, compiled (numba).

The same step, one run at a time, as ``numba.njit`` functions: explicit Euler
in v, exponential Euler in the stiff creep ratio, halved up to
:data:`~workbench.sim.wheel_slip.MAX_HALVINGS` times while the creep ratio
would move by more than :data:`~workbench.sim.wheel_slip.MAX_DLAMBDA`. The
model functions are *not* retyped: they are the ``sympy.lambdify`` (``math``
backend, common subexpressions eliminated) of
:func:`workbench.plants.adhesion.adhesion_model`, exactly the functions
:func:`~workbench.sim.wheel_slip.model_functions` builds, handed to
``numba.njit`` (numba compiles their bytecode). Each operation is the one the
numpy path performs, in the same order, so a compiled run follows its batched
numpy trajectory up to the last bit of the library functions (exp, expm1).

Importing this module needs numba; the functions compile at first use (a
few seconds). The kernels that call them are kept on disk once compiled
(:mod:`workbench.sim.jit_cache`: numba's own ``cache=True`` cannot, the
lambdified model has no source file), so a machine compiles them once.

Parameters ``p`` are float arrays in :data:`~workbench.sim.wheel_slip.PARAM_ORDER`;
``form`` selects the model: :data:`BY_SIGN` (eq 12 for lambda >= 0, eq 15
otherwise: the plant), :data:`TRACTION` (eq 65) or :data:`BRAKING` (eq 70),
:data:`GRADED` (the plant on a slope). The perturbations of
:mod:`workbench.sim.perturb` are at the end, written as there.
"""
from __future__ import annotations

import math

import numba

from .wheel_slip import MAX_DLAMBDA, MAX_HALVINGS, PARAM_ORDER, grade_terms, model_functions

#: Model forms of :func:`forms` (GRADED: as BY_SIGN on a slope, p = (*params, grade)).
BY_SIGN, TRACTION, BRAKING, GRADED = 0, 1, 2, 3

_JIT = dict(nogil=True, error_model="numpy")   # numpy's inf/nan, never ZeroDivisionError
#: The small hot functions are inlined into their callers (numba IR): a call
#: costs as much as the arithmetic, and inlined steps of independent runs
#: overlap in the processor (:mod:`workbench.papers.p003.antiskid_kernel`). numba
#: types an inlined body again at every call site, so the rarely taken ones
#: (the graded forms) stay calls: compiling the sweep kernel takes ~16 s
#: instead of ~40 s with everything inlined, at the same speed.
_JITI = dict(_JIT, inline="always")


def _unpacked(fn, extra: int = 0, inline: bool = True):
    """``fn(v, lam, *params)`` as a compiled ``f(v, lam, p)`` with p an array in
    PARAM_ORDER (plus ``extra`` entries: the slope of the graded forms; the
    wrapper's source is generated from PARAM_ORDER)."""
    inner = numba.njit(**(_JITI if inline else _JIT))(fn)
    args = ", ".join(f"p[{i}]" for i in range(len(PARAM_ORDER) + extra))
    ns = {"inner": inner}
    exec(f"def f(v, lam, p):\n    return inner(v, lam, {args})\n", ns)
    return numba.njit(**(_JITI if inline else _JIT))(ns["f"])


_fns = model_functions("math")
#: eq (13) (y1, y2, y3, dy2/dlambda, dy3/dlambda), compiled
traction = _unpacked(_fns["traction"])
#: eq (16) (z1, z2, z3, dz2/dlambda, dz3/dlambda), compiled
braking = _unpacked(_fns["braking"])
_terms = grade_terms("math")
_traction_slope = _unpacked(_terms["traction"], 1, inline=False)
_braking_slope = _unpacked(_terms["braking"], 1, inline=False)


@numba.njit(**_JIT)
def traction_graded(v, lam, p):
    """eq (13) on a slope, p = (*params, grade): the level form plus the
    slope's terms (:func:`~workbench.sim.wheel_slip.model_functions`, ``graded``)."""
    a, b = traction(v, lam, p), _traction_slope(v, lam, p)
    return a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4]


@numba.njit(**_JIT)
def braking_graded(v, lam, p):
    """eq (16) on a slope (as :func:`traction_graded`)."""
    a, b = braking(v, lam, p), _braking_slope(v, lam, p)
    return a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3], a[4] + b[4]


@numba.njit(**_JITI)
def fmax(a, b):
    """``numpy.maximum`` of two floats (NaN wins)."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a >= b else b


@numba.njit(**_JITI)
def fmin(a, b):
    """``numpy.minimum`` of two floats (NaN wins)."""
    if a != a:
        return a
    if b != b:
        return b
    return a if a <= b else b


@numba.njit(**_JITI)
def forms(v, lam, p, form):
    """(v', lambda'_0, lambda'_u, J_0, J_u) of the model ``form`` (module
    docstring; BY_SIGN: a NaN creep ratio takes eq 15, as the numpy path)."""
    if form == GRADED:
        return traction_graded(v, lam, p) if lam >= 0 else braking_graded(v, lam, p)
    if form == TRACTION or (form == BY_SIGN and lam >= 0):
        return traction(v, lam, p)
    return braking(v, lam, p)


@numba.njit(**_JITI)
def phi1(z):
    """(e^z - 1) / z (1 + z/2 near 0)."""
    if abs(z) > 1e-8:
        return math.expm1(z) / z
    return 1.0 + 0.5 * z


@numba.njit(**_JIT)
def _halved(v, lam, u, dt, p, v_floor, form):
    """The halvings of :func:`stiff_step` once the whole step ``dt`` moved
    lambda too far: the recursion of
    :func:`workbench.sim.wheel_slip.stiff_step_flagged` (each half halved
    again while it moves lambda too far, up to MAX_HALVINGS levels), run as
    a loop over its sub-steps in the recursion's order, with the same
    operations (a recursive numba function cannot be loaded from the disk
    cache of :mod:`workbench.sim.jit_cache`: the loaded code crashes). Bit
    ``k`` of ``pending``: the second half at level ``k`` is still to do;
    ``d`` is dt / 2**k (halving and doubling are exact)."""
    k, d, pending, bad = 1, dt / 2, 2, False
    while True:
        f1, f20, f2u, j0, ju = forms(fmax(v, v_floor), lam, p, form)
        nv = v + d * f1
        nl = lam + d * phi1((j0 + ju * u) * d) * (f20 + f2u * u)
        big = not abs(nl - lam) <= MAX_DLAMBDA
        if k < MAX_HALVINGS and big:       # halve: its first half next
            k, d = k + 1, d / 2
            pending |= 1 << k
            continue
        v, lam, bad = nv, nl, bad or big
        while k > 0 and not (pending >> k) & 1:     # up to a level with a half to do
            k, d = k - 1, d * 2
        if k == 0:
            return v, lam, bad
        pending &= ~(1 << k)


@numba.njit(**_JITI)
def stiff_step(v, lam, u, dt, p, v_floor, form):
    """(v, lambda, unresolved) after one step of :func:`forms` (speed
    floored at ``v_floor`` in the model), halved recursively as
    :func:`workbench.sim.wheel_slip.stiff_step_flagged`."""
    return stiff_step_at(v, lam, u, dt, p, v_floor, form, forms(fmax(v, v_floor), lam, p, form))


@numba.njit(**_JITI)
def stiff_step_at(v, lam, u, dt, p, v_floor, form, fm):
    """:func:`stiff_step` given ``fm = forms(fmax(v, v_floor), lam, p, form)``
    (for a caller that keeps the forms for another use)."""
    f1, f20, f2u, j0, ju = fm
    nv = v + dt * f1
    nl = lam + dt * phi1((j0 + ju * u) * dt) * (f20 + f2u * u)
    big = not abs(nl - lam) <= MAX_DLAMBDA
    if MAX_HALVINGS > 0 and big:
        return _halved(v, lam, u, dt, p, v_floor, form)
    return nv, nl, big


@numba.njit(**_JIT)
def wheel_speed(v, lam, r):
    """omega (rad/s) from v and lambda, eqs (4)-(5)."""
    if lam >= 0:
        return v / (1.0 - fmin(lam, 0.999)) / r
    return v * (1.0 + lam) / r


@numba.njit(**_JIT)
def creep_speed(v, lam):
    """v_s = v_w - v (m/s)."""
    if lam >= 0:
        return lam * v / (1.0 - fmin(lam, 0.999))
    return lam * v


@numba.njit(**_JIT)
def measured_state(v, lam, zv, zw, sv, sw, r_plant, r_ctrl, v_floor):
    """:func:`workbench.sim.perturb.measured_state` for one run."""
    omega = wheel_speed(v, lam, r_plant)
    vm = fmax(v + sv * zv, v_floor)
    vw = fmax((omega + sw * zw) * r_ctrl, 0.0)
    if vw >= vm:
        return vm, 1.0 - vm / vw
    return vm, vw / vm - 1.0


@numba.njit(**_JIT)
def delay_at(t, lo, hi, period, phase):
    """:func:`workbench.sim.perturb.delay_at` for one run."""
    x = t / period + phase
    tri = abs(2.0 * (x - math.floor(x)) - 1.0)
    return fmin(fmax(lo + (hi - lo) * tri, lo), hi)


@numba.njit(**_JIT)
def split_delay(h, dt):
    """:func:`workbench.sim.perturb.split_delays` for one run."""
    q = h / dt
    n = math.floor(q + 0.5)
    if abs(q - n) < 1e-9:
        return int(n), 0.0
    fl = math.floor(q)
    return int(fl), q - fl
