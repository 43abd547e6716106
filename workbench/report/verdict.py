"""The design verdict, the traceability matrix and the hazard and assumption
registers of a report (issue 33, items 1-3).

Two verdicts are never mixed. The **design verdict** (:data:`VERDICTS`)
judges the design as its file states it (for a paper design: as printed),
from the requirement status of each claim and the severity of each finding,
by :data:`RULE`. The **tool status** ("expectations met: 16 of 16") says
only that the workbench reproduced its own expectations, the regression
information, and is printed apart from the verdict and smaller.

Everything here is a pure function of evaluated claims and the design's
registers: :func:`design_items` turns a design's claim results into
:class:`Item` rows (a proof report builds its own), :func:`decide` applies
the rule, :func:`render_verdict`, :func:`traceability_section`,
:func:`register_section` and :func:`hazards_markdown` write Markdown.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..claims import ClaimResult, Verdict
from .markdown import md_table, slug

__all__ = ["VERDICTS", "RULE", "STATUSES", "Item", "DesignVerdict", "claim_status",
           "design_items", "decide", "render_verdict", "traceability_section",
           "register_section", "hazard_entries", "hazards_markdown"]

#: The design verdicts, best first.
VERDICTS = ("accept", "accept with conditions", "reject")
#: Requirement status of a claim (the coverage line counts them).
STATUSES = ("met", "not met", "not tested")
#: The rule :func:`decide` applies, as the report states it.
RULE = ("**reject** when a requirement is not met with severity `safety` (unless its hazard "
        "is `closed`: mitigation shown) or not met with no severity assessed; otherwise "
        "**accept with conditions** when a requirement is not met with severity "
        "`changes-the-result`, is not tested (INCONCLUSIVE), or the design tests none "
        "(each such item is a condition); otherwise **accept**. `minor` and `rounding` "
        "findings are listed as observations and never decide. The verdict is on the "
        "design as its file states it (a paper design: as printed), not on the tool")
HAZARD_HEADING = "Hazard log"


@dataclass(frozen=True)
class Item:
    """One claim as the verdict sees it.

    Attributes
    ----------
    id, what : str
        Claim id and statement.
    status : str
        One of :data:`STATUSES`.
    severity : str or None
        The finding's severity (None: not a finding, or not assessed).
    hazard : str or None
        Hazard id a safety finding links to.
    hazard_status : str or None
        That hazard's status in the log (None: no such entry).
    """

    id: str
    what: str
    status: str
    severity: str | None = None
    hazard: str | None = None
    hazard_status: str | None = None


@dataclass(frozen=True)
class DesignVerdict:
    """The verdict, the items that decide it, the conditions of an accept
    with conditions, and the observations (minor and rounding findings)."""

    verdict: str
    decisive: tuple[tuple[Item, str], ...]
    conditions: tuple[tuple[Item, str], ...]
    observations: tuple[Item, ...]


def claim_status(r: ClaimResult) -> str:
    """``met`` / ``not met`` / ``not tested`` of the requirement a claim
    traces to: a known discrepancy (expected FAIL) that fails, or a workbench
    finding that holds, shows the requirement not met; INCONCLUSIVE, or a
    claim whose check cannot test its requirement (``untested``), is not
    tested; otherwise a PASS meets it."""
    c = r.claim
    if r.verdict is Verdict.INCONCLUSIVE or (c.untested and r.verdict is Verdict.PASS):
        return "not tested"
    if c.is_finding:
        shown = r.verdict is (Verdict.FAIL if c.expect == "fail" else Verdict.PASS)
        return "not met" if shown else "met"
    return "met" if r.verdict is Verdict.PASS else "not met"


def design_items(results: tuple[ClaimResult, ...], hazards=()) -> tuple[Item, ...]:
    """The :class:`Item` of every claim of a design."""
    status = {h.id: h.status for h in hazards}
    return tuple(Item(r.claim.id, r.claim.description + (f" — not tested: {r.claim.untested}"
                                                          if r.claim.untested else ""),
                      claim_status(r), r.claim.severity, r.claim.hazard,
                      status.get(r.claim.hazard)) for r in results)


def decide(items: tuple[Item, ...]) -> DesignVerdict:
    """Apply :data:`RULE` to the items of one report."""
    decisive, conditions, observations = [], [], []
    for it in items:
        if it.status == "not tested":
            conditions.append((it, "not tested (INCONCLUSIVE, or the check cannot test it): "
                                   "test it or waive the requirement"))
        if it.status != "not met":
            continue
        if it.severity is None:
            decisive.append((it, "not met and no severity assessed"))
        elif it.severity == "safety" and it.hazard_status != "closed":
            why = (f"safety, hazard `{it.hazard}` {it.hazard_status}" if it.hazard_status
                   else "safety, **no hazard id in the hazard log**")
            decisive.append((it, why))
        elif it.severity == "safety":
            conditions.append((it, f"safety, hazard `{it.hazard}` closed: review the "
                                   "evidence of its mitigation"))
        elif it.severity == "changes-the-result":
            conditions.append((it, "changes-the-result: correct the design or accept the "
                                   "deviation in writing"))
        else:
            observations.append(it)
    if not items:
        conditions.append((Item("—", "no requirement is tested by this design", "not tested"),
                           "state and test the requirements the design must meet"))
    verdict = "reject" if decisive else "accept with conditions" if conditions else "accept"
    return DesignVerdict(verdict, tuple(decisive), tuple(conditions), tuple(observations))


def _item_rows(pairs) -> str:
    return md_table(["claim", "statement", "why it counts"],
                    [[f"`{it.id}`", it.what, why] for it, why in pairs], "lll")


def render_verdict(v: DesignVerdict, tool_status: str, subject: str = "design") -> str:
    """``## Design verdict``: the verdict, the decisive findings, the
    conditions, the observations, the rule; then the tool status, smaller."""
    lines = [f"## Design verdict\n\n**Design verdict: {v.verdict.upper()}** (the {subject} as "
             "stated, not the tool's status)."]
    if v.decisive:
        lines.append(f"Decisive findings ({len(v.decisive)}):\n\n" + _item_rows(v.decisive))
    if v.conditions:
        lines.append(("Conditions" if not v.decisive else "Further conditions, were the "
                      "decisive findings resolved") + f" ({len(v.conditions)}):\n\n"
                     + _item_rows(v.conditions))
    if v.observations:
        lines.append("Observations (minor or rounding, not decisive): "
                     + ", ".join(f"`{it.id}`" for it in v.observations) + ".")
    lines.append(f"Rule: {RULE}.")
    lines.append(f"<sub>Tool status (regression information, not a design verdict): "
                 f"{tool_status}.</sub>")
    return "\n\n".join(lines)


def _basis(c) -> str:
    if c.basis == "standard":
        return f"standard: {c.standard}"
    return f"{c.basis}: {c.source}"


def _mark(text: str, c, field: str) -> str:
    return text + (" *(derived)*" if field in c.derived else "")


def traceability_section(results: tuple[ClaimResult, ...], link) -> str:
    """``## Traceability``: requirement -> claim -> evidence -> verdict, one
    row per claim ordered by requirement, and the coverage line
    (``link(claim) -> str``: the Markdown link of the claim's evidence)."""
    if not results:
        return ("## Traceability\n\n_This design states no claims, so no requirement is "
                "traced._\n\nCoverage: 0 requirements.")
    rows, by_req = [], {}
    first = {}
    for i, r in enumerate(results):
        first.setdefault(r.claim.requirement, i)
    for r in sorted(results, key=lambda r: first[r.claim.requirement]):
        c, st = r.claim, claim_status(r)
        by_req.setdefault(c.requirement, []).append(st)
        verdict = f"**{st}**" + (f" ({c.severity})" if st == "not met" and c.severity else
                                 f": {c.untested}" if st == "not tested" and c.untested else "")
        rows.append([_mark(f"`{c.requirement}`", c, "requirement"),
                     _mark(_basis(c), c, "basis"), _mark(c.criterion, c, "criterion"),
                     f"`{c.id}`", link(c), verdict])
    req = {k: ("not met" if "not met" in v else "not tested" if "not tested" in v else "met")
           for k, v in by_req.items()}
    count = lambda d, s: sum(x == s for x in d)
    claims = [claim_status(r) for r in results]
    cover = (f"Coverage: {len(req)} requirements — {count(req.values(), 'met')} met, "
             f"{count(req.values(), 'not met')} not met, {count(req.values(), 'not tested')} "
             f"not tested ({len(claims)} claims: {count(claims, 'met')} met, "
             f"{count(claims, 'not met')} not met, {count(claims, 'not tested')} not tested).")
    note = ("*(derived)*: the design file is silent and the field follows the claim "
            "(requirement `R-<claim id>`; criterion: the claim's comparison, negated for a "
            "workbench finding, whose claim states the defect; origin: `paper` "
            "for a paper claim, else `our choice`, with the claim's source). A requirement "
            "is met only when all its claims are.")
    return ("## Traceability\n\n" + md_table(["requirement", "origin", "acceptance criterion",
                                             "claim", "evidence", "verdict"], rows, "llllll")
            + "\n\n" + cover + "\n\n" + note)


def _findings_of(hid: str, claims) -> str:
    return ", ".join(f"`{c.id}`" for c in claims if c.hazard == hid) or "—"


def register_section(hazards, assumptions, claims) -> str:
    """``## Hazard log`` and ``## Assumptions``: the design's registers, the
    safety findings linked to each hazard, and every safety finding that
    links to none (flagged)."""
    if hazards:
        rows = [[f"`{h.id}`", h.hazard, h.cause, h.consequence, h.mitigation,
                 f"**{h.status}**", _findings_of(h.id, claims)] for h in hazards]
        log = md_table(["id", "hazard", "cause", "consequence", "mitigation", "status",
                        "safety findings"], rows, "lllllll")
    else:
        log = "_This design file has no hazard log (`[[hazards]]`)._"
    orphans = [c.id for c in claims if c.severity == "safety" and c.hazard is None]
    if orphans:
        log += ("\n\n**Safety findings without a hazard id** (add them to the log): "
                + ", ".join(f"`{i}`" for i in orphans) + ".")
    if assumptions:
        reg = md_table(["#", "assumption or choice", "effect on the result"],
                       [[str(i), a.text, a.effect] for i, a in enumerate(assumptions, 1)], "rll")
    else:
        reg = "_This design file has no assumptions register (`[[assumptions]]`)._"
    return f"## {HAZARD_HEADING}\n\n{log}\n\n## Assumptions\n\n{reg}"


def hazard_entries(design) -> tuple:
    """``(design name, hazards, safety claims)`` of one design, the input of
    :func:`hazards_markdown` (static: read from the design file alone)."""
    return (design.name, tuple(design.hazards),
            tuple(c for c in design.claims if c.severity == "safety"))


def hazards_markdown(entries) -> str:
    """``reports/HAZARDS.md``: every hazard id of every design (one row per
    id: its text from the first design that logs it, the status and safety
    findings per design), and every safety finding with no hazard id."""
    by_id, orphans = {}, []
    for name, hazards, safety in sorted(entries, key=lambda e: e[0]):
        link = f"[{name}]({name}.md#{slug(HAZARD_HEADING)})"
        for h in hazards:
            by_id.setdefault(h.id, []).append((link, h, _findings_of(h.id, safety)))
        orphans += [f"{link}: `{c.id}`" for c in safety if c.hazard is None]
    rows = []
    for hid in sorted(by_id):
        first = by_id[hid][0][1]
        differs = [link for link, h, _ in by_id[hid][1:]
                   if (h.hazard, h.cause, h.consequence, h.mitigation) !=
                   (first.hazard, first.cause, first.consequence, first.mitigation)]
        where = "; ".join(f"{link} (**{h.status}**): {found}" for link, h, found in by_id[hid])
        what = first.hazard + (" (worded differently in " + ", ".join(differs) + ")"
                               if differs else "")
        rows.append([f"`{hid}`", what, first.cause, first.consequence, first.mitigation, where])
    body = (md_table(["hazard", "what", "cause", "consequence", "mitigation",
                      "designs (status): safety findings"], rows, "llllll")
            if rows else "_No design has a hazard log._")
    tail = ("\n\n## Safety findings without a hazard id\n\n"
            + ("\n".join(f"- {o}" for o in orphans) if orphans else "None.") + "\n")
    return ("# Hazard log\n\nGenerated from the `[[hazards]]` tables and the safety findings "
            "(`severity = \"safety\"`, linked by `hazard = \"<id>\"`) of every design file in "
            "`designs/`; checked fresh with the index by `workbench report --all --check`. One "
            "row per hazard id; its status and safety findings per design that logs it. Status: "
            "`open` (no mitigation), `mitigated` (a mitigation named, not shown by the design's "
            "claims), `closed` (mitigation shown).\n\n" + body + tail)
