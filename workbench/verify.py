"""Claims -> verdicts: run a design's study and check every claim."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import studies
from .claims import ClaimResult, check_claim, fill_claim
from .design import Design
from .memo import run_study
from .report.markdown import fmt


@dataclass(frozen=True)
class Evaluation:
    """A design, its study result and its claims' verdicts."""

    design: Design
    result: Any
    claims: tuple[ClaimResult, ...]

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.claims)


def evaluate_design(design: Design) -> Evaluation:
    """Run the design's study (once per process for an equal spec,
    :func:`workbench.memo.run_study`) and check each of its claims."""
    study = studies.REGISTRY[design.kind]
    result = run_study(design, study.run)
    q = study.quantities(result)
    return Evaluation(design, result, tuple(check_claim(fill_claim(c, q, fmt), q.get(c.quantity))
                                            for c in design.claims))


def report_files(ev: Evaluation):
    """The report of an evaluated design: the study renders its sections,
    :func:`workbench.report.writer.build` assembles them (the writer never
    runs a study)."""
    from .lmi.core import CLARABEL_SETTINGS
    from .report.writer import build
    rendered = studies.renderer(ev.design.kind)(ev.design, ev.result)
    solver = None
    if getattr(studies.REGISTRY[ev.design.kind], "uses_solver", True):
        solver = ", ".join(f"{k}={v}" for k, v in CLARABEL_SETTINGS.items()) or "Clarabel defaults"
    return build(ev, rendered, solver)
