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
:func:`switch_basin_quantities` adds those of the certified level set of the
law with a fixed equilibrium and of a gain sweep at a switch state.
"""
from __future__ import annotations

import math

from .basin import LEVEL_QUANTITIES, level_quantities
from .basin_points import gain_sweep_quantities, gain_sweep_quantity_names

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


def switch_basin_quantity_names(labels, switches, entry: str | None = None) -> set:
    """Names of :func:`switch_basin_quantities`: the certified level
    (:data:`~workbench.features.basin.LEVEL_QUANTITIES`), each case of ``labels``
    at each of the ``switches`` and, given the swept ``entry``, the gain sweep's
    (:func:`~workbench.features.basin_points.gain_sweep_quantity_names`)."""
    names = set(LEVEL_QUANTITIES) | switch_quantity_names(labels, switches)
    return names if entry is None else names | gain_sweep_quantity_names(entry)


def switch_basin_quantities(estimate, labels, judged: dict, sweep=None, entry: str = "") -> dict:
    """Values of :func:`switch_basin_quantity_names`: the level set ``estimate``'s
    (a :class:`~workbench.roa.BasinEstimate`), :func:`switch_quantities` of
    ``judged`` and, when ``sweep`` is given, its
    :func:`~workbench.features.basin_points.gain_sweep_quantities` of ``entry``."""
    q = level_quantities(estimate)
    q.update(switch_quantities(labels, judged))
    if sweep is not None:
        q.update(gain_sweep_quantities(sweep, entry))
    return q
