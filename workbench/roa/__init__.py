"""Regions of attraction of nonlinear closed loops: verified level sets of a
quadratic Lyapunov function (interval arithmetic), with a falsifier.

Layering: imports only :mod:`workbench.errors` and the numeric stack (never
``studies``, ``report``, ``design``, ``sim``).

Public API: :class:`BasinProblem`, :func:`lyapunov_P`, :func:`modal_P`, :func:`estimate_basin`,
:class:`BasinEstimate`, :class:`LevelVerdict`,
:func:`render_basin_markdown`.
"""
from .basin import BasinEstimate, LevelVerdict, estimate_basin
from .lyapunov import lyapunov_P, modal_P
from .problem import BasinProblem

__all__ = ["BasinEstimate", "BasinProblem", "LevelVerdict", "estimate_basin",
           "lyapunov_P", "modal_P"]
