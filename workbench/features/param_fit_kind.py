"""A parameter-recovery study as a study kind: a model recovered from synthetic
logs by the two fits of :mod:`.param_fit_study`, beside a reference model that
is not fitted.

The caller gives the design reader and, per spec, the model
(:class:`RecoveryModel`: the fit's ``simulate`` callback, the true values of
the fitted names, the reference model and its fixed parameter row), and the
words its quantities and JSON use (:class:`RecoveryNames`).
:class:`RecoveryStudy` is then the study object (``load``, ``run``,
``quantity_names``, ``quantities``), with its claimable quantities declared
once (:func:`recovery_quantities`) and its CLI verb (:meth:`RecoveryStudy.command`).
The caller keeps its model and report wording (e.g. paper 000's brake fit);
tested on a first-order lag with dead time (tests/test_param_fit.py).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..jsonable import to_json
from .param_fit_study import METHODS, Recovery, compare, fit_json, recover, relative_errors
from .quantities import Declared, names, values

__all__ = ["RecoveryModel", "RecoveryNames", "RecoveryResult", "RecoveryStudy",
           "recovery_quantities"]


@dataclass(frozen=True)
class RecoveryModel:
    """The model a recovery study fits and the reference it is compared with.

    Attributes
    ----------
    simulate : callable
        ``simulate(values, log)`` of the fitted model
        (:mod:`~workbench.features.param_fit`).
    truth : dict
        Fitted name -> true value (generates the logs).
    reference : callable
        ``reference(values, log)``: the model compared with, not fitted.
    reference_row : ndarray
        The reference model's parameter row.
    """

    simulate: Callable
    truth: dict
    reference: Callable
    reference_row: np.ndarray


@dataclass(frozen=True)
class RecoveryNames:
    """Words of a recovery study's quantities and JSON.

    Attributes
    ----------
    fitted, reference : str
        The fitted and the reference model in quantity names
        (``rmse.<fitted>_foa``, ``rmse.<reference>``,
        ``rmse.ratio_<reference>_over_<fitted>``) and JSON keys.
    unit : str
        Unit of the RMSEs (times the study's ``scale``).
    json_unit : str
        Suffix of the JSON's RMSE keys (``rmse_<json_unit>``).
    """

    fitted: str = "fitted"
    reference: str = "reference"
    unit: str = "1"
    json_unit: str = ""

    def rmse_key(self, what: str = "") -> str:
        return "_".join(x for x in ("rmse", what, self.json_unit) if x)


@dataclass(frozen=True)
class RecoveryResult:
    """The recovery, the reference's RMSE on the logs and the curves per log
    (t, logged, fruit-fly fit, reference) of :func:`~.param_fit_study.compare`."""

    rec: Recovery
    rmse_reference: float
    curves: tuple
    names: RecoveryNames

    def to_json(self) -> dict:
        """Truth, RMSEs at the truth and of the reference, and each fit."""
        n, rec = self.names, self.rec
        return to_json({"truth": rec.truth, n.rmse_key("truth"): rec.rmse_truth,
                        n.rmse_key(n.reference): self.rmse_reference,
                        **{m: fit_json(rec, m, n.rmse_key()) for m, _ in METHODS}})


def recovery_quantities(words: RecoveryNames, fitted: tuple, derived: Callable = dict) -> tuple:
    """The claimable quantities of a recovery study: each fit's RMSE, the
    truth's and the reference's, their ratio, and per method ``m`` and name
    ``k`` of ``derived`` (over the ``fitted`` names) ``m.k.rel_error`` (|fitted /
    true - 1|)."""
    u, f, ref = words.unit, words.fitted, words.reference
    keys = tuple(derived(dict.fromkeys(fitted, 1.0)))
    return (
        *(Declared(f"rmse.{f}_{m}", u, lambda r, m=m: getattr(r.rec, m).rmse) for m, _ in METHODS),
        Declared("rmse.truth", u, lambda r: r.rec.rmse_truth),
        Declared(f"rmse.{ref}", u, lambda r: r.rmse_reference),
        Declared(f"rmse.ratio_{ref}_over_{f}", "1", lambda r: r.rmse_reference / r.rec.foa.rmse),
        Declared("{m}.{k}.rel_error", "1",
                 lambda r, m, k: abs(relative_errors(r.rec, m, derived)[k]),
                 over=lambda spec: [{"m": m, "k": k} for m, _ in METHODS for k in keys]),
    )


class RecoveryStudy:
    """The study object of a recovery kind.

    Parameters
    ----------
    kind : str
        The design kind.
    read : callable
        ``read(root) -> spec``; the spec has ``recovery``
        (:class:`~.param_fit_study.RecoverySpec`).
    model : callable
        ``model(spec) -> RecoveryModel``.
    words : RecoveryNames
    fitted : tuple
        The fitted names, in the order of :attr:`RecoveryModel.truth`.
    derived : callable
        ``derived(values) -> values``: the names compared with the truth
        (e.g. the values and a ratio that is identifiable where its parts are not).
    floor, scale : float
        Noisy outputs clip at ``floor``; RMSEs are reported times ``scale``.
    """

    uses_solver = False    # no convex solver runs: the report says so

    def __init__(self, kind: str, read: Callable, model: Callable, words: RecoveryNames,
                 fitted: tuple, derived: Callable = dict, *, floor: float | None = None,
                 scale: float = 1.0):
        self.kind, self.read, self.model, self.words = kind, read, model, words
        self.derived, self.floor, self.scale = derived, floor, scale
        self.table = recovery_quantities(words, fitted, derived)

    def load(self, root):
        return self.read(root)

    def quantity_names(self, spec) -> set[str]:
        return names(self.table, spec)

    def run(self, design) -> RecoveryResult:
        """Generate the logs, fit them twice, score the reference on them."""
        spec = design.spec
        m = self.model(spec)
        rec = recover(m.simulate, m.truth, spec.recovery, floor=self.floor, scale=self.scale)
        err, curves = compare(rec, m.simulate, m.reference, m.reference_row, self.scale)
        return RecoveryResult(rec, err, curves, self.words)

    def quantities(self, res: RecoveryResult) -> dict:
        return values(self.table, None, res)

    def command(self, design, header: str, table: Callable, *, as_json: bool = False) -> int:
        """A CLI verb: run ``design`` and print the JSON, or ``header`` (a format
        of ``name`` and ``logs``, their number) and ``table(result)``."""
        import json

        res = self.run(design)
        if as_json:
            print(json.dumps(res.to_json(), indent=2))
            return 0
        print(header.format(name=design.name, logs=len(res.rec.logs)))
        print(table(res))
        return 0
