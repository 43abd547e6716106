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

The gains compared at every point and their table are general
(:mod:`workbench.features.point_gains`, rows read as
:class:`~workbench.features.other_gains.OtherGain`); this module keeps paper
003's operating points (its adhesion plant per rail, speed and mass).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ...errors import DesignError, ModelError
from ...features.other_gains import OtherGain, load_other_gains
from ...jsonable import json_method
from ...plants.units import ADHESION_003 as PARAMETER_UNITS
from ...reader import Quantity, Reader

if TYPE_CHECKING:   # the solvers load when a design runs
    from ...crosscheck import PointCheck
    from ...lmi.robust import RobustSynthesis

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
    alpha: float
    eps_grid: tuple[float, ...]
    golden_steps: int
    rel_tol: float
    h_max: float
    margin: float
    order: int
    gain_fraction: float
    gain_digits: int
    compare: tuple[OtherGain, ...]
    requirements: object = None     # RequirementsSpec ([requirements]) or None


@dataclass(frozen=True)
class RobustResult:
    points: tuple[Point, ...]
    compare: tuple[OtherGain, ...]
    alpha: float
    order: int
    synthesis: RobustSynthesis
    checks: tuple[PointCheck, ...]           # robust K, per point
    abscissa: tuple[float, ...]              # spectral abscissa at h_certified, per point
    compared: tuple[tuple[PointCheck, ...], ...]
    requirements: object = None     # workbench.requirements.RequirementResult or None

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"eps": "synthesis.eps", "h_certified": "synthesis.bracket.h_certified",
                   "K": "synthesis.K", "reason": "synthesis.reason"}
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
        from ...lmi.core import DEFAULT_MARGIN
        from ...lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION
        spec = dict(
            alpha=syn.number("alpha", nonneg=True, hi=10.0, what="decay rate (1/s)"),
            eps_grid=syn.numbers("eps_grid", positive=True, min_len=2, what="eps values",
                                 lo=1e-6, hi=1e6),
            golden_steps=int(syn.number("golden_steps", default=3, integer=True, lo=0, hi=20)),
            rel_tol=syn.number("rel_tol", default=1e-2, positive=True, hi=0.1),
            h_max=syn.number("h_max", default=10.0, lo=1e-3, hi=1e4, what="number (s)"),
            margin=syn.number("margin", default=DEFAULT_MARGIN, positive=True, hi=1e-2),
            order=int(syn.number("analysis_order", default=2, integer=True, lo=0, hi=6)),
            gain_fraction=syn.number("gain_fraction", default=DEFAULT_FRACTION, positive=True,
                                     hi=1.0, what="fraction of h_certified"),
            gain_digits=int(syn.number("gain_digits", default=DEFAULT_DIGITS, integer=True,
                                       lo=2, hi=8)))
        syn.finish()
        compare = load_other_gains(root, points[0].B.shape[0], "compare")
        from ...kinds.delay_feedback.requirements import load_rate_requirements
        return RobustSpec(common, rails, points, compare=compare,
                          requirements=load_rate_requirements(root), **spec)

    def quantity_names(self, spec: RobustSpec) -> set[str]:
        names = {"synthesis.h_certified", "synthesis.h_gain", "synthesis.eps", "synthesis.K1",
                 "synthesis.K2",
                 "robust.all_stable", "robust.min_exact_margin", "robust.max_abscissa_at_h",
                 "robust.min_exact_over_certified"}
        for p in spec.points:
            names |= {f"points[{p.id}].{f}" for f in ("exact_margin", "h_certified",
                                                        "abscissa_at_h", "lambda_d")}
        from ...kinds.delay_feedback.requirements import requirement_quantity_names
        names |= requirement_quantity_names(spec.requirements)
        names |= {"requirements.K1", "requirements.K2"} if spec.requirements else set()
        from ...features.point_gains import compare_quantity_names
        return names | compare_quantity_names([p.id for p in spec.points], spec.compare)

    def run(self, design) -> RobustResult:
        s: RobustSpec = design.spec
        pts = [(p.A, p.B) for p in s.points]
        from ...crosscheck import check_gain
        from ...lmi.robust import synthesize_robust
        from ...margins import spectral_abscissa
        syn = synthesize_robust(pts, alpha=s.alpha, eps_grid=s.eps_grid,
                                golden_steps=s.golden_steps, rel_tol=s.rel_tol,
                                margin=s.margin, h_hi=s.h_max, gain_fraction=s.gain_fraction,
                                gain_digits=s.gain_digits)
        checks, absc = (), ()
        if syn.K is not None:
            checks = check_gain(pts, syn.K, N=s.order, margin=s.margin)
            h = syn.gain.h_certified          # what the rounded canonical K certifies
            absc = tuple(spectral_abscissa(A, B @ syn.K, h) for A, B in pts)
        from ...features.point_gains import check_named_gains
        compared = check_named_gains(pts, s.compare, s.order, s.margin)
        req = None
        if s.requirements is not None:       # the design to requirements (issue 31)
            from ...requirements import Requirements, design_to_requirements
            r = s.requirements
            req = design_to_requirements(pts, Requirements(r.delay, r.decay_rate,
                                                           objective=r.objective))
        return RobustResult(s.points, s.compare, s.alpha, s.order, syn, checks, absc, compared,
                            req)

    def quantities(self, res: RobustResult) -> dict:
        syn = res.synthesis
        h = syn.bracket.h_certified
        h_gain = syn.gain.h_certified if syn.gain else 0.0
        q = {"synthesis.h_certified": h if h > 0 and syn.K is not None else None,  # no gain
             "synthesis.h_gain": h_gain if h_gain > 0 else None, "synthesis.eps": syn.eps,
             "synthesis.K1": None if syn.K is None else float(syn.K[0, 0]),
             "synthesis.K2": None if syn.K is None else float(syn.K[0, 1])}
        spec_points = res.points
        if res.checks:
            q["robust.all_stable"] = "yes" if all(c.stable_at_zero for c in res.checks) else "no"
            q["robust.min_exact_margin"] = min(c.exact.h for c in res.checks)
            q["robust.max_abscissa_at_h"] = max(res.abscissa)
            q["robust.min_exact_over_certified"] = (min(c.exact.h for c in res.checks) / h_gain
                                                    if h_gain > 0 else None)
            for p, c, a in zip(spec_points, res.checks, res.abscissa):
                q[f"points[{p.id}].exact_margin"] = c.exact.h
                q[f"points[{p.id}].h_certified"] = c.h_certified
                q[f"points[{p.id}].abscissa_at_h"] = a
        for p in spec_points:
            q[f"points[{p.id}].lambda_d"] = p.lambda_d
        if res.requirements is not None:
            from ...kinds.delay_feedback.requirements import requirement_quantities
            q.update(requirement_quantities(res.requirements))
            K = res.requirements.K
            q["requirements.K1"] = None if K is None else float(K[0, 0])
            q["requirements.K2"] = None if K is None else float(K[0, 1])
        from ...features.point_gains import compare_quantities
        return q | compare_quantities([p.id for p in spec_points], res.compare, res.compared)


STUDY = AntiskidRobust()
