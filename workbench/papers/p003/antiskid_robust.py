"""Study ``antiskid-robust``: one antiskid gain for dry and wet rail, a range
of cruise speeds and mass +/- 5 %, with a decay rate, compared with a
printed gain checked at the same operating points.

Design tables: ``[plant.common]`` (the model constants shared by every
point), ``[plant.dry]`` / ``[plant.wet]`` (adhesion a, b, c per rail), each
``{ value, unit, source }``; ``[operating_points]`` (rails, v_d list in m/s,
mass factors); ``[synthesis]`` (decay rate alpha, eps grid, numerical
settings); ``[[compare]]`` (printed gains to check at every point).

Each operating point is the cruise linearisation of paper 003 (eqs 17-32,
:func:`~workbench.symbolic.linearise.linearise_cruise`) at its solved
equilibrium lambda_d. Certificates hold at the listed points only.

The robust synthesis, its per-point checks (:mod:`workbench.features.robust_gain`),
the gains compared at every point and their table are general
(:mod:`workbench.features.point_gains`, rows read as
:class:`~workbench.features.other_gains.OtherGain`); this module keeps paper
003's operating points (its adhesion plant per rail, speed and mass, and
their lambda_d quantities).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import DesignError, ModelError
from ...features.other_gains import OtherGain, load_other_gains
from ...features.robust_gain import (RobustGain, RobustSettings, load_robust_settings,
                                     robust_quantities, robust_quantity_names, run_robust)
from ...jsonable import json_method
from ...plants.units import ADHESION_003 as PARAMETER_UNITS
from ...reader import Quantity, Reader

if TYPE_CHECKING:   # the solvers load when a design runs
    from ...crosscheck import PointCheck

RAIL_KEYS = ("a", "b", "c")


@dataclass(frozen=True)
class Point:
    """One operating point: rail, cruise speed (m/s), mass factor, and its
    linearisation (A, B) at the solved lambda_d."""

    rail: str
    v_d: float
    mass_factor: float
    lambda_d: float
    A: np.ndarray
    B: np.ndarray

    @property
    def id(self) -> str:
        return f"{self.rail}-v{self.v_d:g}-m{self.mass_factor:g}"


@dataclass(frozen=True)
class RobustSpec:
    common: dict
    rails: dict
    points: tuple[Point, ...]
    settings: RobustSettings
    compare: tuple[OtherGain, ...]
    requirements: object = None     # RequirementsSpec ([requirements]) or None


@dataclass(frozen=True)
class RobustResult:
    points: tuple[Point, ...]
    compare: tuple[OtherGain, ...]
    robust: RobustGain                       # the robust K and its per-point checks
    compared: tuple[tuple[PointCheck, ...], ...]
    requirements: object = None     # workbench.requirements.RequirementResult or None

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"eps": "robust.synthesis.eps",
                   "h_certified": "robust.synthesis.bracket.h_certified",
                   "K": "robust.synthesis.K", "reason": "robust.synthesis.reason"}
    to_json = json_method


def _points(path, common, rails, op: Reader) -> tuple[Point, ...]:
    from ...plants.adhesion import NumericAdhesion
    from ...symbolic.linearise import linearise_cruise
    names = op.raw("rails")
    if not isinstance(names, list) or not names or any(r not in rails for r in names):
        raise op.fail("rails", names, "a list of rails among " + ", ".join(sorted(rails)))
    speeds = op.numbers("v_d", positive=True, what="cruise speeds (m/s)")
    factors = op.numbers("mass_factor", positive=True, what="mass factors")
    op.finish()
    out = []
    for rail in names:
        for v in speeds:
            for f in factors:
                vals = {k: q.value for k, q in common.items()}
                vals.update({k: q.value for k, q in rails[rail].items()})
                vals["m"] *= f
                plant = NumericAdhesion.from_dict(vals)
                try:
                    lam = plant.cruise_lambda(v)
                except ModelError as exc:
                    raise DesignError(path, "operating_points.v_d", v,
                                      f"a speed with a cruise equilibrium on {rail} rail "
                                      f"({exc})") from None
                lin = linearise_cruise(plant, v, lam)
                out.append(Point(rail, v, f, lam, lin.A, lin.B))
    return tuple(out)


class AntiskidRobust:
    kind = "antiskid-robust"

    def load(self, root: Reader) -> RobustSpec:
        plant = root.table("plant")
        cm = plant.table("common")
        common = {k: cm.quantity(k, u, positive=True)
                  for k, u in PARAMETER_UNITS.items() if k not in RAIL_KEYS}
        cm.finish()
        rails: dict[str, dict[str, Quantity]] = {}
        for rail in ("dry", "wet"):
            if plant.has(rail):
                rt = plant.table(rail)
                rails[rail] = {k: rt.quantity(k, "1", positive=True) for k in RAIL_KEYS}
                rt.finish()
        plant.finish()
        points = _points(root.path, common, rails, root.table("operating_points"))
        syn = root.table("synthesis")
        settings = load_robust_settings(syn)
        syn.finish()
        compare = load_other_gains(root, points[0].B.shape[0], "compare")
        from ...kinds.delay_feedback.requirements import load_rate_requirements
        return RobustSpec(common, rails, points, settings, compare,
                          load_rate_requirements(root))

    def quantity_names(self, spec: RobustSpec) -> set[str]:
        ids = [p.id for p in spec.points]
        names = robust_quantity_names(ids, spec.points[0].A.shape[0])
        names |= {f"points[{i}].lambda_d" for i in ids}
        from ...kinds.delay_feedback.requirements import requirement_quantity_names
        names |= requirement_quantity_names(spec.requirements)
        names |= {"requirements.K1", "requirements.K2"} if spec.requirements else set()
        from ...features.point_gains import compare_quantity_names
        return names | compare_quantity_names(ids, spec.compare)

    def run(self, design) -> RobustResult:
        s: RobustSpec = design.spec
        pts = [(p.A, p.B) for p in s.points]
        from ...features.point_gains import check_named_gains
        robust = run_robust(pts, s.settings)
        compared = check_named_gains(pts, s.compare, s.settings.order, s.settings.margin)
        req = None
        if s.requirements is not None:       # the design to requirements (issue 31)
            from ...requirements import Requirements, design_to_requirements
            r = s.requirements
            req = design_to_requirements(pts, Requirements(r.delay, r.decay_rate,
                                                           objective=r.objective))
        return RobustResult(s.points, s.compare, robust, compared, req)

    def quantities(self, res: RobustResult) -> dict:
        ids = [p.id for p in res.points]
        q = robust_quantities(ids, res.points[0].A.shape[0], res.robust)
        q |= {f"points[{p.id}].lambda_d": p.lambda_d for p in res.points}
        if res.requirements is not None:
            from ...kinds.delay_feedback.requirements import requirement_quantities
            q.update(requirement_quantities(res.requirements))
            K = res.requirements.K
            q["requirements.K1"] = None if K is None else float(K[0, 0])
            q["requirements.K2"] = None if K is None else float(K[0, 1])
        from ...features.point_gains import compare_quantities
        return q | compare_quantities(ids, res.compare, res.compared)


STUDY = AntiskidRobust()
