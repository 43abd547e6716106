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
:mod:`~workbench.features.eps_sweep`) and serve ``delay-feedback`` designs
too. This module keeps what is paper 003's: the cruise linearisation of its
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
from ...features.published_rows import (Published, PublishedCheck, load_published,
                                        published_quantities, published_quantity_names)

if TYPE_CHECKING:   # the solvers and the symbolic model load when a design runs
    from ...crosscheck import PointCheck
    from ...lmi.tight_synthesis import TightSynthesis
    from ...margins import DelayMargin
    from ...symbolic.linearise import Linearisation
    from ...synthesis import SynthesisRow, SynthesisSettings

PARAM_DOC = {
    "a": "adhesion peak parameter", "b": "adhesion slope parameter",
    "c": "adhesion decay parameter", "J": "wheel moment of inertia", "r": "wheel radius",
    "m": "mass (quarter train)", "zeta": "viscous friction", "c0": "resistance, constant",
    "c1": "resistance, linear", "c2": "resistance, quadratic", "g": "gravity",
}


@dataclass(frozen=True)
class TightSettings:
    """``[tight]``: Wirtinger-based synthesis beyond the paper.

    Attributes
    ----------
    h_max : float
        Delay search cap (s) of the synthesis and of the analysis checks.
    grid : tuple[float, ...]
        Log grid of the descriptor scalar eps (refined by golden section).
    order : int
        Bessel-Legendre order N of the analysis check of each gain.
    reference_eps : float
        Row of the problem (60) sweep (and of the printed table) to compare with.
    """

    h_max: float
    grid: tuple[float, ...]
    order: int
    reference_eps: float


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
class TightComparison:
    """The tight synthesis next to the paper's row and our problem (60) row.

    Attributes
    ----------
    synthesis : TightSynthesis
    reference : SynthesisRow
        Our problem (60) row at ``reference_eps``.
    reference_check : PointCheck or None
        Bessel-Legendre bound and exact margin with that row's K.
    published : Published or None
        The printed row at ``reference_eps`` (if the design lists one).
    published_check : PointCheck or None
        Bessel-Legendre bound and exact margin with the printed K.
    open_loop_hurwitz : bool
        A itself is Hurwitz (then K = 0 is stable for every delay).
    check : PointCheck or None
        Bessel-Legendre analysis bound and exact margin with the tight K.
    exact_siso : DelayMargin or None
        python-control's single-input exact margin with the tight K.
    """

    synthesis: TightSynthesis
    reference: SynthesisRow
    reference_check: PointCheck | None
    published: Published | None
    published_check: PointCheck | None
    open_loop_hurwitz: bool
    check: PointCheck | None = None
    exact_siso: DelayMargin | None = None


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
        eps = syn.numbers("eps", positive=True, what="eps values", lo=1e-6, hi=1e6)
        if len(set(eps)) != len(eps):
            raise syn.fail("eps", list(eps), "distinct eps values")
        from ...lmi.core import DEFAULT_MARGIN
        from ...lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION
        from ...synthesis import SynthesisSettings
        settings = SynthesisSettings(
            margin=syn.number("margin", default=DEFAULT_MARGIN, positive=True, hi=1e-2),
            rel_tol=syn.number("rel_tol", default=1e-4, positive=True, hi=0.1),
            h_max=syn.number("h_max", default=100.0, lo=1e-3, hi=1e4, what="number (s)"),
            gain_fraction=syn.number("gain_fraction", default=DEFAULT_FRACTION, positive=True,
                                     hi=1.0, what="fraction of h_certified"),
            gain_digits=int(syn.number("gain_digits", default=DEFAULT_DIGITS, integer=True,
                                       lo=2, hi=8)),
        )
        published = load_published(syn)
        compare = syn.boolean("compare_published", default=True)
        syn.finish()
        tight = self._load_tight(root, eps) if root.has("tight") else None
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

    @staticmethod
    def _load_tight(root: Reader, eps: tuple[float, ...]) -> TightSettings | None:
        t = root.table("tight")
        enable = t.boolean("enable", default=True)
        h_max = t.number("h_max", default=10.0, lo=1e-3, hi=1e3, what="number (s)")
        grid = t.numbers("grid", default=(0.01, 0.1, 1.0, 10.0, 100.0), positive=True,
                         min_len=2, what="eps values", lo=1e-6, hi=1e6)
        if list(grid) != sorted(set(grid)):
            raise t.fail("grid", list(grid), "distinct eps values in increasing order")
        order = t.number("order", default=2, integer=True, lo=0, hi=8, what="integer N")
        ref = t.number("reference_eps", default=eps[0], positive=True)
        if ref not in eps:
            raise t.fail("reference_eps", ref, "one of synthesis.eps " + str(list(eps)))
        t.finish()
        return TightSettings(h_max, grid, int(order), ref) if enable else None

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
        tight = _run_tight(spec, lin, rows) if spec.tight else None
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
            q.update(_tight_quantities(res.tight))
        q.update(other_gain_quantities(res.other_gains))
        return q

    # -- render ----------------------------------------------------------------


#: Quantities of the ``[tight]`` comparison (prefixed ``tight.``).
TIGHT_QUANTITIES = ("eps", "h_certified", "h_analysis", "exact_margin", "exact_margin_siso",
                    "K1", "K2", "at_cap", "ratio_to_reference", "reference.h_analysis", "paper_K.h_analysis",
                    "paper_K.exact_margin")


def _run_tight(spec: CruiseSpec, lin: Linearisation, rows) -> TightComparison:
    """Tight synthesis, and the Bessel-Legendre + exact check of the reference gains."""
    import numpy as np

    from ...crosscheck import check_gain, check_tight
    from ...lmi.tight_synthesis import synthesize_tight
    ts, st = spec.tight, spec.settings
    syn = synthesize_tight(lin.A, lin.B, eps_grid=ts.grid, h_max=ts.h_max,
                           margin=st.margin, rel_tol=max(st.rel_tol, 1e-3),
                           gain_fraction=st.gain_fraction, gain_digits=st.gain_digits)
    own = (check_tight(lin.A, lin.B, syn.K, N=ts.order, margin=st.margin, h_hi=ts.h_max)
           if syn.K is not None else None)

    def check(K):
        return check_gain([(lin.A, lin.B)], np.array([K]), N=ts.order, margin=st.margin,
                          h_hi=ts.h_max)[0]
    ref = next(r for r in rows if r.eps == ts.reference_eps)
    pub = next((p for p in spec.published if p.eps == ts.reference_eps), None)
    return TightComparison(syn, ref, check(ref.K) if ref.K else None, pub,
                           check(pub.K) if pub else None,
                           bool(np.max(np.linalg.eigvals(lin.A).real) < 0),
                           own.check if own else None, own.exact_siso if own else None)


def _tight_quantities(t: TightComparison) -> dict:
    s, c = t.synthesis, t.check
    K = s.K.ravel() if s.K is not None else None
    q = {"eps": s.eps, "h_certified": s.h_certified if s.h_certified > 0 else None,
         "h_analysis": c.h_certified if c else None, "exact_margin": c.exact.h if c else None,
         "exact_margin_siso": t.exact_siso.h if t.exact_siso else None,
         "K1": None if K is None else float(K[0]), "K2": None if K is None else float(K[1]),
         "at_cap": "yes" if s.at_cap else "no",
         "ratio_to_reference": (s.h_certified / t.reference.h_certified
                                if s.h_certified > 0 and t.reference.h_certified > 0 else None),
         "reference.h_analysis": t.reference_check.h_certified if t.reference_check else None,
         "paper_K.h_analysis": t.published_check.h_certified if t.published_check else None,
         "paper_K.exact_margin": t.published_check.exact.h if t.published_check else None}
    return {f"tight.{k}": v for k, v in q.items()}


STUDY = AntiskidCruise()
