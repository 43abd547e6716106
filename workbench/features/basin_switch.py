"""Phase switches of a switched run judged against the basin of the law that
takes over: the switch states of a run's cases, and the claimable verdict and
fate of each case at each switch.

General: a case's switch state comes from a callback ``state_of(case) ->
(label, x)`` (a state with a non-finite coordinate: the case never reached
that switch), and the judge of a switch is whatever gives, per judged state,
an :class:`~workbench.outcome.Outcome` and the fate of the trajectory from it
(e.g. :func:`workbench.features.basin_points.check_points` for a law with a
fixed equilibrium, :func:`workbench.features.basin_scalar.scalar_verdict` for
a loop frozen at the switch instant). Nothing here knows the plant, the laws
or the cases' metrics.

Quantities, per switch ``s`` and case label ``c``:
``switch.{s}[{c}].in_basin`` (the outcome's name) and ``switch.{s}[{c}].fate``;
a case not judged at that switch (it never reached it) gets None for both.
"""
from __future__ import annotations

import math

#: Key of a case's quantities at one switch.
SWITCH_KEY = "switch.{switch}[{label}]"
#: Quantities of each case at each switch.
SWITCH_FIELDS = ("in_basin", "fate")


def switch_states(cases, state_of) -> list:
    """(label, x) per case whose switch state is finite, in the cases' order
    (``state_of(case)`` -> (label, sequence of float)); x as a tuple of float."""
    out = []
    for c in cases:
        label, x = state_of(c)
        x = tuple(float(v) for v in x)
        if all(math.isfinite(v) for v in x):
            out.append((label, x))
    return out


def switch_quantity_names(labels, switches) -> set:
    """Names of :func:`switch_quantities` for the case ``labels`` at each of
    the ``switches`` (switch names)."""
    return {f"{SWITCH_KEY.format(switch=s, label=lab)}.{f}"
            for s in switches for lab in labels for f in SWITCH_FIELDS}


def switch_quantities(labels, judged: dict) -> dict:
    """Values of :func:`switch_quantity_names`: ``judged`` maps a switch name
    to its judged states, ((label, outcome, fate), ...); every other case label
    gets None."""
    q = {}
    for s, rows in judged.items():
        for lab in labels:
            q.update(dict.fromkeys(
                (f"{SWITCH_KEY.format(switch=s, label=lab)}.{f}" for f in SWITCH_FIELDS)))
        for lab, outcome, fate in rows:
            at = SWITCH_KEY.format(switch=s, label=lab)
            q[f"{at}.in_basin"], q[f"{at}.fate"] = outcome.name, fate
    return q
