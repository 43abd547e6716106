"""The basin check of the general pipeline: (sympy closed loop, operating
point, gain) -> certified level set and the verdict for named states.

A design of any kind that has a sympy closed-loop vector field, its
equilibrium and the linearisation A + B K can call :func:`check_basin`
(``basin = true``) and render the result with
:func:`workbench.roa.render.render_basin_markdown`.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import sympy as sp

from ..errors import ModelError
from .basin import BasinEstimate, LevelVerdict, estimate_basin
from .lyapunov import lyapunov_P
from .problem import BasinProblem


@dataclass(frozen=True)
class PointCheck:
    """Verdict for one named state (e.g. the state at a phase switch).

    Attributes
    ----------
    label : str
    x : tuple of float
        The state.
    verdict : LevelVerdict
        CERTIFIED: inside the certified level set; REFUTED: its level holds
        a point with V' >= 0 (V cannot certify it); INCONCLUSIVE otherwise.
    """

    label: str
    x: tuple
    verdict: LevelVerdict


@dataclass(frozen=True)
class BasinCheck:
    """Result of :func:`check_basin` (rendering: :mod:`workbench.roa.render`).

    Attributes
    ----------
    estimate : BasinEstimate
    points : tuple of PointCheck
    loop : str
        Which loop the vector field is (stated in the report), e.g.
        "delay-free closed loop under exact prediction (paper 003, Theorems 2-3)".
    """

    estimate: BasinEstimate
    points: tuple
    loop: str


def largest_level_in_box(P: np.ndarray, x_eq: np.ndarray, lo: Sequence[float],
                         hi: Sequence[float]) -> float:
    """Largest c whose ellipsoid {V <= c} has its bounding box inside [lo, hi]."""
    d = np.minimum(np.asarray(x_eq, float) - np.asarray(lo, float),
                   np.asarray(hi, float) - np.asarray(x_eq, float))
    if not np.all(d > 0):
        raise ModelError("the equilibrium lies outside the domain box")
    return float(np.min(d * d / np.diag(np.linalg.inv(P))) * (1 - 1e-6))


def search_level(prob: BasinProblem, points, domain: tuple | None = None,
                 c_search: float | None = None) -> float:
    """The level a basin search examines: ``c_search`` if given, else 4 x the
    largest level V of ``points`` (states), capped by the largest ellipsoid
    whose bounding box fits in ``domain`` = (lo, hi) (that level alone when no
    point lies away from x*).

    Raises
    ------
    ModelError
        When neither gives a positive level.
    """
    levels = [float(prob.V(np.asarray(x, float)[None, :])[0]) for x in points]
    if c_search is None:
        c_search = 4.0 * max(levels) if levels and max(levels) > 0 else None
    if domain is not None:
        cap = largest_level_in_box(prob.P, prob.x_eq, *domain)
        c_search = cap if c_search is None else min(c_search, cap)
    if c_search is None or not c_search > 0:
        raise ModelError("check_basin needs c_search, a domain box or points away from x*")
    return c_search


def check_basin(f: Sequence[sp.Expr], states: Sequence[sp.Symbol], x_eq: Sequence[float], *,
                A_cl, points: Sequence[tuple[str, Sequence[float]]] = (),
                c_search: float | None = None, domain: tuple | None = None,
                names: Sequence[str] | None = None, loop: str = "delay-free closed loop",
                seed: int = 0, min_width: float = 2.0**-12) -> BasinCheck:
    """Certified basin of a closed loop and the verdict for named states.

    Parameters
    ----------
    f, states, x_eq
        Delay-free closed-loop vector field (sympy, in ``states`` only) and
        its equilibrium.
    A_cl : (n, n) array_like
        Linearisation A + B K; P from A_cl' P + P A_cl = -I (a modal P, for a
        loop with slow and fast modes: :class:`workbench.features.basin_loop.GainLoop`).
    points : sequence of (label, state)
        States to judge (e.g. the states at the phase switches).
    c_search : float, optional
        Largest level examined; default 4 x the largest level of ``points``
        (at least the level of the domain box when only that is given).
    domain : (lo, hi), optional
        Box outside which the model is not meant to be used: c_search is
        capped at the largest ellipsoid whose bounding box fits inside it.
    names : sequence of str, optional
        Display names of the states.
    loop : str
        Statement of which loop ``f`` is.
    seed : int
        Seed of the falsifier.
    min_width : float
        Smallest box width of the cover, relative to the box's distance from x*.

    Raises
    ------
    ModelError
        When no P can be formed (A_cl not Hurwitz), or no search level is known.
    """
    prob = BasinProblem(f, states, x_eq, lyapunov_P(A_cl), P_source="lyapunov", names=names)
    c_search = search_level(prob, [x for _, x in points], domain, c_search)
    est: BasinEstimate = estimate_basin(prob, c_search, seed=seed, min_width=min_width)
    checks = tuple(PointCheck(label, tuple(float(v) for v in x), est.point_verdict(x))
                   for label, x in points)
    return BasinCheck(est, checks, loop)
