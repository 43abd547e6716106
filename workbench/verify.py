"""Claims -> verdicts: run a design's study and check every claim."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from . import kinds
from .claims import ClaimResult, Verdict, check_claim, fill_claim
from .design import Design
from .memo import run_study
from .report.markdown import fmt, noise_peak


@dataclass(frozen=True)
class Evaluation:
    """A design, its study result and its claims' verdicts."""

    design: Design
    result: Any
    claims: tuple[ClaimResult, ...]
    refinement: Any = None      # RefinementTable of the findings, or None

    @property
    def ok(self) -> bool:
        return all(c.ok for c in self.claims)


def evaluate_design(design: Design) -> Evaluation:
    """Run the design's study (once per process for an equal spec,
    :func:`workbench.memo.run_study`) and check each of its claims.

    A study with a ``refine_field`` (the spec's numerical step; for the
    designs its ``refines(spec)`` accepts, when it has one) has every
    finding's metric checked at the step, its half and its quarter (:func:`workbench.features.refinement.refine_findings`, issue 33 item 4):
    a finding whose metric has not converged within the claim's tolerance
    is INCONCLUSIVE ("not converged: ...")."""
    study = kinds.REGISTRY[design.kind]
    result = run_study(design, study.run)
    q = study.quantities(result)
    checked = [replace(check_claim(fill_claim(c, q, fmt), q.get(c.quantity)),
                       peak=noise_peak(c.quantity, q)) for c in design.claims]
    table = None
    if hasattr(study, "refine_field") and getattr(study, "refines", lambda spec: True)(design.spec):
        table = _refined(design, study, q, checked, result)
        by_id = {row.claim_id: row for row in table.rows}
        checked = [_unconverged(r, by_id[r.claim.id]) if r.claim.id in by_id
                   and not by_id[r.claim.id].converged else r for r in checked]
    if hasattr(study, "unconverged"):    # a kind that refines its own metrics (switched-run)
        why = study.unconverged(result)   # claim id or claimed quantity -> reason
        checked = [_not_converged(r, why.get(r.claim.id, why.get(r.claim.quantity)))
                   for r in checked]
    return Evaluation(design, result, tuple(checked), table)


def _not_converged(r: ClaimResult, why: str | None) -> ClaimResult:
    """INCONCLUSIVE with the study's reason ``why`` (None: ``r`` as it is). A
    claim INCONCLUSIVE already keeps its note, unless its quantity was not
    determined: then the reason says why (issue 33)."""
    if why is None or r.verdict is Verdict.INCONCLUSIVE and r.got is not None:
        return r
    return ClaimResult(r.claim, r.got, Verdict.INCONCLUSIVE, why)


def _refined(design, study, q, checked, result):
    """:func:`workbench.features.refinement.refine_findings`, computed once per run: kept
    in this process and in the run folder (:func:`workbench.memo.shared`) under
    the exact key of the design's kind, spec and claim results (the refinement
    reads nothing else), so the verify phase of ``workbench check`` and the
    test session reuse what the check's workers computed."""
    from .memo import computed_once, spec_key
    from .features.refinement import refine_findings
    spec, claims = spec_key(design.spec), spec_key(tuple(checked))
    compute = lambda: refine_findings(design, study, q, checked, result)   # noqa: E731
    if spec is None or claims is None:
        return compute()
    return computed_once("refine_findings", (design.kind, spec, claims), compute)


def _unconverged(r: ClaimResult, row) -> ClaimResult:
    return replace(r, verdict=Verdict.INCONCLUSIVE, note=row.reason)


def project_commit(root) -> str:
    """The commit of the project at ``root`` (``git rev-parse HEAD``), or
    "" when it is not a git checkout or files outside ``reports/`` differ
    from that commit, untracked ones included (the report is then
    "uncommitted")."""
    import subprocess
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                              text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=normal", "--",
                                ".", ":(exclude)reports"], cwd=root, capture_output=True,
                               text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return ""
    return "" if dirty else head


def pinned_versions(root) -> dict:
    """``package -> version`` of the ``name==version`` lines of
    ``<root>/constraints.txt`` (lower-case names; empty when absent)."""
    from pathlib import Path
    p = Path(root) / "constraints.txt"
    if not p.is_file():
        return {}
    out = {}
    for line in p.read_text(encoding="utf-8").splitlines():
        name, sep, version = line.split("#")[0].strip().partition("==")
        if sep:
            out[name.strip().lower()] = version.strip()
    return out


def configuration(design):
    """The :class:`workbench.report.writer.Configuration` of a design's
    report: file hash, project commit, pinned versions."""
    from .project import find_project
    from .report.writer import Configuration
    root = find_project().root
    return Configuration(design.sha256, project_commit(root), pinned_versions(root))


def report_files(ev: Evaluation):
    """The report of an evaluated design: the study renders its sections,
    :func:`workbench.report.writer.build` assembles them (the writer never
    runs a study)."""
    from .lmi.core import CLARABEL_SETTINGS
    from .report.writer import build
    rendered = kinds.renderer(ev.design.kind)(ev.design, ev.result)
    solver = None
    if getattr(kinds.REGISTRY[ev.design.kind], "uses_solver", True):
        solver = ", ".join(f"{k}={v}" for k, v in CLARABEL_SETTINGS.items()) or "Clarabel defaults"
    return build(ev, rendered, solver, configuration(ev.design))
