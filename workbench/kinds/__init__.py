"""Studies: what a design of a given ``kind`` computes, claims and reports.

Each study module provides an object with

``load(root: Reader) -> spec``
    Validate the study's tables of a design file into a frozen spec.
``quantity_names(spec) -> set[str]``
    Every quantity a claim may name (known before running, so an unknown
    quantity is a design error, exit 2).
``run(design) -> result``
    Compute (a frozen dataclass; its JSON is :func:`workbench.jsonable.to_json`,
    with the keys its class names in ``JSON_FIELDS``).
``quantities(result) -> dict[str, float | str | None]``
    Values of the named quantities (``None``: not determined).
``quantity_names`` and ``quantities`` are best both expanded from one table
that declares each quantity once, with its unit and the function that reads
it (:mod:`workbench.features.quantities`; ``delay-feedback`` does, in
:mod:`workbench.kinds.delay_feedback.quantities`).
``uses_solver`` (optional attribute, default True)
    False when the study runs no convex solver (its report's provenance
    then names none).
and, in the study's render module (``<study>_render.py``, which imports the
study module, never the other way round), a function

``render(design, result) -> workbench.report.markdown.Rendered``
    Markdown sections and figures (pure).

New capabilities add a module here and one line to :data:`STUDIES` and to
:data:`RENDERERS`; the command-line verbs a kind has (``simulate``,
``sweep``, ``synthesize ...``) are declared in :mod:`.capabilities`.

Loading is lazy: :data:`REGISTRY` imports a study's module the first time
its kind is looked up, so reading (or rejecting) a design imports only its
own study. A study module keeps its top level light (the design tables,
specs and quantity names); the solvers, the symbolic model and the plotting
libraries (cvxpy, control, sympy, matplotlib) are imported inside the
functions that compute or render.
"""
from __future__ import annotations

import importlib
from collections.abc import Mapping
from typing import Any, Iterator

#: kind -> "module:attribute" of the study object.
STUDIES: dict[str, str] = {
    "antiskid-cruise": "workbench.papers.p003.antiskid_cruise:STUDY",
    "delay-benchmark": "workbench.kinds.delay_benchmark:STUDY",
    "antiskid-robust": "workbench.papers.p003.antiskid_robust:STUDY",
    "antiskid-run": "workbench.papers.p003.antiskid_run:STUDY",
    "brake-fit": "workbench.papers.p000.brake_fit:STUDY",
    "tracking": "workbench.kinds.tracking:STUDY",
    "platoon": "workbench.kinds.platoon:STUDY",
    "delay-feedback": "workbench.kinds.delay_feedback:STUDY",
    "switched-run": "workbench.kinds.switched_run:STUDY",
    "stop-accuracy": "workbench.kinds.stop_accuracy:STUDY",
}


#: kind -> "module:function" of the study's renderer (see the module docstring).
RENDERERS: dict[str, str] = {
    "antiskid-cruise": "workbench.papers.p003.antiskid_cruise_render:render",
    "delay-benchmark": "workbench.kinds.delay_benchmark_render:render",
    "antiskid-robust": "workbench.papers.p003.antiskid_robust_render:render",
    "antiskid-run": "workbench.papers.p003.antiskid_run_render:render",
    "brake-fit": "workbench.papers.p000.brake_fit:render",
    "tracking": "workbench.kinds.tracking.render:render",
    "platoon": "workbench.kinds.platoon.render:render",
    "delay-feedback": "workbench.kinds.delay_feedback.render:render",
    "switched-run": "workbench.kinds.switched_run.render:render",
    "stop-accuracy": "workbench.kinds.stop_accuracy.render:render",
}


def renderer(kind: str):
    """The render function of a study kind, ``render(design, result)``."""
    module, attr = RENDERERS[kind].split(":")
    return getattr(importlib.import_module(module), attr)


class _LazyRegistry(Mapping):
    """kind -> study object, each module imported on first lookup."""

    def __init__(self, table: dict[str, str]):
        self._table, self._loaded = table, {}

    def __getitem__(self, kind: str) -> Any:
        if kind not in self._loaded:
            module, attr = self._table[kind].split(":")
            study = getattr(importlib.import_module(module), attr)
            if study.kind != kind:
                raise RuntimeError(f"{module}:{attr} is a {study.kind!r} study, not {kind!r}")
            self._loaded[kind] = study
        return self._loaded[kind]

    def __iter__(self) -> Iterator[str]:
        return iter(self._table)

    def __len__(self) -> int:
        return len(self._table)


#: kind -> study object (imported on demand, see the module docstring).
REGISTRY: Mapping[str, Any] = _LazyRegistry(STUDIES)
