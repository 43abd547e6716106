"""Studies: what a design of a given ``kind`` computes, claims and reports.

Each study module provides an object with

``load(root: Reader) -> spec``
    Validate the study's tables of a design file into a frozen spec.
``quantity_names(spec) -> set[str]``
    Every quantity a claim may name (known before running, so an unknown
    quantity is a design error, exit 2).
``run(design) -> result``
    Compute (a frozen dataclass with ``to_json()``).
``quantities(result) -> dict[str, float | str | None]``
    Values of the named quantities (``None``: not determined).
``render(design, result) -> workbench.report.Rendered``
    Markdown sections and figures (pure).

New capabilities add a module here and one line to :data:`REGISTRY`.
"""
from __future__ import annotations

from . import antiskid_cruise, platoon001, tracking002
from . import brake004, fit000, stopping000
from . import antiskid_run
from . import antiskid_robust, delay_benchmark

REGISTRY = {
    antiskid_cruise.STUDY.kind: antiskid_cruise.STUDY,
    delay_benchmark.STUDY.kind: delay_benchmark.STUDY,
    antiskid_robust.STUDY.kind: antiskid_robust.STUDY,
    antiskid_run.STUDY.kind: antiskid_run.STUDY,
    stopping000.STUDY.kind: stopping000.STUDY,
    brake004.STUDY.kind: brake004.STUDY,
    fit000.STUDY.kind: fit000.STUDY,
    tracking002.STUDY.kind: tracking002.STUDY,
    platoon001.STUDY.kind: platoon001.STUDY,
}
