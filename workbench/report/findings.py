"""The verdict-first summary of a report: what holds, what does not, how badly.

:func:`summarise` counts a design's evaluated claims (paper claims
reproduced or not, workbench findings, each finding with its severity from
:data:`workbench.claims.SEVERITIES`); :func:`findings_section` renders the
``## Findings`` block every report opens with, and :func:`index_cells` the
columns of ``reports/README.md``. Pure functions of the claim results.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..claims import SEVERITIES, ClaimResult, Verdict
from .markdown import fmt, md_table


@dataclass(frozen=True)
class Summary:
    """Counts of one report's claims (see the module docstring).

    Attributes
    ----------
    claims : int
    not_ok : tuple[str, ...]
        Ids of claims that do not hold as the design states them.
    paper : int
        Claims that cite a paper.
    reproduced : int
        Paper claims that pass (and are not findings).
    findings : tuple[ClaimResult, ...]
        Claims with a severity, most severe first (paper claims not
        reproduced, then workbench findings, each by severity).
    """

    claims: int
    not_ok: tuple[str, ...]
    paper: int
    reproduced: int
    findings: tuple[ClaimResult, ...]

    def by_severity(self, origin: str) -> dict[str, int]:
        """Findings of one origin per severity, most severe first (zeros left out)."""
        out = {s: sum(r.claim.severity == s and r.claim.origin == origin for r in self.findings)
               for s in reversed(SEVERITIES)}
        return {s: n for s, n in out.items() if n}


def summarise(results: tuple[ClaimResult, ...]) -> Summary:
    """Count a report's claims; findings sorted most severe first."""
    rank = {s: i for i, s in enumerate(SEVERITIES)}
    findings = sorted((r for r in results if r.claim.is_finding),
                      key=lambda r: (-rank[r.claim.severity], r.claim.origin != "paper"))
    paper = [r for r in results if r.claim.origin == "paper"]
    reproduced = sum(r.verdict is Verdict.PASS and not r.claim.is_finding for r in paper)
    return Summary(len(results), tuple(r.claim.id for r in results if not r.ok), len(paper),
                   reproduced, tuple(findings))


def _counts(d: dict[str, int]) -> str:
    return ", ".join(f"{n} {s}" for s, n in d.items()) or "none"


def _evidence(r: ClaimResult) -> str:
    c = r.claim
    want = f"{c.compare} {fmt(c.value, 6)}"
    if c.compare == "within" or (c.compare != "==" and c.tolerance):
        want += f" ± {fmt(c.tolerance)}"
    return f"expected {want}, got {fmt(r.got, 5)} ({r.verdict.value}); claim `{c.id}`"


def findings_section(results: tuple[ClaimResult, ...]) -> str:
    """``## Findings``: the verdict, the counts and every finding (most
    severe first) with one line of evidence; details in ``## Claims``."""
    s = summarise(results)
    if not results:
        return "## Findings\n\n_This design states no claims._"
    if s.not_ok:
        head = (f"**NOT OK: {len(s.not_ok)} of {s.claims} claims do not hold as the design "
                f"states them** (" + ", ".join(f"`{i}`" for i in s.not_ok) + ").")
    else:
        head = f"**Verified: all {s.claims} claims hold as the design states them.**"
    lines = [head, "",
             f"- Paper claims reproduced: {s.reproduced} of {s.paper}; not reproduced: "
             f"{_counts(s.by_severity('paper'))}.",
             f"- Findings of the workbench that the paper does not state: "
             f"{_counts(s.by_severity('workbench'))}."]
    body = "\n".join(lines)
    if s.findings:
        rows = [[f"**{r.claim.severity}**",
                 ("paper claim not reproduced: " if r.claim.origin == "paper" else
                  "workbench: ") + r.claim.description, _evidence(r)] for r in s.findings]
        body += ("\n\n" + md_table(["severity", "finding", "evidence (see [Claims](#claims))"],
                                   rows, "lll"))
    body += ("\n\nSeverities, mildest first: `rounding` (within the paper's printed "
             "precision), `minor` (no conclusion changes), `changes-the-result`, `safety` "
             "(divergence, wheel lock or spin, instability).")
    return "## Findings\n\n" + body


def index_cells(results: tuple[ClaimResult, ...]) -> list[str]:
    """Cells of the index row: verdict, paper claims reproduced, findings by
    severity, the most severe finding."""
    s = summarise(results)
    verdict = "verified" if not s.not_ok else f"**NOT OK** ({len(s.not_ok)})"
    worst = s.findings[0] if s.findings else None
    total = {k: n for k, n in ((sev, sum(r.claim.severity == sev for r in s.findings))
                               for sev in reversed(SEVERITIES)) if n}
    what = "" if worst is None else ("not reproduced: " if worst.claim.origin == "paper"
                                     else "workbench: ")
    return [verdict, f"{s.reproduced} of {s.paper}", _counts(total),
            f"**{worst.claim.severity}** ({what}{worst.claim.description})" if worst else "—"]
