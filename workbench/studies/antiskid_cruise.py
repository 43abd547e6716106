"""Study ``antiskid-cruise``: paper 003's cruise linearisation and the
certified delay bound of problem (60), cross-checked with exact margins.

Design tables read here: ``[plant]`` (parameters with units and sources),
``[operating_point]`` (v_d, optional pinned lambda_d), ``[synthesis]``
(eps sweep and numerical settings) and ``[[synthesis.published]]`` (rows a
paper printed, compared with what we compute — data, never used as inputs
to the synthesis itself).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..design import Quantity, Reader
from ..errors import DesignError, ModelError
from ..lmi.core import DEFAULT_MARGIN
from ..margins import DelayMargin, delay_margin_eig
from ..plants.adhesion import PARAMETER_UNITS, NumericAdhesion
from ..report.markdown import Figure, Rendered, fmt, latex_matrix, md_table
from ..symbolic.linearise import Linearisation, linearise_cruise
from ..synthesis import (SynthesisRow, SynthesisSettings, certify_given_gain, eps_for_bound,
                         synthesize_delay_bound)

PARAM_DOC = {
    "a": "adhesion peak parameter", "b": "adhesion slope parameter",
    "c": "adhesion decay parameter", "J": "wheel moment of inertia", "r": "wheel radius",
    "m": "mass (quarter train)", "zeta": "viscous friction", "c0": "resistance, constant",
    "c1": "resistance, linear", "c2": "resistance, quadratic", "g": "gravity",
}


@dataclass(frozen=True)
class Published:
    """A row a paper printed: eps, h_m and K (for comparison only)."""

    eps: float
    h_m: float
    K: tuple[float, ...]
    source: str


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


@dataclass(frozen=True)
class PublishedCheck:
    """What we find for a printed row.

    Attributes
    ----------
    row : Published
    h_ours : float or None
        Our h_certified at the same eps (None if eps not in the sweep).
    h_paper_K : float
        Largest delay the same criterion certifies with the printed K.
    h_paper_K_refuted : float
    exact_paper_K : DelayMargin
        Exact margin of the loop closed with the printed K.
    eps_matching : float or None
        The eps at which our bound equals the printed h_m (None: not found
        in [eps_lo, eps_hi] of the sweep).
    """

    row: Published
    h_ours: float | None
    h_paper_K: float
    h_paper_K_refuted: float
    exact_paper_K: DelayMargin
    eps_matching: float | None


@dataclass(frozen=True)
class CruiseResult:
    lambda_opt: float
    lambda_d_solved: float
    lambda_d_used: float
    lin: Linearisation
    rows: tuple[SynthesisRow, ...]
    published: tuple[PublishedCheck, ...]

    def row(self, eps: float) -> SynthesisRow:
        return next(r for r in self.rows if r.eps == eps)

    def to_json(self) -> dict:
        return {"lambda_opt": self.lambda_opt, "lambda_d_solved": self.lambda_d_solved,
                "lambda_d_used": self.lambda_d_used,
                "A": self.lin.A.tolist(), "B": self.lin.B.tolist(),
                "rows": [r.to_json() for r in self.rows]}


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
        eps = syn.numbers("eps", positive=True, what="eps values")
        if len(set(eps)) != len(eps):
            raise syn.fail("eps", list(eps), "distinct eps values")
        settings = SynthesisSettings(
            margin=syn.number("margin", default=DEFAULT_MARGIN, positive=True, hi=1e-2),
            rel_tol=syn.number("rel_tol", default=1e-4, positive=True, hi=0.1),
            h_max=syn.number("h_max", default=100.0, positive=True),
        )
        published = []
        for pr in syn.tables("published", default=[]):
            e = pr.number("eps", positive=True)
            h = pr.number("h_m", positive=True)
            K = pr.numbers("K", min_len=2, what="gain entries")
            if len(K) != 2:
                raise pr.fail("K", list(K), "two gain entries [k1, k2]")
            published.append(Published(e, h, K, pr.string("source")))
            pr.finish()
        compare = syn.boolean("compare_published", default=True)
        syn.finish()
        plant_values = {k: q.value for k, q in params.items()}
        try:  # an impossible operating point is bad input, found at load time
            NumericAdhesion.from_dict(plant_values).cruise_lambda(v_d.value)
        except ModelError as exc:
            raise DesignError(root.path, "operating_point.v_d", v_d.value,
                              f"a speed with a creep-region equilibrium ({exc})") from None
        return CruiseSpec(rail, params, v_d, pinned, eps, settings, tuple(published), compare)

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
        for p in spec.published:
            for f in ("h_paper_K", "exact_margin_paper_K", "eps_matching"):
                names.add(f"published[eps={_eps_key(p.eps)}].{f}")
        return names

    # -- run -------------------------------------------------------------------
    def run(self, design) -> CruiseResult:
        spec: CruiseSpec = design.spec
        plant = NumericAdhesion.from_dict({k: q.value for k, q in spec.params.items()})
        lam_opt = plant.lambda_opt()
        lam_solved = plant.cruise_lambda(spec.v_d.value)
        lam_used = spec.lambda_d_pinned.value if spec.lambda_d_pinned else lam_solved
        lin = linearise_cruise(plant, spec.v_d.value, lam_used)
        rows = synthesize_delay_bound(lin.A, lin.B, spec.eps, spec.settings)
        checks = []
        if spec.compare_published:
            eps_lo, eps_hi = min(spec.eps) / 2, max(spec.eps) * 1.5
            for p in spec.published:
                ours = next((r.h_certified for r in rows if r.eps == p.eps), None)
                K = np.array([p.K])
                br = certify_given_gain(lin.A, lin.B, K, p.eps, spec.settings)
                em = delay_margin_eig(lin.A, lin.B @ K)
                match = eps_for_bound(lin.A, lin.B, p.h_m, eps_lo, eps_hi,
                                      settings=spec.settings)
                checks.append(PublishedCheck(p, ours, br.h_certified, br.h_refuted, em, match))
        return CruiseResult(lam_opt, lam_solved, lam_used, lin, rows, tuple(checks))

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
        for c in res.published:
            base = f"published[eps={_eps_key(c.row.eps)}]"
            q[f"{base}.h_paper_K"] = c.h_paper_K
            q[f"{base}.exact_margin_paper_K"] = c.exact_paper_K.h
            q[f"{base}.eps_matching"] = c.eps_matching
        return q

    # -- render ----------------------------------------------------------------
    def render(self, design, res: CruiseResult) -> Rendered:
        from .antiskid_cruise_render import render
        return render(design, res)


STUDY = AntiskidCruise()
