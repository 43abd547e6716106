"""The basin check for a ``delay-feedback`` design: (sympy plant model,
operating point, gain) -> :class:`workbench.roa.check.BasinCheck`.

The closed loop is x' = f(x, u* + K (x - x*)) with the design's parameter
values substituted: the *delay-free* loop, i.e. the loop seen under exact
prediction (as paper 003's Theorems 2-3 argue); the input delay is the LMI
certificate's subject, not the basin's. A design that asks for ``basin =
true`` renders the result with :func:`workbench.roa.render.render_basin_markdown`.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import sympy as sp

from ..roa.check import BasinCheck, check_basin
from .delay_feedback_model import OperatingPoint, PlantModel, linearise

LOOP = ("delay-free closed loop x' = f(x, u* + K (x - x*)): the loop under exact prediction "
        "(as in paper 003's Theorems 2-3); the input delay is the subject of the LMI certificate")


def delay_feedback_basin(model: PlantModel, values: dict, op: OperatingPoint, K, *,
                         points: Sequence = (), c_search: float | None = None,
                         domain: tuple | None = None, weights=None,
                         seed: int = 0) -> BasinCheck:
    """Certified basin of the delay-free loop of a delay-feedback design.

    Parameters
    ----------
    model : PlantModel
        The design's sympy plant.
    values : dict
        Parameter values (SI).
    op : OperatingPoint
        Equilibrium (x*, u*).
    K : (m, n) array_like
        Gain, u = u* + K (x - x*).
    points : sequence of (label, state)
        States to judge (absolute coordinates).
    c_search, domain, weights, seed
        As :func:`workbench.roa.check.check_basin` (``weights``: modal P;
        default: the Lyapunov equation with Q = I).
    """
    K = np.atleast_2d(np.asarray(K, float))
    f = model.substituted(model.f, values)
    law = {u: sp.Float(float(op.u[i])) + sum(sp.Float(float(K[i, j])) * (x - sp.Float(float(op.x[j])))
                                             for j, x in enumerate(model.x))
           for i, u in enumerate(model.u)}
    fcl = [e.xreplace(law) for e in f]
    A, B = linearise(model, values, op)
    return check_basin(fcl, model.x, op.x, A_cl=A + B @ K, weights=weights, points=points,
                       c_search=c_search, domain=domain, names=model.spec.state_names,
                       loop=LOOP, seed=seed)
