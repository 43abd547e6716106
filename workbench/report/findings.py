"""The findings of a report: what does not hold, how badly, and the index row.

One renderer for every report. A :class:`Summary` holds a report's counts
and its findings (each a :class:`Finding` with its severity from
:data:`workbench.claims.SEVERITIES`, or None: not assessed);
:func:`summarise` builds it from a design's evaluated claims, and
:mod:`workbench.prove` from a paper's proof claims. :func:`render_findings`
writes the ``## Findings`` block (after the design verdict of
:mod:`workbench.report.verdict`) and :func:`index_row` the columns of
``reports/README.md``; both are pure functions of the summary.
:func:`findings_section` and :func:`index_cells` are the two for a design's
claims.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

from ..claims import SEVERITIES, ClaimResult, Verdict
from .markdown import fmt, md_table, noise_cell, slug
from .verdict import HAZARD_HEADING, DesignVerdict

#: Label of a finding whose severity nobody assessed (listed after the others).
NOT_ASSESSED = "not assessed"


@dataclass(frozen=True)
class Finding:
    """One finding: a paper statement that does not hold, or a defect the
    workbench shows.

    Attributes
    ----------
    id : str
        The claim's id.
    severity : str or None
        One of :data:`workbench.claims.SEVERITIES`; None when not assessed.
    origin : str
        "paper" or "workbench".
    label : str
        What kind of finding, as the table prints it ("paper claim not
        reproduced", "workbench", "erratum").
    what : str
        The statement.
    evidence : str
        One line of evidence (Markdown), with a link to where it is shown.
    why : str
        Why the severity (shown in the report's table, not in the index).
    hazard : str or None
        The hazard id a safety finding links to (None: none, flagged).
    """

    id: str
    severity: str | None
    origin: str
    label: str
    what: str
    evidence: str
    why: str = ""
    hazard: str | None = None


@dataclass(frozen=True)
class Labels:
    """The words of a Findings block: what is counted and where the
    details are (designs: claims; proofs: steps)."""

    items: str = "claims"
    holds: str = "hold as the design states them"
    reproduced: str = "Paper claims reproduced"
    not_reproduced: str = "not reproduced"
    workbench: str | None = "Findings of the workbench that the paper does not state"
    details: str = "[Claims](#claims)"
    index_reproduced: str = ""


DESIGN = Labels()


@dataclass(frozen=True)
class Summary:
    """Counts of one report's claims (see the module docstring).

    Attributes
    ----------
    claims : int
    not_ok : tuple[str, ...]
        Ids of claims that do not hold as stated.
    paper : int
        Claims that state the paper's own results.
    reproduced : int
        Paper claims that hold as printed (and are not findings, and their
        check can test them: not ``untested``).
    findings : tuple[Finding, ...]
        Most severe first (paper findings before workbench ones within a
        severity; those not assessed last).
    untested : int
        Paper claims whose check holds but cannot test them (``untested``).
    """

    claims: int
    not_ok: tuple[str, ...]
    paper: int
    reproduced: int
    findings: tuple[Finding, ...]
    untested: int = 0

    def by_severity(self, origin: str | None = None) -> dict[str, int]:
        """Findings (of one origin, or all) per severity, most severe first,
        then those not assessed (zeros left out)."""
        keys = (*reversed(SEVERITIES), None)
        out = {NOT_ASSESSED if s is None else s:
               sum(f.severity == s and origin in (None, f.origin) for f in self.findings)
               for s in keys}
        return {s: n for s, n in out.items() if n}


def ordered(findings) -> tuple[Finding, ...]:
    """Most severe first; within a severity paper findings first; not assessed last."""
    rank = {s: i for i, s in enumerate(SEVERITIES)}
    return tuple(sorted(findings, key=lambda f: (f.severity is None,
                                                 -rank.get(f.severity, -1),
                                                 f.origin != "paper")))


def section_link(quantity: str, anchors) -> str:
    """``[heading](#slug)`` of the first section whose pattern matches the
    start of ``quantity`` (``anchors``: (regular expression, heading)
    pairs; a plain prefix is a pattern too), or "" for none."""
    for pattern, heading in anchors:
        if re.match(pattern, quantity):
            return f"[{heading}](#{slug(heading)})"
    return ""


def _evidence(r: ClaimResult, anchors) -> str:
    c = r.claim
    want = f"{c.compare} {fmt(c.value, 6)}"
    if c.compare == "within" or (c.compare != "==" and c.tolerance):
        want += f" ± {fmt(c.tolerance)}"
    link = section_link(c.quantity, anchors)
    return (f"expected {want}, got {noise_cell(r.got, r.peak, 5)} ({r.verdict.value}); claim `{c.id}`"
            + (f"; shown in {link}" if link else ""))


def summarise(results: tuple[ClaimResult, ...], anchors=()) -> Summary:
    """A design's counts; findings sorted most severe first (``anchors``:
    (quantity prefix, section heading) pairs the evidence links to)."""
    findings = [Finding(r.claim.id, r.claim.severity, r.claim.origin,
                        "paper claim not reproduced" if r.claim.origin == "paper"
                        else "workbench", r.claim.description, _evidence(r, anchors),
                        (f"— why `{r.claim.severity}`: {r.claim.severity_reason}."
                         if r.claim.severity_reason else ""), r.claim.hazard)
                for r in results if r.claim.is_finding]
    paper = [r for r in results if r.claim.origin == "paper"]
    reproduced = sum(r.verdict is Verdict.PASS and not r.claim.is_finding and not r.claim.untested
                     for r in paper)
    untested = sum(bool(r.claim.untested) for r in paper)
    return Summary(len(results), tuple(r.claim.id for r in results if not r.ok), len(paper),
                   reproduced, ordered(findings), untested)


def _counts(d: dict[str, int]) -> str:
    return ", ".join(f"{n} {s}" for s, n in d.items()) or "none"


def _hazard(f: Finding) -> str:
    if f.severity != "safety":
        return ""
    if f.hazard is None:
        return "; **no hazard id** (flagged)"
    return f"; hazard [`{f.hazard}`](#{slug(HAZARD_HEADING)})"


def tool_status(s: Summary, labels: Labels = DESIGN) -> str:
    """The regression status: ``expectations met: 16 of 16 claims ...``."""
    text = (f"expectations met: {s.claims - len(s.not_ok)} of {s.claims} {labels.items} "
            f"{labels.holds}")
    if s.not_ok:
        text += " — **NOT OK**: " + ", ".join(f"`{i}`" for i in s.not_ok) + " do not"
    return text


def render_findings(s: Summary, labels: Labels = DESIGN, notes: tuple[str, ...] = ()) -> str:
    """``## Findings``: the counts (and ``notes``, more bullet lines) and
    every finding (most severe first) with one line of evidence and, for a
    safety finding, its hazard id (or a flag that it has none)."""
    if not s.claims:
        return f"## Findings\n\n_This design states no {labels.items}._"
    lines = [f"- {labels.reproduced}: {s.reproduced} of {s.paper}; {labels.not_reproduced}: "
             f"{_counts(s.by_severity('paper'))}"
             + (f"; not tested (the check cannot test them): {s.untested}" if s.untested else "")
             + "."]
    if labels.workbench:
        lines.append(f"- {labels.workbench}: {_counts(s.by_severity('workbench'))}.")
    lines += notes
    body = "\n".join(lines)
    if s.findings:
        rows = [[f"**{f.severity or NOT_ASSESSED}**",
                 f"{f.label}: {f.what}" + (f" {f.why}" if f.why else ""),
                 f.evidence + _hazard(f)]
                for f in s.findings]
        body += ("\n\n" + md_table(["severity", "finding", f"evidence (see {labels.details})"],
                                   rows, "lll"))
    body += ("\n\nSeverities, mildest first: `rounding` (within the paper's printed "
             "precision), `minor` (no conclusion changes), `changes-the-result`, `safety` "
             "(divergence, wheel lock or spin, instability).")
    return "## Findings\n\n" + body


def findings_section(results: tuple[ClaimResult, ...], anchors=()) -> str:
    """``## Findings`` of a design report (details in ``## Claims``)."""
    return render_findings(summarise(results, anchors))


def _ids(pairs, most: int = 3) -> str:
    ids = [f"`{it.id}`" for it, _ in pairs]
    return ", ".join(ids[:most]) + (f" (+{len(ids) - most} more)" if len(ids) > most else "")


def index_row(s: Summary, v: DesignVerdict, labels: Labels = DESIGN) -> list[str]:
    """Cells of the index row: design verdict, what decides it (decisive
    findings or conditions), findings by severity, paper claims reproduced,
    and the tool status, smaller."""
    verdict = f"**{v.verdict}**"
    if v.decisive:
        why = f"{len(v.decisive)} decisive: " + _ids(v.decisive)
    elif v.conditions:
        n = len(v.conditions)
        why = f"{n} condition{'s' if n > 1 else ''}: " + _ids(v.conditions)
    else:
        why = "—"
    tool = f"{s.claims - len(s.not_ok)} of {s.claims}" + (" **NOT OK**" if s.not_ok else "")
    return [verdict, why, _counts(s.by_severity()),
            f"{s.reproduced} of {s.paper}{labels.index_reproduced}", f"<sub>{tool}</sub>"]


def index_cells(results: tuple[ClaimResult, ...], v: DesignVerdict) -> list[str]:
    """The index row of a design's report (see :func:`index_row`)."""
    return index_row(summarise(results), v)
