"""Study ``antiskid-cruise``: paper 003's cruise linearisation and the
certified delay bound of problem (60), cross-checked with exact margins.

Design tables read here: ``[plant]`` (parameters with units and sources),
``[operating_point]`` (v_d, optional pinned lambda_d), ``[synthesis]``
(eps sweep and numerical settings), ``[[synthesis.published]]`` (rows a
paper printed, compared with what we compute — data, never used as inputs
to the synthesis itself) and the optional ``[tight]`` (Wirtinger-based
synthesis with its scalar searched automatically,
:mod:`workbench.lmi.tight_synthesis`, shown next to the paper's row) and
``[[other_gains]]`` (gains designed elsewhere, checked on this loop:
:mod:`workbench.features.other_gains`).

The general pieces live in :mod:`workbench.features` (the printed-row
comparison :mod:`~workbench.features.published_rows`, the foreign gains
:mod:`~workbench.features.other_gains`, the eps sweep's figures
:mod:`~workbench.features.eps_sweep`, which serve ``delay-feedback`` designs
too, and the ``[tight]`` comparison :mod:`~workbench.features.tight_compare`).
This module keeps what is paper 003's: the cruise linearisation of its
adhesion plant (eqs 17-32, :func:`operating_point`), the design tables in
its parameter names and the quantity names of its reports.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ...errors import DesignError, ModelError
from ...jsonable import json_method
from ...plants.units import ADHESION_003 as PARAMETER_UNITS
from ...reader import Quantity, Reader
from ...features.other_gains import (GainCheck, OtherGain, check_other_gains, load_other_gains,
                                     other_gain_quantities)
from ...features.other_gains import quantity_names as other_gain_names
from ...features.eps_sweep import read_eps, read_settings
from ...features.published_rows import (Published, PublishedCheck, load_published,
                                        published_quantities, published_quantity_names)
from ...features.tight_compare import (TIGHT_QUANTITIES, TightComparison, TightSettings,
                                       load_tight, run_tight, tight_quantities)

if TYPE_CHECKING:   # the solvers and the symbolic model load when a design runs
    from ...symbolic.linearise import Linearisation
    from ...synthesis import SynthesisRow, SynthesisSettings

PARAM_DOC = {
    "a": "adhesion peak parameter", "b": "adhesion slope parameter",
    "c": "adhesion decay parameter", "J": "wheel moment of inertia", "r": "wheel radius",
    "m": "mass (quarter train)", "zeta": "viscous friction", "c0": "resistance, constant",
    "c1": "resistance, linear", "c2": "resistance, quadratic", "g": "gravity",
}


@dataclass(frozen=True)
class CruiseSpec:
    rail: str
    params: dict
    v_d: Quantity
    lambda_d_pinned: Quantity | None
    eps: tuple[float, ...]
    settings: SynthesisSettings
    published: tuple[Published, ...]
    compare_published: bool
    tight: TightSettings | None = None
    other_gains: tuple[OtherGain, ...] = ()


@dataclass(frozen=True)
class CruiseResult:
    lambda_opt: float
    lambda_d_solved: float
    lambda_d_used: float
    lin: Linearisation
    rows: tuple[SynthesisRow, ...]
    published: tuple[PublishedCheck, ...]
    tight: TightComparison | None = None
    #: (h, spectral abscissa of x' = A x + B K x(t - h)) for the canonical gain
    #: of the row with the largest certified bound (the figure of the loop's set)
    abscissa_vs_h: tuple = ()
    #: gains of ``[[other_gains]]`` on this loop (:mod:`workbench.features.other_gains`)
    other_gains: tuple[GainCheck, ...] = ()

    def row(self, eps: float) -> SynthesisRow:
        return next(r for r in self.rows if r.eps == eps)

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"lambda_opt": "lambda_opt", "lambda_d_solved": "lambda_d_solved",
                   "lambda_d_used": "lambda_d_used", "A": "lin.A", "B": "lin.B",
                   "rows": "rows"}
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


def _eps_key(eps: float) -> str:
    return f"{eps:g}"


class AntiskidCruise:
    kind = "antiskid-cruise"

    # -- load ----------------------------------------------------------------
    def load(self, root: Reader) -> CruiseSpec:
        plant = root.table("plant")
        plant.string("model", choices=("adhesion-003",))
        rail = plant.string("rail", choices=("dry", "wet"))
        params = {}
        for k, unit in PARAMETER_UNITS.items():
            params[k] = plant.quantity(k, unit, positive=True)
        plant.finish()
        op = root.table("operating_point")
        v_d = op.quantity("v_d", "m/s", positive=True, hi=150.0)
        pinned = op.quantity("lambda_d_pinned", "1", positive=True, hi=1.0, default=None)
        op.finish()
        syn = root.table("synthesis")
        syn.string("method", choices=("free-weighting-003",))
        eps, settings = read_eps(syn), read_settings(syn)
        published = load_published(syn)
        compare = syn.boolean("compare_published", default=True)
        syn.finish()
        tight = load_tight(root, eps)
        other = load_other_gains(root)
        from ...plants.adhesion import NumericAdhesion
        plant_values = {k: q.value for k, q in params.items()}
        try:  # an impossible operating point is bad input, found at load time
            NumericAdhesion.from_dict(plant_values).cruise_lambda(v_d.value)
        except ModelError as exc:
            raise DesignError(root.path, "operating_point.v_d", v_d.value,
                              f"a speed with a creep-region equilibrium ({exc})") from None
        return CruiseSpec(rail, params, v_d, pinned, eps, settings, published, compare,
                          tight, other)

    def quantity_names(self, spec: CruiseSpec) -> set[str]:
        names = {"operating_point.lambda_d", "operating_point.lambda_d_solved",
                 "operating_point.lambda_opt", "operating_point.y1_residual", "exact_margin",
                 "synthesis.best.h_certified"}
        names |= {f"linearisation.{k}" for k in
                  ("a1", "a2", "a3", "b1", "b2", "b3", "b4", "b5", "b6",
                   "d1", "d2", "d3", "d4", "d5", "d6")}
        for e in spec.eps:
            for f in ("h_certified", "h_refuted", "K1", "K2", "exact_margin",
                      "exact_margin_siso", "ratio", "status"):
                names.add(f"synthesis.rows[eps={_eps_key(e)}].{f}")
        names |= published_quantity_names(spec.published)
        if spec.tight:
            names |= {f"tight.{k}" for k in TIGHT_QUANTITIES}
        return names | other_gain_names(spec.other_gains)

    # -- run -------------------------------------------------------------------
    def run(self, design) -> CruiseResult:
        from ...features.eps_sweep import abscissa_vs_h
        from ...features.published_rows import check_published
        from ...synthesis import synthesize_delay_bound
        spec: CruiseSpec = design.spec
        lam_opt, lam_solved, lam_used, lin = operating_point(spec)
        rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
        checks = (check_published(lin.A, lin.B, rows, spec.published, spec.eps, spec.settings)
                  if spec.compare_published else ())
        tight = (run_tight(lin.A, lin.B, spec.tight, spec.settings, rows, spec.published)
                 if spec.tight else None)
        return CruiseResult(lam_opt, lam_solved, lam_used, lin, rows, checks, tight,
                            abscissa_vs_h(lin.A, lin.B, rows),
                            check_other_gains(lin.A, lin.B, spec.other_gains))

    def quantities(self, res: CruiseResult) -> dict:
        q = {"operating_point.lambda_d": res.lambda_d_used,
             "operating_point.lambda_d_solved": res.lambda_d_solved,
             "operating_point.lambda_opt": res.lambda_opt,
             "operating_point.y1_residual": res.lin.y1_residual}
        q.update({f"linearisation.{k}": v for k, v in res.lin.coefficients.items()})
        for r in res.rows:
            base = f"synthesis.rows[eps={_eps_key(r.eps)}]"
            certified = r.status.value == "certified"
            q[f"{base}.h_certified"] = r.h_certified if certified else None
            q[f"{base}.h_refuted"] = r.h_refuted
            q[f"{base}.K1"] = r.K[0] if r.K else None
            q[f"{base}.K2"] = r.K[1] if r.K else None
            q[f"{base}.exact_margin"] = r.exact.h if r.exact else None
            q[f"{base}.exact_margin_siso"] = r.exact_siso.h if r.exact_siso else None
            q[f"{base}.ratio"] = r.ratio
            q[f"{base}.status"] = r.status.value
        best = max(res.rows, key=lambda r: r.h_certified)
        q["synthesis.best.h_certified"] = best.h_certified if best.h_certified > 0 else None
        q["exact_margin"] = best.exact.h if best.exact else None
        q.update(published_quantities(res.published))
        if res.tight:
            q.update(tight_quantities(res.tight))
        q.update(other_gain_quantities(res.other_gains))
        return q


STUDY = AntiskidCruise()
