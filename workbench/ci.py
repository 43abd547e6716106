"""Claims as CI test cases: one run of ``verify``, its cases and its timings.

:func:`run_verify` evaluates the chosen designs (and proof modules), timing
each; :func:`design_cases` and :func:`proof_cases` turn verdicts into
:class:`Case` records — one per claim, named ``design::claim-id`` — that the
three CI forms share: the ``verify`` table's exit code, JUnit XML
(:mod:`workbench.junit`) and the pytest plugin (:mod:`workbench.pytest_plugin`).

Outcome rules (the same in all three forms):

* PASS / PROVED — passes.
* FAIL / REFUTED — fails, with expected, got, tolerance and source.
* INCONCLUSIVE — fails (CI must not go green on a claim nobody could decide),
  unless the claim sets ``allow_inconclusive = true``.
* A claim with ``expect = "fail"`` (or a proof with ``expect="refuted"``)
  passes when it fails as documented; its reason goes to system-out. If it
  passes instead, it fails: the discrepancy went away, so update the design.
"""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from .report.markdown import fmt, md_table


@dataclass(frozen=True)
class Case:
    """One claim as a test case.

    Attributes
    ----------
    suite : str
        Design name, or ``proofs/<module>`` for a proof claim (JUnit classname).
    claim : str
        Claim id.
    ok : bool
        Whether the case passes.
    verdict : str
        PASS, FAIL, INCONCLUSIVE (designs) or PROVED, REFUTED, INCONCLUSIVE (proofs).
    message : str
        One line: why it failed ("" when ok).
    detail : str
        Several lines: statement, expected, got, tolerance, source.
    out : str
        Notes for system-out (e.g. the reason of an expected failure).
    """

    suite: str
    claim: str
    ok: bool
    verdict: str
    message: str
    detail: str
    out: str

    @property
    def name(self) -> str:
        """``design::claim-id``."""
        return f"{self.suite}::{self.claim}"


def _expected(c) -> str:
    """The claim's comparison in words, e.g. ``== 0.0433 (4 printed digits, truncate)``."""
    s = f"{c.compare} {fmt(c.value, 12)}"
    if c.compare == "==" and c.digits is not None and not isinstance(c.value, str):
        s += f" ({c.digits} printed digits, {c.rounding})"
    return s


def design_cases(ev) -> list[Case]:
    """Cases of one :class:`workbench.verify.Evaluation`, in claim order."""
    out = []
    for r in ev.claims:
        c = r.claim
        got = fmt(r.got, 12) if r.got is not None else f"nothing ({r.note or 'not determined'})"
        facts = (f"expected {_expected(c)}, got {got}; tolerance {fmt(c.tolerance, 6)}; "
                 f"source: {c.source}")
        detail = "\n".join([f"{ev.design.name}::{c.id}: {c.description}",
                            f"quantity: {c.quantity}", f"expected: {_expected(c)}",
                            f"got: {got}", f"tolerance: {fmt(c.tolerance, 6)}",
                            f"verdict: {r.verdict.value}", f"source: {c.source}",
                            f"design file: {ev.design.path}"])
        note = ""
        if c.expect == "fail":
            note = f"expected to fail (known discrepancy, severity {c.severity}): {c.reason}"
        elif c.severity is not None:
            note = f"workbench finding, severity {c.severity}"
        if not r.severity_holds:
            message = (f"severity 'rounding' does not hold (the difference is more than "
                       f"0.1 % of the value): {facts}")
        elif r.ok:
            message = ""
            if r.verdict.value == "INCONCLUSIVE":
                note = "INCONCLUSIVE, allowed by allow_inconclusive = true"
        elif c.expect == "fail":
            message = (f"{r.verdict.value} but expected to FAIL ({c.reason}); the discrepancy "
                       f"went away, update the design: {facts}")
        elif r.verdict.value == "INCONCLUSIVE":
            message = f"INCONCLUSIVE (counted as a failure): {facts}"
        else:
            message = f"FAIL: {facts}"
        out.append(Case(ev.design.name, c.id, r.ok, r.verdict.value, message,
                        detail + (f"\n{note}" if note else ""), note))
    return out


def proof_cases(results) -> list[Case]:
    """Cases of ``(ProofModule, ProofResult)`` pairs from :func:`workbench.prove.run_proofs`."""
    from .prove import expected_verdict as proof_expected
    from .prove import result_detail
    out = []
    for m, r in results:
        c = r.claim
        want = proof_expected(r)
        facts = (f"expected {want}, got {r.verdict.value}"
                 + (f"; {result_detail(r)}" if result_detail(r) else "")
                 + (f"; tolerance: {c.digits} printed digits" if c.digits is not None else "")
                 + f"; source: paper {m.paper}, eqs {c.equations}")
        detail = "\n".join([f"proofs/{m.name}::{c.id}: {c.statement}", f"kind: {c.kind}",
                            f"expected: {want}", f"got: {r.verdict.value}",
                            f"source: paper {m.paper}, eqs {c.equations}"]
                           + ([result_detail(r)] if result_detail(r) else []))
        note = (f"expected REFUTED (as printed): {c.note}" if c.expect == "refuted" else "")
        message = "" if r.ok else (
            f"INCONCLUSIVE (counted as a failure): {facts}" if r.verdict.value == "INCONCLUSIVE"
            else f"{r.verdict.value}: {facts}")
        out.append(Case(f"proofs/{m.name}", c.id, r.ok, r.verdict.value, message,
                        detail + (f"\n{note}" if note else ""), note))
    return out


@dataclass(frozen=True)
class VerifyRun:
    """What one ``workbench verify`` evaluated.

    Attributes
    ----------
    evaluations : tuple of workbench.verify.Evaluation
    proofs : tuple of (ProofModule, ProofResult)
    seconds : tuple of (str, float)
        Wall time of each design (its name) and proof module (``proofs/<name>``), s.
    skipped : tuple of str
        Designs and proof modules left out by ``--changed-since`` (unchanged).
    """

    evaluations: tuple
    proofs: tuple
    seconds: tuple[tuple[str, float], ...]
    skipped: tuple[str, ...]

    @property
    def cases(self) -> list[Case]:
        return [c for e in self.evaluations for c in design_cases(e)] + proof_cases(self.proofs)

    @property
    def ok(self) -> bool:
        return all(e.ok for e in self.evaluations) and all(r.ok for _, r in self.proofs)


def run_verify(paths: list[str], *, changed_since: str | None = None,
               progress: bool = False) -> VerifyRun:
    """Evaluate designs and proofs, timing each.

    Parameters
    ----------
    paths : list of str
        Design files; empty: every design of the project and every proof module.
    changed_since : str, optional
        A git revision: keep only designs (and proof modules) that depend on a
        file changed since it (see :mod:`workbench.changes`).
    progress : bool
        A progress bar over the designs and proof modules on stderr (only
        when stderr is a terminal: :mod:`workbench.sim.progress`).

    Raises
    ------
    DesignError
        A design file is malformed, none is found, or the revision is unknown.
    """
    from .design import load_design
    from .errors import DesignError
    from .project import find_project
    from .verify import evaluate_design

    project = find_project()
    files = [Path(p) for p in paths] or project.design_files()
    if not files and not paths and not project.proofs.is_dir():
        raise DesignError("<cli>", "DESIGN", str(project.designs),
                          "a folder with design files (run `workbench init PATH` for a project)")
    designs = [load_design(p) for p in files]   # a bad design answers before any proof loads
    modules = []
    if not paths:
        from .prove import proof_modules, run_proofs
        modules = list(proof_modules())
    skipped: list[str] = []
    if changed_since is not None:
        from .changes import changed_files, design_changed, proof_changed
        changed = changed_files(project.root, changed_since)
        keep = [d for d in designs
                if design_changed(Path(d.path), d.kind, project.designs, changed)]
        skipped += [d.name for d in designs if d not in keep]
        designs = keep
        keep_m = [m for m in modules
                  if proof_changed(project.proofs / f"{m.name}.py", changed)]
        skipped += [f"proofs/{m.name}" for m in modules if m not in keep_m]
        modules = keep_m
    from .sim.progress import progress as progress_bar
    seconds, evaluations, proofs = [], [], []
    bar = progress_bar(total=len(designs) + len(modules), desc="verify", unit="design",
                       enabled=progress and len(designs) + len(modules) > 1)
    with bar:
        for d in designs:
            bar.set_postfix_str(d.name, refresh=False)
            t0 = time.perf_counter()
            evaluations.append(evaluate_design(d))
            seconds.append((d.name, time.perf_counter() - t0))
            bar.update()
        for m in modules:
            bar.set_postfix_str(f"proofs/{m.name}", refresh=False)
            t0 = time.perf_counter()
            proofs += run_proofs([m.name])
            seconds.append((f"proofs/{m.name}", time.perf_counter() - t0))
            bar.update()
    return VerifyRun(tuple(evaluations), tuple(proofs), tuple(seconds), tuple(skipped))


def timing_table(seconds) -> str:
    """``design | seconds`` table, slowest first, with the total."""
    rows = [[n, f"{s:.2f}"] for n, s in sorted(seconds, key=lambda t: (-t[1], t[0]))]
    rows.append(["total", f"{sum(s for _, s in seconds):.2f}"])
    return md_table(["design", "seconds"], rows, "lr")
