"""A closed loop whose gain enters as symbols, and its basin problem for a
candidate modal Lyapunov matrix: what a gain sweep of a basin verdict
(:mod:`workbench.features.basin_points`) builds per gain and candidate.

General: the loop is any sympy vector field in its states and gain symbols;
its Jacobian and Hessians are derived once (symbolically, with the gain
free) and the gain substituted per value, so that a sweep over gains does not
differentiate again.
"""
from __future__ import annotations

import sympy as sp

from ..roa import BasinProblem, modal_P
from ..roa.check import search_level


def derivatives(f, states) -> tuple:
    """(Jacobian, Hessians) of the vector field ``f`` in ``states`` (sympy lists)."""
    J = [[sp.diff(fi, s) for s in states] for fi in f]
    H = [[[sp.diff(Jki, s) for s in states] for Jki in row] for row in J]
    return J, H


def at_gain(f, derivs, symbols, K) -> tuple:
    """(f, (J, H)) with the gain symbols replaced by the values ``K`` (floats)."""
    rep = {k: sp.Float(float(v)) for k, v in zip(symbols, K)}
    put = lambda e: e.xreplace(rep)
    J, H = derivs
    return ([put(e) for e in f], ([[put(e) for e in row] for row in J],
                                  [[[put(e) for e in r] for r in Hk] for Hk in H]))


def modal_problem(f, states, x_eq, A_cl, weights, *, derivs=None, names=None, points=(),
                  domain=None, c_search=None, P_source: str = "optimised") -> tuple:
    """(BasinProblem with P = :func:`~workbench.roa.modal_P` (A_cl, weights), level
    searched: :func:`~workbench.roa.check.search_level` of ``points`` in ``domain``)."""
    P = modal_P(A_cl, weights)
    prob = BasinProblem(f, states, x_eq, P, P_source=P_source, names=names, derivatives=derivs)
    return prob, search_level(prob, points, domain, c_search)
