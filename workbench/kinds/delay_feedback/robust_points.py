"""One gain for a list of operating points, each a linear delay loop
x' = A_i x + B_i u(t - h): the robust gain with its per-point checks
(:mod:`workbench.features.robust_gain`), the named gains compared there
(:mod:`workbench.features.point_gains`) and, with ``[requirements]``, the
gain designed to requirements over the same points (:mod:`workbench.requirements`).

A study that owns its plant builds the points (any objects with an ``id``
and the matrices ``A`` and ``B``) and keeps only that: it reads the tables
below with :func:`load_robust_points`, computes with :func:`run_robust_points`
and lists :func:`robust_points_quantities` in its
:class:`~workbench.features.quantities.Declared` table.

Design tables: ``[synthesis]`` (:func:`~workbench.features.robust_gain.load_robust_settings`),
``[[compare]]`` (rows of :class:`~workbench.features.other_gains.OtherGain`),
``[requirements]`` (optional, :func:`.requirements.load_rate_requirements`).
Quantities: those of the robust gain, ``compare[NAME]...``,
``requirements.<row>.<field>`` and ``requirements.K1``, ``K2``, ... (the
first input's row of the gain designed to requirements).
"""
from __future__ import annotations

from dataclasses import dataclass

from ...features.quantities import Group
from ...jsonable import json_method
from ...reader import Reader

__all__ = ["RobustPoints", "RobustPointsResult", "load_robust_points",
           "robust_points_quantities", "run_robust_points"]


@dataclass(frozen=True)
class RobustPoints:
    """The points (``id``, ``A``, ``B`` each), the synthesis settings
    (:class:`~workbench.features.robust_gain.RobustSettings`), the gains to
    compare and the ``[requirements]`` (a ``RequirementsSpec`` or None)."""

    points: tuple
    settings: object
    compare: tuple = ()
    requirements: object = None

    @property
    def ids(self) -> list[str]:
        return [p.id for p in self.points]


@dataclass(frozen=True)
class RobustPointsResult:
    """The robust gain (:class:`~workbench.features.robust_gain.RobustGain`),
    each compared gain's checks per point, and the design to requirements
    (a ``RequirementResult`` or None)."""

    spec: RobustPoints
    robust: object
    compared: tuple
    requirements: object = None

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"eps": "robust.synthesis.eps",
                   "h_certified": "robust.synthesis.bracket.h_certified",
                   "K": "robust.synthesis.K", "reason": "robust.synthesis.reason"}
    to_json = json_method


def load_robust_points(root: Reader, points) -> RobustPoints:
    """The tables of the module docstring for these ``points``."""
    from ...features.other_gains import load_other_gains
    from ...features.robust_gain import load_robust_settings
    from .requirements import load_rate_requirements
    syn = root.table("synthesis")
    settings = load_robust_settings(syn)
    syn.finish()
    compare = load_other_gains(root, points[0].B.shape[0], "compare")
    return RobustPoints(tuple(points), settings, compare, load_rate_requirements(root))


def run_robust_points(s: RobustPoints) -> RobustPointsResult:
    """The robust gain, the compared gains and the design to requirements."""
    from ...features.point_gains import check_named_gains
    from ...features.robust_gain import run_robust
    pts = [(p.A, p.B) for p in s.points]
    compared = check_named_gains(pts, s.compare, s.settings.order, s.settings.margin)
    req = None
    if s.requirements is not None:       # the design to requirements (issue 31)
        from ...requirements import Requirements, design_to_requirements
        r = s.requirements
        req = design_to_requirements(pts, Requirements(r.delay, r.decay_rate,
                                                       objective=r.objective))
    return RobustPointsResult(s, run_robust(pts, s.settings), compared, req)


def _names(s: RobustPoints) -> set[str]:
    from ...features.point_gains import compare_quantity_names
    from ...features.robust_gain import robust_quantity_names
    from .requirements import requirement_quantity_names
    n = s.points[0].A.shape[0]
    names = robust_quantity_names(s.ids, n) | compare_quantity_names(s.ids, s.compare)
    if s.requirements is not None:
        names |= {f"requirements.K{j + 1}" for j in range(n)}
    return names | requirement_quantity_names(s.requirements)


def _values(r: RobustPointsResult) -> dict:
    from ...features.point_gains import compare_quantities
    from ...features.robust_gain import robust_quantities
    from .requirements import requirement_quantities
    s = r.spec
    n = s.points[0].A.shape[0]
    q = robust_quantities(s.ids, n, r.robust)
    if r.requirements is not None:
        K = r.requirements.K
        q |= requirement_quantities(r.requirements)
        q |= {f"requirements.K{j + 1}": None if K is None else float(K[0, j])
              for j in range(n)}
    return q | compare_quantities(s.ids, s.compare, r.compared)


def robust_points_quantities() -> tuple:
    """The entries of a :class:`~workbench.features.quantities.Declared` table
    (the spec is a :class:`RobustPoints`, the result a :class:`RobustPointsResult`)."""
    return (Group(_names, _values),)
