"""Assemble a design's report (pure) and write / check report files.

``render_report(evaluation, rendered, ...) -> (markdown, figures)`` is a pure
function of what it is given: the evaluated claims and the study's own
rendered sections (:func:`workbench.verify.report_files` renders them). This
module never runs a study or a solver; :func:`write_reports` and
:func:`check_reports` touch files.
"""
from __future__ import annotations

import platform
import re
from dataclasses import dataclass, field, replace
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from ..claims import ROUNDING_RTOL, ClaimResult, Verdict
from .files import atomic_write, check_name, replace_set
from .findings import findings_section, index_cells, section_link, summarise, tool_status
from .markdown import Figure, Rendered, fmt, github_math, md_table, noise_cell
from .verdict import (decide, design_items, hazard_entries, hazards_markdown, register_section,
                      render_verdict, traceability_section)

PACKAGES = ("workbench", "cvxpy", "clarabel", "control", "numpy", "scipy", "sympy",
            "matplotlib")


def claims_table(results: tuple[ClaimResult, ...]) -> str:
    """The claims table: claim, expected, got, verdict, source."""
    if not results:
        return "_This design states no claims._"
    rows = []
    for r in results:
        c = r.claim
        exp = f"{c.compare} {fmt(c.value, 6)}"
        if c.compare == "within" or (c.compare != "==" and c.tolerance):
            exp += f" ± {fmt(c.tolerance)}"
        if c.digits is not None:
            exp += f" ({c.digits} decimals, {'truncated' if c.rounding == 'truncate' else 'rounded'})"
        verdict = r.verdict.value
        if not r.severity_holds:
            verdict += f" (not a rounding: more than {fmt(100 * ROUNDING_RTOL)} % off)"
        elif r.verdict is Verdict.INCONCLUSIVE and c.allow_inconclusive:
            verdict += " (allowed)" + (f": {r.note}" if r.note else "")
        elif c.expect == "fail":
            verdict += (" (expected)" if r.ok else
                        f" (expected FAIL, now {r.verdict.value}: update the design)")
        note = c.description + (f" — known discrepancy ({c.severity}): {c.reason}"
                                if c.expect == "fail" else
                                f" — workbench finding ({c.severity})" if c.severity else "")
        note += f" — does not test its requirement: {c.untested}" if c.untested else ""
        rows.append([f"`{c.id}`", note, f"`{c.quantity}`", exp, noise_cell(r.got, r.peak, 5),
                     f"**{verdict}**", c.source])
    return md_table(["claim", "statement", "quantity", "expected", "got", "verdict", "source"],
                    rows, "lllrrll")


def refinement_section(table) -> list[str]:
    """The three-level refinement of the findings' metrics (issue 33, item
    4), from a :class:`workbench.features.refinement.RefinementTable` (empty list
    when the study has no refined step)."""
    if table is None:
        return []
    head = (f"## Refinement of the findings\n\nEvery finding's metric at the designed step "
            f"{table.field} = {fmt(table.step)} {table.unit} and at {table.field}/2 and "
            f"{table.field}/4 (every other parameter, the control period included, as "
            "designed). Observed order p = log2(|q1 − q2| / |q2 − q4|), Richardson estimate "
            f"of the error of q4 = |q2 − q4| / (2^p − 1); p above {fmt(table.p_max)} is clipped to "
            f"{fmt(table.p_max)}, and below {fmt(table.p_min)} (levels not in the asymptotic "
            f"range) the estimate is max(|q1 − q2|, |q2 − q4|) / (2^{fmt(table.p_min)} − 1), "
            "INCONCLUSIVE when above the tolerance. The tolerance is the error that could change "
            "the finding: the claim's tolerance for `within`, the distance to the bound for "
            "`<=` / `>=`. A finding whose estimate exceeds it is INCONCLUSIVE.")
    if not table.rows:
        return [head + "\n\n_No finding with a measured metric._"]
    rows = []
    own = any(r.parameter for r in table.rows)
    for r in table.rows:
        c = r.check
        vals = tuple(fmt(x, 5) for x in r.values) if r.values else ("—",) * 3
        rows.append([f"`{r.claim_id}`", f"`{r.quantity}`", *([r.parameter or "—"] if own else []),
                     *vals, "—" if c is None or c.order is None else fmt(c.order, 2),
                     "—" if c is None or c.estimate is None else fmt(c.estimate, 2),
                     "—" if r.tolerance is None else fmt(r.tolerance, 2),
                     r.outcome + (f" ({c.note})" if c and c.note else "")
                     + (f": {r.reason}" if not r.values and r.reason else "")])
    if own:
        head += (" Here each finding names the parameter refined (q1 at its designed value, q2 "
                 "at its half, q4 at its quarter); where the study reports a metric from a "
                 "refined level (the cases from dt/2), the finding's value is that level's.")
    return [head + "\n\n" + md_table(
        ["finding", "metric", *(["parameter"] if own else []), "q1", "q2", "q4", "p",
         "estimate", "tolerance", "outcome"], rows, "ll" + ("l" if own else "") + "rrrrrrl")]


def verdict_summary(results) -> str:
    """One line: how many claims hold as stated, and how many of those are
    known discrepancies (FAIL as expected) rather than passes."""
    n = len(results)
    ok = sum(r.ok for r in results)
    known = sum(r.ok and r.claim.expect == "fail" for r in results)
    passed = sum(r.ok and r.verdict is Verdict.PASS and r.claim.expect == "pass"
                 for r in results)
    other = ok - known - passed
    return (f"{ok} of {n} claims hold as stated: {passed} pass, {known} known "
            f"discrepancies fail as expected" + (f", {other} inconclusive as allowed"
                                                   if other else "")
            + ("" if ok == n else f"; {n - ok} do not hold"))


#: The line of a report that names the project commit: the only line the
#: freshness check ignores (:func:`check_reports`).
COMMIT_LINE = re.compile(r"^- Project commit: .*$", re.M)


@dataclass(frozen=True)
class Configuration:
    """What identifies the configuration a report was made from (issue 33,
    item 6): the design file's SHA-256, the project commit (``""``:
    uncommitted changes) and the versions pinned in ``constraints.txt``."""

    sha256: str = ""
    commit: str = ""
    pins: dict = field(default_factory=dict, compare=False)


def configuration_lines(path: str, config: Configuration) -> str:
    """The identification bullets of ``## Provenance``."""
    commit = f"`{config.commit}`" if config.commit else "uncommitted"
    return (f"- Design file: `{path}`, SHA-256 `{config.sha256 or 'unknown'}`\n"
            f"- Project commit: {commit}\n"
            "- Pinned versions: `constraints.txt` of the project (column *pinned* below)")


@lru_cache(maxsize=None)
def _workbench_distribution() -> str:
    """The distribution that installs the ``workbench`` package, looked up once
    per process (scanning every installed distribution's files takes 0.4 s)."""
    return metadata.packages_distributions().get("workbench", ["workbench"])[0]


def provenance(solver: str | None, pins: dict | None = None, ident: str = "") -> str:
    """``## Provenance``: the configuration ``ident`` (bullets), package
    versions installed and pinned, and the solver settings ``solver`` (None:
    the study runs no convex solver)."""
    pins = pins or {}
    rows = []
    # the workbench's distribution has a name of its own (workbench.DISTRIBUTION)
    dist = {"workbench": _workbench_distribution()}
    for p in PACKAGES:
        try:
            rows.append([p, metadata.version(dist.get(p, p)), pins.get(p, "—")])
        except metadata.PackageNotFoundError:
            rows.append([p, "not installed", pins.get(p, "—")])
    rows.append(["python", ".".join(platform.python_version_tuple()[:2]), "—"])
    how = ("No convex solver runs in this study. " if solver is None else
           f"Solver: Clarabel through cvxpy ({solver}); problems built once with cvxpy "
           "Parameters (DPP) and re-solved. ")
    return ("## Provenance\n\n" + (ident + "\n\n" if ident else "")
            + md_table(["package", "installed", "pinned"], rows) + "\n\n" + how +
            "Numbers are printed with the digits that mean something (4 significant digits "
            "for bounds), so solver and floating-point noise below them does not change this "
            "file. Generated by `workbench report`; do not edit by hand.")


def render_report(ev, rendered: Rendered, figdir: str, solver: str | None,
                  config: Configuration = Configuration()) -> tuple[str, tuple[Figure, ...]]:
    """Markdown of one design's report and the figures it links (pure).

    Parameters
    ----------
    ev : workbench.verify.Evaluation
        The design and its evaluated claims.
    rendered : Rendered
        The study's own sections and figures.
    figdir : str
        Relative folder of the figures, as linked from the Markdown.
    solver : str or None
        Solver settings for the provenance section (None: no solver runs).
    config : Configuration
        Design file hash, project commit and pinned versions.

    The report opens with the design verdict (the tool status below it,
    smaller), then the findings, the study's sections, the hazard log and
    assumptions, the claims, the provenance, and ends with the
    traceability matrix.
    """
    d = ev.design
    head = f"# {d.title}\n\nDesign `{d.path}` (kind `{d.kind}`), from {d.source}."
    body = [s.replace("{figdir}", figdir) for s in rendered.sections]
    v = decide(design_items(ev.claims, d.hazards))
    link = lambda c: (section_link(c.quantity, rendered.anchors) or "[Claims](#claims)")
    ident = configuration_lines(d.path, config)
    parts = [head, render_verdict(v, tool_status(summarise(ev.claims))),
             findings_section(ev.claims, rendered.anchors), *body,
             register_section(d.hazards, d.assumptions, [r.claim for r in ev.claims]),
             "## Claims\n\n" + verdict_summary(ev.claims) + ".\n\n" + claims_table(ev.claims),
             *refinement_section(getattr(ev, "refinement", None)),
             provenance(solver, config.pins, ident),
             traceability_section(ev.claims, link)]
    return github_math("\n\n".join(parts).rstrip() + "\n"), rendered.figures


@dataclass(frozen=True)
class ReportFiles:
    """One report: its Markdown, figures, and its row of the index.

    ``index``: verdict, paper claims reproduced, findings by severity, the
    most severe finding (:func:`workbench.report.findings.index_cells`).
    """

    name: str
    markdown: str
    figures: tuple[Figure, ...]
    ok: bool
    summary: str
    index: tuple[str, ...] = ()
    hazards: tuple = ()


def build(ev, rendered: Rendered, solver: str | None,
          config: Configuration = Configuration()) -> ReportFiles:
    """The report files of one evaluated design (see :func:`render_report`)."""
    md, figs = render_report(ev, rendered, ev.design.name, solver, config)
    figs = tuple(replace(f, title=figure_title(ev.design, f)) for f in figs)
    v = decide(design_items(ev.claims, ev.design.hazards))
    return ReportFiles(ev.design.name, md, figs, ev.ok, verdict_summary(ev.claims),
                       tuple(index_cells(ev.claims, v)), hazard_entries(ev.design))


def figure_title(design, fig: Figure) -> str:
    """The title drawn on a figure: design name and the figure's caption,
    then the design's title (its case and key parameters, e.g. rail and
    v_d); a title the study gave the figure is kept."""
    return fig.title or f"{design.name}: {fig.caption}\n{design.title}"


def index_markdown(files: list[ReportFiles]) -> str:
    """``reports/README.md``: one row per report, design verdict first."""
    from .verdict import RULE
    rows = [[f"[{f.name}]({f.name}.md)", *f.index] for f in sorted(files, key=lambda f: f.name)]
    return ("# Reports\n\nGenerated by `workbench report --all` (`make report`); checked fresh in "
            "CI by `workbench report --all --check`. The **design verdict** judges the design "
            f"as its file states it: {RULE}. Hazards of every design: [HAZARDS.md](HAZARDS.md). "
            "The *tool status* (last column, regression information only) counts the claims "
            "that hold as the design file states them, a known discrepancy included. "
            "Severities, mildest first: `rounding`, `minor`, `changes-the-result`, `safety`.\n\n"
            + md_table(["report", "design verdict", "decided by", "findings by severity",
                        "paper claims reproduced", "<sub>tool status</sub>"], rows, "llllll")
            + "\n")


def hazard_log(files: list[ReportFiles]) -> str:
    """``reports/HAZARDS.md`` of the reports' designs (:func:`hazards_markdown`)."""
    return hazards_markdown([f.hazards for f in files if f.hazards])


def write_reports(files: list[ReportFiles], outdir: Path, *, index: bool,
                  skip=frozenset()) -> list[Path]:
    """Write each report's Markdown and figures as a set
    (:func:`workbench.report.files.replace_set`), and the index; returns the
    paths written. ``skip``: reports written elsewhere (``report --jobs``),
    still counted in the index."""
    from .figures import figure_png
    written = []
    outdir.mkdir(parents=True, exist_ok=True)
    for f in files:
        if f.name in skip:
            continue
        figs = {f"{check_name(fig.name, 'figure')}.png": figure_png(fig) for fig in f.figures}
        written += replace_set(outdir, f.name, f.markdown, figs)
    if index:
        written.append(atomic_write(outdir / "README.md", index_markdown(files), folder=outdir))
        written.append(atomic_write(outdir / "HAZARDS.md", hazard_log(files), folder=outdir))
    return written


def check_reports(files: list[ReportFiles], outdir: Path, *, index: bool,
                  only_index: bool = False) -> list[str]:
    """Problems with the committed reports: stale Markdown, missing or stale
    figures (each figure is drawn again and compared byte for byte:
    :func:`workbench.report.figures.figure_png`). ``only_index``: the index
    alone (the reports were compared elsewhere)."""
    from .figures import figure_png
    problems = []
    for f in () if only_index else files:
        p = outdir / f"{f.name}.md"
        if not p.is_file():
            problems.append(f"{p}: missing (run `workbench report`)")
        elif _sans_commit(p.read_text(encoding="utf-8")) != _sans_commit(f.markdown):
            problems.append(f"{p}: stale (regenerate with `workbench report`)")
        for fig in f.figures:
            fp = outdir / f.name / f"{fig.name}.png"
            if not fp.is_file():
                problems.append(f"{fp}: missing figure linked from {p.name}")
            elif fp.read_bytes() != figure_png(fig):
                problems.append(f"{fp}: stale figure (regenerate with `workbench report`)")
    if index:
        p = outdir / "README.md"
        if not p.is_file() or p.read_text(encoding="utf-8") != index_markdown(files):
            problems.append(f"{p}: stale or missing index")
        p = outdir / "HAZARDS.md"
        if not p.is_file() or p.read_text(encoding="utf-8") != hazard_log(files):
            problems.append(f"{p}: stale or missing hazard log")
    return problems


def _sans_commit(markdown: str) -> str:
    """The report with its project-commit line blanked: the one line a
    freshness check ignores (the commit a report was made at is never the
    commit that holds it)."""
    return COMMIT_LINE.sub("- Project commit: (ignored by the check)", markdown)
