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

The robust synthesis over points, its per-point checks, the gains compared
at every point and the design to requirements are general
(:mod:`workbench.kinds.delay_feedback.robust_points`, which takes any points
with an id and their A, B); this module keeps paper 003's operating points
(its adhesion plant per rail, speed and mass, and their lambda_d quantities).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ...errors import DesignError, ModelError
from ...features.quantities import Declared, DeclaredQuantities
from ...kinds.delay_feedback.robust_points import (RobustPoints, RobustPointsResult,
                                                   load_robust_points, robust_points_quantities,
                                                   run_robust_points)
from ...plants.units import ADHESION_003 as PARAMETER_UNITS
from ...reader import Reader

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


def _points(path, common, rails, op: Reader) -> tuple[Point, ...]:
    from ...plants.adhesion import NumericAdhesion
    from ...symbolic.linearise import linearise_cruise
    names = op.strings("rails", sorted(rails))
    speeds = op.numbers("v_d", positive=True, what="cruise speeds (m/s)")
    factors = op.numbers("mass_factor", positive=True, what="mass factors")
    op.finish()
    out = []
    for rail, v, f in itertools.product(names, speeds, factors):
        vals = {k: q.value for k, q in (common | rails[rail]).items()}
        vals["m"] *= f
        plant = NumericAdhesion.from_dict(vals)
        try:
            lam = plant.cruise_lambda(v)
        except ModelError as exc:
            raise DesignError(path, "operating_points.v_d", v, f"a speed with a cruise "
                              f"equilibrium on {rail} rail ({exc})") from None
        lin = linearise_cruise(plant, v, lam)
        out.append(Point(rail, v, f, lam, lin.A, lin.B))
    return tuple(out)


#: Every claimable quantity of an ``antiskid-robust`` design.
TABLE = (*robust_points_quantities(),
         Declared("points[{i}].lambda_d", "1", lambda r, i, p: p.lambda_d,
                  over=lambda spec: [{"i": p.id, "p": p} for p in spec.points]))


class AntiskidRobust(DeclaredQuantities):
    kind = "antiskid-robust"
    TABLE = TABLE

    def load(self, root: Reader) -> RobustPoints:
        plant = root.table("plant")
        common = plant.table("common").quantities(
            {k: u for k, u in PARAMETER_UNITS.items() if k not in RAIL_KEYS}, positive=True)
        rails = {rail: plant.table(rail).quantities(dict.fromkeys(RAIL_KEYS, "1"), positive=True)
                 for rail in ("dry", "wet") if plant.has(rail)}
        plant.finish()
        return load_robust_points(root, _points(root.path, common, rails,
                                                root.table("operating_points")))

    def run(self, design) -> RobustPointsResult:
        return run_robust_points(design.spec)


STUDY = AntiskidRobust()
