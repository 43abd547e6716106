"""The basin verdict of a one-state loop x' = g(x) on an interval [lo, hi]
(e.g. a loop frozen at a switch instant, when one state moves much faster
than the others).

A one-state trajectory moves monotonically towards the nearest equilibrium in
the direction of g; so, from the state x_s:

* no equilibrium between x_s and the interval's end in that direction, with
  the sign of g proven by interval arithmetic on the whole way: REFUTED --
  x_s lies in the basin of no equilibrium, and reaches the end within the
  time the proven bound of |g| gives;
* a stable equilibrium x* in that direction: the level-set certificate of
  :mod:`workbench.roa` (V = p (x - x*)^2, p from the Lyapunov equation) and
  the state's verdict; a state beyond the certified level that is proven to
  move towards it (sign of g on the way) is CERTIFIED too;
* otherwise INCONCLUSIVE.

:class:`FrozenSwitch` holds such a verdict for a state where a law whose
reference varies in time takes over: the verdict of the loop frozen at the
switch instant (reference held, the fast state alone moving), and the fate of
the time-varying loop from the same state
(:func:`~workbench.features.basin_trajectory.time_varying_fate`), which drops
the frozen assumptions; :func:`frozen_switch` builds both from the loop's
vector field in its states and the reference (and its rate) as symbols.
Rendering: :mod:`.basin_scalar_render`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..outcome import Outcome
from ..plants.lambdify_cache import lambdify
from ..roa import BasinProblem, estimate_basin, lyapunov_P
from ..roa.interval import IntervalFunction
from .basin_trajectory import time_varying_fate


@dataclass(frozen=True)
class ScalarVerdict:
    """Result of :func:`scalar_verdict`.

    Attributes
    ----------
    outcome : Outcome
    why : str
        "no equilibrium" (REFUTED), "sign not proven", "nearest equilibrium
        unstable", "monotone approach, level set" or "level set".
    direction : float
        Sign of g at the state (+1 or -1).
    star : float or None
        Equilibrium the state moves to (None: none).
    rate : float or None
        A proven lower bound of |g| on the way (to the end, or to the certified level).
    level : (float, float) or None
        Level-set case: (V at the state (upper bound), c_certified).
    """

    outcome: Outcome
    why: str
    direction: float
    star: float | None
    rate: float | None
    level: tuple | None


def prove_sign(g, x, a: float, b: float, sign: float, *, max_boxes: int = 20_000):
    """A lower bound m > 0 of sign * g on [a, b] (interval bisection), or None."""
    fn = IntervalFunction([sign * g], (x,))
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


def equilibria(gn, a: float, b: float) -> list:
    """Sign changes of the numeric g on a fine grid of [a, b], refined by brentq."""
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


def scalar_verdict(g, x, x_s: float, lo: float, hi: float, *, name: str = "x",
                   seed: int = 0) -> ScalarVerdict:
    """Verdict for the state ``x_s`` of x' = g(x) on [lo, hi] (module docstring).

    Parameters
    ----------
    g : sympy expression
        The vector field, in the symbol ``x`` only.
    x : sympy Symbol
    x_s : float
        The state judged.
    lo, hi : float
        The interval the model is meant for (its ends: the loop has left it).
    name : str
        Display name of the state (the basin estimate's).
    seed : int
        Falsifier seed of the level-set case.
    """
    gn = lambdify(x, g, "math")
    d = 1.0 if gn(x_s) > 0 else -1.0
    ends = (x_s, hi) if d > 0 else (lo, x_s)
    eqs = [e for e in equilibria(gn, *ends) if abs(e - x_s) > 1e-12]
    if not eqs:
        m = prove_sign(g, x, ends[0], ends[1], d)
        if m is not None:
            return ScalarVerdict(Outcome.REFUTED, "no equilibrium", d, None, m, None)
        return ScalarVerdict(Outcome.INCONCLUSIVE, "sign not proven", d, None, None, None)
    star = min(eqs, key=lambda e: abs(e - x_s))
    slope = (gn(star + 1e-7) - gn(star - 1e-7)) / 2e-7
    if not slope < 0:
        return ScalarVerdict(Outcome.INCONCLUSIVE, "nearest equilibrium unstable", d, star,
                             None, None)
    P = lyapunov_P([[slope]])
    prob = BasinProblem([g], (x,), (star,), P, P_source="lyapunov", names=(name,))
    cap = float(P[0, 0]) * min(star - lo, hi - star) ** 2 * (1 - 1e-6)
    c = min(4.0 * float(P[0, 0]) * (x_s - star) ** 2, cap)
    est = estimate_basin(prob, c, seed=seed)
    pv = est.point_verdict((x_s,))
    level = (pv.level, est.c_certified)
    if pv.outcome is not Outcome.CERTIFIED and est.c_certified > 0:
        # monotone approach: d g > 0 proven from x_s to the certified level's edge
        edge = star - d * math.sqrt(est.c_certified / float(P[0, 0])) * (1 - 1e-9)
        m = prove_sign(g, x, *sorted((x_s, edge)), d)
        if m is not None:
            return ScalarVerdict(Outcome.CERTIFIED, "monotone approach, level set", d, star, m,
                                 level)
    return ScalarVerdict(pv.outcome, "level set", d, star, None, level)


@dataclass(frozen=True)
class FrozenSwitch:
    """A switch state judged on the loop frozen at the switch instant, and the
    fate of the time-varying loop from it (module docstring).

    Attributes
    ----------
    label : str
    x : tuple of float
        The full state at the switch.
    reference : float
        The reference at the switch instant, held in the frozen loop.
    verdict : ScalarVerdict
        Of the frozen one-state loop (:func:`scalar_verdict`).
    fate : str
        Of the time-varying loop: the escape word, the settled word or "undecided".
    t_fate : float or None
        When it escaped (time after the switch).
    """

    label: str
    x: tuple
    reference: float
    verdict: ScalarVerdict
    fate: str
    t_fate: float | None

    @property
    def outcome(self) -> Outcome:
        return self.verdict.outcome

    @property
    def judged(self) -> tuple:
        """(label, outcome, fate) (:func:`~workbench.features.basin_switch.switch_quantities`)."""
        return self.label, self.outcome, self.fate


def frozen_switch(label: str, field, states, refs, x, index: int, reference, t0: float,
                  lo: float, hi: float, *, T: float, settled, events=(), rtol: float = 1e-8,
                  max_step: float = math.inf, t_frozen: float | None = None, name: str = "x",
                  seed: int = 0) -> FrozenSwitch:
    """The :class:`FrozenSwitch` of the state ``x`` where a law tracking a
    time-varying reference takes over at ``t0`` (module docstring).

    Parameters
    ----------
    label : str
    field : sequence of sympy expressions
        The closed loop's vector field, in ``states`` and ``refs``.
    states : tuple of sympy Symbol
    refs : (Symbol, Symbol)
        The reference r and its rate dr/dt as they enter ``field``.
    x : sequence of float
        The state at the switch.
    index : int
        The fast state: the frozen loop is ``field[index]`` in it alone, the
        other states held at ``x``, r held at its value at ``t_frozen`` and dr/dt = 0;
        its verdict is :func:`scalar_verdict` on [lo, hi].
    reference : callable
        (t, x) -> (r, dr/dt) along the time-varying loop.
    t0 : float
        The switch instant; the time-varying loop runs over [t0, t0 + T].
    lo, hi : float
        Interval of the fast state (its ends: the loop has left its model).
    T : float
    settled : callable
        (x, r) -> bool: the time-varying loop has settled at its end ("tracks").
    events, rtol, max_step
        Of the time-varying loop (:func:`~.basin_trajectory.time_varying_fate`).
    t_frozen : float, optional
        The instant the loop is frozen at (default ``t0``).
    name : str
        Display name of the fast state.
    seed : int
        Falsifier seed of the level-set case.
    """
    x = tuple(float(v) for v in x)
    r0 = float(reference(t0 if t_frozen is None else t_frozen, x)[0])
    held = {s: sp.Float(v) for i, (s, v) in enumerate(zip(states, x)) if i != index}
    g = field[index].xreplace({**held, refs[0]: sp.Float(r0), refs[1]: sp.Integer(0)})
    sv = scalar_verdict(g, states[index], x[index], lo, hi, name=name, seed=seed)
    fn = lambdify((*states, *refs), list(field), "math")
    fate, t_fate = time_varying_fate(lambda t, *s: fn(*s, *reference(t, s)), x, t0, T,
                                     lambda t, s: settled(s, reference(t, s)[0]), events=events,
                                     rtol=rtol, max_step=max_step)
    return FrozenSwitch(label, x, r0, sv, fate, t_fate)
