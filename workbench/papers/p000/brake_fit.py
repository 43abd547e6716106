"""Study ``brake-fit``: recover paper 000's brake parameters from SYNTHETIC logs.

Design tables: ``[plant]`` (the true parameters that generate the logs),
``[[logs]]``, ``[noise]``, ``[fit]`` (read by the general
:func:`workbench.features.param_fit_study.read_recovery`), ``[existing]`` (the
delay + lag model of eq 28 to compare against). The recovery itself (synthetic
logs, fruit fly, differential evolution, recovery table) is the general
:mod:`workbench.features.param_fit_study`; what stays here is paper 000's: the
brake model as the fit's callback, the K1/K2 ratio of eq 7, the existing model
of eq 28 and the report wording.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import partial

from ...features.param_fit_study import (Recovery, RecoverySpec, compare, fit_json,
                                         plot_curves, read_recovery, recover,
                                         recovery_table, relative_errors)
from ...features.quantities import Declared, names, values
from ...fit import FITTED, fitted_row, model_speeds
from ...jsonable import json_method
from ...kinds.stop_accuracy.pipeline import read_brake_plant
from ...plants.brake000 import BrakeParams, existing_model
from ...reader import Reader
from ...report.markdown import Figure, Rendered, fmt, md_table


@dataclass(frozen=True)
class FitSpec:
    params: dict
    recovery: RecoverySpec
    delay: float
    lag: float


@dataclass(frozen=True)
class FitStudyResult:
    rec: Recovery
    rmse_existing: float
    curves: tuple      # per log: (t, logged, foa model, existing model)

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"truth": "rec.truth", "rmse_truth_cm_s": "rec.rmse_truth",
                   "rmse_existing_cm_s": "rmse_existing",
                   **{m: (lambda res, m=m: fit_json(res.rec, m, "rmse_cm_s"))
                      for m in ("foa", "de")}}
    to_json = json_method


def _with_ratio(values: dict) -> dict:
    """``values`` (name -> value of :data:`~workbench.fit.FITTED`) and K1/K2,
    the ratio eq 7 identifies (K1 and K2 alone are not)."""
    return {**values, "K1/K2": values["K1"] / values["K2"]}


#: The claimable quantities of a ``brake-fit`` design, declared once.
TABLE = (
    Declared("rmse.precise_foa", "cm/s", lambda r: r.rec.foa.rmse),
    Declared("rmse.precise_de", "cm/s", lambda r: r.rec.de.rmse),
    Declared("rmse.truth", "cm/s", lambda r: r.rec.rmse_truth),
    Declared("rmse.existing", "cm/s", lambda r: r.rmse_existing),
    Declared("rmse.ratio_existing_over_precise", "1",
             lambda r: r.rmse_existing / r.rec.foa.rmse),
    Declared("{m}.{k}.rel_error", "1",
             lambda r, m, k: abs(relative_errors(r.rec, m, _with_ratio)[k]),
             over=lambda spec: [{"m": m, "k": k} for m in ("foa", "de")
                                for k in FITTED + ("K1/K2",)]),
)


class BrakeFit:
    kind = "brake-fit"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader) -> FitSpec:
        params = read_brake_plant(root)
        rec = read_recovery(root, FITTED,
                            lambda lg: lg.quantity("v0", "m/s", positive=True, hi=40.0).value,
                            "commands (m/s^2)")
        ex = root.table("existing")
        spec = FitSpec(params, rec, ex.quantity("delay", "s", positive=True).value,
                       ex.quantity("lag", "s", positive=True).value)
        ex.finish()
        return spec

    def quantity_names(self, spec) -> set[str]:
        return names(TABLE, spec)

    def run(self, design) -> FitStudyResult:
        s: FitSpec = design.spec
        base = {k: q.value for k, q in s.params.items()}
        model = partial(model_speeds, base, dt=s.recovery.dt)
        rec = recover(model, {k: base[k] for k in FITTED}, s.recovery, floor=0.0, scale=100.0)
        exd = existing_model(BrakeParams.from_dict(base), delay=s.delay, lag=s.lag).as_dict()
        err, curves = compare(rec, model, partial(model_speeds, exd, dt=s.recovery.dt),
                              fitted_row(exd), 100.0)
        return FitStudyResult(rec, err, curves)

    def quantities(self, res: FitStudyResult) -> dict:
        return values(TABLE, None, res)


def _table(res: FitStudyResult) -> str:
    """The recovery table (shared by the report and the CLI)."""
    return recovery_table(res.rec, _with_ratio, "RMSE (cm/s)")


def _plot(fig, res):
    ax = fig.add_subplot(111)
    plot_curves(ax, res.curves, ("log {i} (synthetic)", "fitted precise {i}", "existing {i}"),
                100)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("speed (cm/s)")
    ax.legend(fontsize=7)


STUDY = BrakeFit()


def render(design, res: FitStudyResult) -> Rendered:
    """Report sections of a ``brake-fit`` design (pure)."""
    s, r = design.spec, design.spec.recovery
    text = ("## Parameter recovery from synthetic logs (paper 000, eqs 11-12)\n\n"
            f"**Synthetic data**: {len(res.rec.logs)} braking logs generated by the brake model "
            f"with the parameters of the design (paper 000's Table 1), sampled every "
            f"{fmt(r.dt_log)} s, speed noise sd {fmt(100 * r.noise_sd)} cm/s, quantised to "
            f"{fmt(100 * r.quantum)} cm/s (seed {r.seed}). Both optimisers minimise eq 12 "
            f"over the box below, {r.flies} candidates per iteration, {r.iterations} "
            "iterations.\n\n" + _table(res)
            + "\n\nK1 and K2 enter eq 7 only as K1/K2: the objective is flat along "
            "K1/K2 = const, so K1 and K2 are **not separately identifiable** — only their "
            "ratio is recovered (its row). T1 and T2 (electric delay and lag) trade off "
            "against each other (their sum is what the logs fix); the air-stage delay T3 is "
            "weakly determined, because the air brake acts only in the last seconds below "
            "the hand-over speed, where the noise is comparable to its effect.\n\n"
            + md_table(["model", "RMSE (cm/s)"], [
                ["true parameters (noise floor)", fmt(res.rec.rmse_truth, 4)],
                ["precise model, fruit fly", fmt(res.rec.foa.rmse, 4)],
                ["precise model, differential evolution", fmt(res.rec.de.rmse, 4)],
                [f"existing model (delay {fmt(s.delay)} s, lag {fmt(s.lag)} s)",
                 fmt(res.rmse_existing, 4)]], "lr")
            + "\n\n![fit]({figdir}/fit-curves.png)")
    figs = (Figure("fit-curves", "Synthetic logs, fitted precise model, existing model.",
                   lambda fig, res=res: _plot(fig, res), size=(7.0, 4.0)),)
    return Rendered((text,), figs)


def fit_command(design, *, as_json: bool = False) -> int:
    """The ``workbench fit DESIGN`` verb: run a loaded ``brake-fit`` design, print recovery."""
    import json

    res = STUDY.run(design)
    if as_json:
        print(json.dumps(res.to_json(), indent=2))
        return 0
    print(f"{design.name}: SYNTHETIC logs ({len(res.rec.logs)}), fit by eq 12")
    print(_table(res))
    return 0
