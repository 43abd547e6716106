"""Study ``antiskid-cruise``: paper 003's cruise linearisation and the
certified delay bound of problem (60), cross-checked with exact margins.

Design tables read here: ``[plant]`` (parameters with units and sources),
``[operating_point]`` (v_d, optional pinned lambda_d); the sweep of
``[synthesis]`` over eps with the rows a paper printed
(``[[synthesis.published]]``), the optional ``[tight]`` and
``[[other_gains]]`` are the general :mod:`workbench.features.sweep_study`'s,
which reads, computes and declares them on any single-input loop.

What stays here is paper 003's: the cruise linearisation of its adhesion
plant (eqs 17-32, :func:`operating_point`), the plant and operating-point
tables in its parameter names and the quantities of that operating point
(lambda_opt, lambda_d, the Taylor coefficients of eqs 18 and 23).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import DesignError, ModelError
from ...features.quantities import Declared, DeclaredQuantities
from ...features.sweep_study import (SweepResult, SweepSpec, load_sweep, run_sweep,
                                     sweep_quantities)
from ...jsonable import json_method
from ...plants.units import ADHESION_003 as PARAMETER_UNITS
from ...reader import Quantity, Reader

if TYPE_CHECKING:   # the symbolic model loads when a design runs
    from ...symbolic.linearise import Linearisation

PARAM_DOC = {
    "a": "adhesion peak parameter", "b": "adhesion slope parameter",
    "c": "adhesion decay parameter", "J": "wheel moment of inertia", "r": "wheel radius",
    "m": "mass (quarter train)", "zeta": "viscous friction", "c0": "resistance, constant",
    "c1": "resistance, linear", "c2": "resistance, quadratic", "g": "gravity",
}
#: The Taylor coefficients of eqs (18) and (23) (quantities ``linearisation.<name>``).
COEFFICIENTS = ("a1", "a2", "a3", "b1", "b2", "b3", "b4", "b5", "b6",
                "d1", "d2", "d3", "d4", "d5", "d6")


@dataclass(frozen=True)
class CruiseSpec:
    rail: str
    params: dict
    v_d: Quantity
    lambda_d_pinned: Quantity | None
    sweep: SweepSpec


@dataclass(frozen=True)
class CruiseResult:
    lambda_opt: float
    lambda_d_solved: float
    lambda_d_used: float
    lin: Linearisation
    sweep: SweepResult
    spec: CruiseSpec

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"lambda_opt": "lambda_opt", "lambda_d_solved": "lambda_d_solved",
                   "lambda_d_used": "lambda_d_used", "A": "lin.A", "B": "lin.B",
                   "rows": "sweep.rows"}
    to_json = json_method


def operating_point(spec: CruiseSpec) -> tuple[float, float, float, Linearisation]:
    """(lambda_opt, lambda_d solved, lambda_d used, linearisation) of a cruise spec."""
    from ...plants.adhesion import NumericAdhesion
    from ...symbolic.linearise import linearise_cruise
    plant = NumericAdhesion.from_dict({k: q.value for k, q in spec.params.items()})
    lam_solved = plant.cruise_lambda(spec.v_d.value)
    lam_used = spec.lambda_d_pinned.value if spec.lambda_d_pinned else lam_solved
    import numpy as np
    with np.errstate(all="ignore"):
        lin = linearise_cruise(plant, spec.v_d.value, lam_used)
    big = max(np.max(np.abs(lin.A)), np.max(np.abs(lin.B)))
    if not big <= 1e9:    # past it Clarabel's factorisations fail (a Rust panic at J = 1e-300)
        raise ModelError(f"the linearisation at v_d = {spec.v_d.value:g} m/s has an entry of "
                         f"{big:.3g}; expected a model whose A and B entries are finite and at "
                         "most 1e9 in magnitude (check the [plant] values)")
    return plant.lambda_opt(), lam_solved, lam_used, lin


#: Every claimable quantity of an ``antiskid-cruise`` design.
TABLE = (
    Declared("operating_point.lambda_d", "1", lambda r: r.lambda_d_used),
    Declared("operating_point.lambda_d_solved", "1", lambda r: r.lambda_d_solved),
    Declared("operating_point.lambda_opt", "1", lambda r: r.lambda_opt),
    Declared("operating_point.y1_residual", "m/s^2", lambda r: r.lin.y1_residual),
    Declared("linearisation.{k}", "?", lambda r, k: r.lin.coefficients[k],
             over=lambda spec: [{"k": k} for k in COEFFICIENTS]),
    *sweep_quantities(),
)


class AntiskidCruise(DeclaredQuantities):
    kind = "antiskid-cruise"
    TABLE = TABLE

    # -- load ----------------------------------------------------------------
    def load(self, root: Reader) -> CruiseSpec:
        plant = root.table("plant")
        plant.string("model", choices=("adhesion-003",))
        rail = plant.string("rail", choices=("dry", "wet"))
        params = plant.quantities(PARAMETER_UNITS, positive=True)
        op = root.table("operating_point")
        v_d = op.quantity("v_d", "m/s", positive=True, hi=150.0)
        pinned = op.quantity("lambda_d_pinned", "1", positive=True, hi=1.0, default=None)
        op.finish()
        syn = root.table("synthesis")
        syn.string("method", choices=("free-weighting-003",))
        sweep = load_sweep(root, syn)
        from ...plants.adhesion import NumericAdhesion
        plant_values = {k: q.value for k, q in params.items()}
        try:  # an impossible operating point is bad input, found at load time
            NumericAdhesion.from_dict(plant_values).cruise_lambda(v_d.value)
        except ModelError as exc:
            raise DesignError(root.path, "operating_point.v_d", v_d.value,
                              f"a speed with a creep-region equilibrium ({exc})") from None
        return CruiseSpec(rail, params, v_d, pinned, sweep)

    # -- run -------------------------------------------------------------------
    def run(self, design) -> CruiseResult:
        lam_opt, lam_solved, lam_used, lin = operating_point(design.spec)
        return CruiseResult(lam_opt, lam_solved, lam_used, lin,
                            run_sweep(lin.A, lin.B, design.spec.sweep), design.spec)

    def loop(self, design) -> tuple:
        """(A, B, header) of ``workbench synthesize delay-bound``
        (:func:`workbench.kinds.delay_feedback.cli.loop_sweep_command`)."""
        from ...report.markdown import fmt
        spec = design.spec
        _, lam_solved, lam, lin = operating_point(spec)
        return lin.A, lin.B, (
            f"{design.name}: problem (60) of paper 003 at v_d = {fmt(spec.v_d.value)} m/s, "
            f"lambda_d = {fmt(lam, 5)} ({'pinned' if spec.lambda_d_pinned else 'solved'}; "
            f"solved {fmt(lam_solved, 6)})")


STUDY = AntiskidCruise()
