"""``workbench prove``: check the claims of ``proofs/``, for the CLI, verify and reports.

``run_proofs(names)`` checks the selected claims with
:func:`workbench.symbolic.proof.check_claim`; :func:`cmd_prove` prints them,
:func:`verification_rows` feeds ``workbench verify`` and
:func:`report_files` renders one report per paper (``reports/proofs-NNN.md``).
"""
from __future__ import annotations

import hashlib
import importlib
import importlib.util
import json
import pkgutil
import sys
import types
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import metadata
from pathlib import Path

import sympy as sp

from .claims import ROUNDING_RTOL
from .errors import DesignError
from .report.findings import (Finding, Labels, Summary, index_row, ordered, render_findings,
                              tool_status)
from .report.verdict import Item, decide, render_verdict
from .report.markdown import fmt, md_table, slug
from .symbolic.proof import ProofResult, Verdict, check_claim


@dataclass(frozen=True)
class ProofModule:
    """One module of ``proofs/``: name, paper, title and its claims."""

    name: str
    paper: str
    title: str
    claims: tuple


def proofs_folder() -> Path:
    """``proofs/`` of the current project (see :mod:`workbench.project`)."""
    from .project import find_project
    return find_project().proofs


def _import_folder(folder: Path) -> list:
    """Import every module of ``folder`` not starting with ``_`` (name order).

    The folder is imported as a package under a name private to its path
    (``_workbench_proofs_<hash>``), so two projects never share modules and
    nothing is looked up on ``sys.path``. An ``__init__.py`` is optional.
    """
    pkg = "_workbench_proofs_" + hashlib.sha1(str(folder).encode()).hexdigest()[:12]
    if pkg not in sys.modules:
        init = folder / "__init__.py"
        if init.is_file():
            spec = importlib.util.spec_from_file_location(
                pkg, init, submodule_search_locations=[str(folder)])
            module = importlib.util.module_from_spec(spec)
            sys.modules[pkg] = module
            spec.loader.exec_module(module)
        else:
            module = types.ModuleType(pkg)
            module.__path__ = [str(folder)]
            sys.modules[pkg] = module
    names = sorted(m.name for m in pkgutil.iter_modules([str(folder)])
                   if not m.name.startswith("_"))
    return [importlib.import_module(f"{pkg}.{n}") for n in names]


@lru_cache(maxsize=None)
def _modules_in(folder: Path) -> tuple[ProofModule, ...]:
    if not folder.is_dir():
        return ()
    out = []
    for m in _import_folder(folder):
        name = m.__name__.rsplit(".", 1)[-1]
        for attr in ("PAPER", "TITLE", "claims"):
            if not hasattr(m, attr):
                raise DesignError(str(folder / f"{name}.py"), attr, "<missing>",
                                  "PAPER, TITLE and claims() in every proof module")
        claims = tuple(m.claims())
        for c in claims:
            check_proof_severity(folder / f"{name}.py", c)
        out.append(ProofModule(name, m.PAPER, m.TITLE, claims))
    return tuple(out)


def check_proof_severity(path: Path, c) -> None:
    """A proof claim's severity: one of SEVERITIES, on an erratum
    (``expect = "refuted"``), with a one-line reason (else exit 2)."""
    from .claims import SEVERITIES
    key = f"claims()[{c.id}].severity"
    if c.severity is None:
        return
    if c.severity not in SEVERITIES:
        raise DesignError(str(path), key, c.severity, "one of " + ", ".join(SEVERITIES))
    if c.expect != "refuted":
        raise DesignError(str(path), key, c.severity, 'a severity only on an erratum '
                          '(expect = "refuted")')
    if c.severity == "rounding" and c.kind != "value":
        raise DesignError(str(path), key, c.severity, '"rounding" only on a value claim '
                          "(where it is checked against the printed value)")
    if not c.severity_reason.strip() or "\n" in c.severity_reason:
        raise DesignError(str(path), f"claims()[{c.id}].severity_reason",
                          c.severity_reason, "one line saying why")


def proof_modules(folder: str | Path | None = None) -> tuple[ProofModule, ...]:
    """Every module of the project's ``proofs/`` (or of ``folder``); none if absent."""
    return _modules_in(Path(folder).resolve() if folder else proofs_folder())


def select(names: list[str] | tuple[str, ...] = ()) -> list[tuple[ProofModule, object]]:
    """(module, claim) pairs chosen by paper ("003"), module ("p003_lmi") or claim id.

    Raises
    ------
    DesignError
        For a name that matches nothing (exit 2 in the CLI).
    """
    modules = proof_modules()
    pairs = [(m, c) for m in modules for c in m.claims]
    if not names:
        return pairs
    out = []
    for n in names:
        hit = [(m, c) for m, c in pairs if n in (m.paper, m.name, c.id)]
        if not hit:
            raise DesignError("<cli>", "PROOF", n, "a paper (" + ", ".join(sorted(
                {m.paper for m in modules})) + "), a module of proofs/ ("
                + ", ".join(m.name for m in modules) + ") or a claim id")
        out += [p for p in hit if p not in out]
    return out


@lru_cache(maxsize=None)
def check_proof_claim(folder: Path, module: str, claim_id: str) -> ProofResult:
    """Check one claim of a ``proofs/`` module (once per process)."""
    from .memo import shared
    claim = next(c for m in proof_modules(folder) if m.name == module for c in m.claims
                 if c.id == claim_id)
    source = (folder / f"{module}.py").read_bytes()

    def check():
        r = check_claim(claim)
        return replace(r, severity_holds=rounding_holds(r))
    return shared("proof-claim", (module, claim_id, source), check)


def rounding_holds(r: ProofResult) -> bool:
    """A ``rounding`` erratum is checked as on a design claim: the exact
    value lies within :data:`workbench.claims.ROUNDING_RTOL` of the printed
    one (every other severity, or none, is not checked: True)."""
    c = r.claim
    if c.severity != "rounding" or r.counterexample is None:
        return True
    computed = dict(r.counterexample).get("computed")
    return computed is not None and abs(computed - float(c.rhs)) <= ROUNDING_RTOL * abs(float(c.rhs))


def run_proofs(names=()) -> list[tuple[ProofModule, ProofResult]]:
    """Check the selected claims of the project's ``proofs/`` (each once per process)."""
    folder = proofs_folder()
    return [(m, check_proof_claim(folder, m.name, c.id)) for m, c in select(tuple(names))]


def expected_verdict(r: ProofResult) -> str:
    """What the claim expects: "PROVED", or "REFUTED (as printed)" for a known error."""
    return "REFUTED (as printed)" if r.claim.expect == "refuted" else "PROVED"


def result_detail(r: ProofResult) -> str:
    """One line of evidence: the counterexample, or what remains to be shown."""
    if r.counterexample is not None:
        return "counterexample: " + ", ".join(f"{n} = {fmt(v, 6)}" for n, v in r.counterexample)
    return ("remains: " + r.remaining) if r.remaining else ""


def cmd_prove(args) -> int:
    """``workbench prove [PROOF ...] [--json]``: exit 0 all ok, 1 otherwise, 2 bad name."""
    results = run_proofs(args.proofs)
    ok = all(r.ok for _, r in results)
    if args.json:
        print(json.dumps({"proofs": [dict(module=m.name, **r.to_json()) for m, r in results]},
                         indent=2))
        return 0 if ok else 1
    rows = [[m.paper, r.claim.id, r.claim.equations, r.claim.kind, expected_verdict(r),
             r.verdict.value + ("" if r.ok else " ✗"), result_detail(r)[:120]] for m, r in results]
    print(md_table(["paper", "claim", "eqs", "kind", "expected", "verdict", "detail"], rows))
    n_bad = sum(not r.ok for _, r in results)
    print(f"\n{len(results) - n_bad} of {len(results)} proof claims ok"
          + ("" if not n_bad else f"; {n_bad} not ok"))
    return 0 if ok else 1


def verification_rows(results=None) -> dict:
    """Rows for ``workbench verify``: every proof claim (or those of ``results``, from
    :func:`run_proofs`), PROVED ok, REFUTED ok only when expected (the as-printed half
    of an erratum pair), INCONCLUSIVE not ok."""
    results = run_proofs() if results is None else results
    rows = []
    for m, r in results:
        verdict = ("PASS (expected refuted)" if r.ok and r.claim.expect == "refuted"
                   else "PASS" if r.ok else "FAIL ✗")
        rows.append([f"proofs/{m.name}", r.claim.id, expected_verdict(r), r.verdict.value, verdict,
                     f"paper {m.paper}, eqs {r.claim.equations}"])
    return {"rows": rows, "bad": sum(not r.ok for _, r in results),
            "json": {"proofs": [dict(module=m.name, **r.to_json()) for m, r in results]}}


# -- reports ---------------------------------------------------------------------------
#: The words of a proof report's Findings block (:mod:`workbench.report.findings`).
PROOF_LABELS = Labels(
    items="proof claims",
    holds="hold as stated (PROVED, or REFUTED where the claim is the paper's printed form "
          "of an erratum)",
    reproduced="Paper steps proved as printed", not_reproduced="refuted as printed (errata)",
    workbench=None, details="[Checked steps](#checked-steps)", index_reproduced=" steps as printed")


def _eqs(equations: str) -> str:
    if not equations[:1].isdigit():
        return equations
    return ("eq " if equations.isdigit() else "eqs ") + equations


def _heading(r: ProofResult) -> str:
    return f"`{r.claim.id}` — {r.verdict.value}" + ("" if r.ok else " — **NOT OK**")


def proof_summary(results) -> Summary:
    """The Findings counts of a paper's proof claims: paper steps proved as
    printed, and each erratum (refuted as printed) a finding with its
    severity (None: not assessed)."""
    findings = []
    for r in results:
        c = r.claim
        if c.expect != "refuted":
            continue
        why = f"— why `{c.severity}`: {c.severity_reason}." if c.severity else ""
        if r.counterexample is None:
            detail = r.verdict.value
        elif c.kind == "value":
            detail = (f"{r.verdict.value}: exact value {fmt(dict(r.counterexample)['computed'], 6)}"
                      f", printed {c.rhs}")
        else:
            detail = (f"{r.verdict.value}: a counterexample, re-checked with 30 digits, fails "
                      f"by {fmt(r.violation, 3)}")
        findings.append(Finding(
            c.id, c.severity, "paper", "erratum", f"{c.statement} ({_eqs(c.equations)})",
            f"{detail}; claim `{c.id}`; shown in [its section](#{slug(_heading(r))})", why))
    paper = [r for r in results if r.claim.origin == "paper"]
    return Summary(len(results), tuple(r.claim.id for r in results if not r.ok), len(paper),
                   sum(r.verdict is Verdict.PROVED for r in paper), ordered(findings))


def proof_items(results) -> tuple[Item, ...]:
    """The design-verdict items of a paper's proof claims: an erratum refuted
    as printed is a requirement (the paper's step) not met, with its
    severity; a step proved is met; INCONCLUSIVE is not tested; a step
    expected proved but refuted is not met, with no severity assessed."""
    out = []
    for r in results:
        c = r.claim
        if r.verdict is Verdict.INCONCLUSIVE:
            status = "not tested"
        elif c.expect == "refuted":
            status = "not met" if r.verdict is Verdict.REFUTED else "met"
        else:
            status = "met" if r.verdict is Verdict.PROVED else "not met"
        out.append(Item(c.id, f"{c.statement} ({_eqs(c.equations)})", status,
                        c.severity if c.expect == "refuted" else None))
    return tuple(out)


def _verdict(results) -> str:
    return render_verdict(decide(proof_items(results)),
                          tool_status(proof_summary(results), PROOF_LABELS),
                          subject="paper's derivation")


def _findings(results) -> str:
    own = [r for r in results if r.claim.origin == "workbench"]
    note = (f"- Corrected forms and repairs the workbench adds: {len(own)}, "
            f"{sum(r.verdict is Verdict.PROVED for r in own)} proved." if own else "")
    return render_findings(proof_summary(results), PROOF_LABELS, notes=(note,) if note else ())


def _summary(results) -> str:
    n, ok = len(results), sum(r.ok for r in results)
    counts = {v: sum(r.verdict is v for r in results) for v in Verdict}
    exp = sum(r.ok and r.claim.expect == "refuted" for r in results)
    return (f"{ok}/{n} proof claims ok — {counts[Verdict.PROVED]} PROVED, "
            f"{counts[Verdict.REFUTED]} REFUTED ({exp} as printed, expected), "
            f"{counts[Verdict.INCONCLUSIVE]} INCONCLUSIVE")


def _claim_section(module: ProofModule, r: ProofResult) -> str:
    c = r.claim
    lines = [f"### {_heading(r)}", "",
             f"{c.statement}. Paper {c.paper}, eqs {c.equations}; kind `{c.kind}`; "
             f"expected {expected_verdict(r)}; "
             + ("a corrected form or repair the workbench adds; " if c.origin == "workbench"
                else "") + f"module `proofs/{module.name}.py`."]
    if c.expect == "refuted":
        lines += ["", f"**Severity: {c.severity}** — {c.severity_reason}" if c.severity else
                  "**Severity: not assessed.**"]
        if not r.severity_holds:
            lines[-1] += (f" **Not a rounding: more than {fmt(100 * ROUNDING_RTOL)} % "
                          "off.**")
    if c.note:
        lines += ["", f"> {c.note}"]
    marks = {True: "✓", False: "✗", None: "—"}
    lines += ["", md_table(["step", "result"], [[s.what, marks[s.ok]] for s in r.steps], "ll")]
    for s in r.steps:
        if s.latex and not s.what.startswith("falsification"):
            lines += ["", f"*{s.what}:*", "", "$$", s.latex, "$$"]
    if r.counterexample is not None:
        lines += ["", f"**Counterexample** (re-checked with 30 digits; fails by "
                  f"{fmt(r.violation, 3)}):", "",
                  md_table(["symbol", "value"], [[f"${n}$" if n != "computed" else n, fmt(v, 6)]
                                                 for n, v in r.counterexample], "lr")]
    if r.remaining:
        lines += ["", f"**Remains to be shown:** ${r.remaining}$"]
    return "\n".join(lines)


def _traceability(pairs) -> str:
    """``## Traceability`` of a paper's proof claims: each claim traces to a
    requirement of its own, ``R-<claim id>`` (the paper's step, or the
    workbench's corrected form), with its expected verdict as criterion."""
    items = proof_items([r for _, r in pairs])
    rows = [[f"`R-{r.claim.id}`", ("paper" if r.claim.origin == "paper" else "our choice")
             + f": paper {r.claim.paper}, {_eqs(r.claim.equations)}",
             "PROVED" + (" as printed (expected REFUTED: an erratum)"
                         if r.claim.expect == "refuted" else ""), f"`{r.claim.id}`",
             f"[its section](#{slug(_heading(r))})",
             f"**{it.status}**" + (f" ({it.severity})" if it.status == "not met" and it.severity
                                   else "")] for (_, r), it in zip(pairs, items)]
    n = {s: sum(it.status == s for it in items) for s in ("met", "not met", "not tested")}
    return ("## Traceability\n\n" + md_table(["requirement", "origin", "acceptance criterion",
                                               "claim", "evidence", "verdict"], rows, "llllll")
            + f"\n\nCoverage: {len(items)} requirements — {n['met']} met, {n['not met']} not "
            f"met, {n['not tested']} not tested. Each proof claim is a requirement of its own "
            "(derived: `R-<claim id>`; criterion: the step is PROVED; origin: `paper` for a "
            "step of the paper, `our choice` for a corrected form the workbench adds).")


_SYMBOL_FACTS = ("positive", "nonnegative", "negative", "nonpositive", "integer", "real")


def _symbol_facts(c) -> str:
    """The declared sympy assumptions of the symbols a claim's two sides use
    (the strongest of :data:`_SYMBOL_FACTS` each symbol is declared with)."""
    exprs = [e for e in (c.lhs, c.rhs) if isinstance(e, sp.Basic)]
    syms = sorted(set().union(*(e.free_symbols for e in exprs)) if exprs else set(), key=str)
    groups: dict[str, list[str]] = {}
    for x in syms:
        fact = next((f for f in _SYMBOL_FACTS if x.assumptions0.get(f)), None)
        if fact is not None:
            groups.setdefault(fact, []).append(f"${sp.latex(x)}$")
    return "; ".join(f"{', '.join(v)} {k}" for k, v in groups.items())


def _assumptions(pairs) -> str:
    """``## Assumptions`` of a paper's proof report (issue 33, item 3): what each
    proof uses beyond the paper's equations, read off the claim itself — its
    hypotheses, the substitutions it is given, the symbols assumed nonzero and
    the declared signs of its symbols. A PROVED verdict holds under these only."""
    rows = []
    for _, r in pairs:
        c = r.claim
        parts = []
        if c.hypotheses:
            parts.append("hypotheses " + ", ".join(f"${sp.latex(h.relational)}$"
                                                   for h in c.hypotheses))
        if c.given:
            parts.append("given " + ", ".join(f"${sp.latex(a)} = {sp.latex(b)}$"
                                              for a, b in c.given))
        if c.nonzero:
            parts.append("nonzero " + ", ".join(f"${sp.latex(x)}$" for x in c.nonzero))
        facts = _symbol_facts(c)
        if facts:
            parts.append("declared: " + facts)
        if c.kind == "value":
            parts.append(f"the printed value stands for the exact one to its {c.digits} "
                         "printed decimals (the paper's rounding is not an error)")
        if parts:
            rows.append([f"`{c.id}`", "; ".join(parts)])
    effect = ("A PROVED verdict holds only where these hold; the falsification search "
              "samples only points where they hold; outside them the step is not claimed.")
    if not rows:
        return "## Assumptions\n\n_No proof here uses an assumption beyond its equations._"
    return ("## Assumptions\n\n" + md_table(["claim", "assumed"], rows, "ll")
            + "\n\n" + effect)


def render_paper_report(paper: str, pairs, ident: str = "") -> str:
    """Markdown of one paper's proof report (pure function of the results;
    ``ident``: the configuration lines of the provenance section)."""
    results = [r for _, r in pairs]
    titles = sorted({m.title for m, _ in pairs})
    table = md_table(["claim", "eqs", "statement", "expected", "verdict"],
                     [[f"`{r.claim.id}`", r.claim.equations, r.claim.statement, expected_verdict(r),
                       f"**{r.verdict.value}**" + ("" if r.ok else " ✗")] for r in results],
                     "llllr")
    head = f"# Proofs for paper {paper}\n\n" + "; ".join(titles) + "."
    how = (f"**{_summary(results)}.**\n\n"
            "Each claim is built as sympy objects in `proofs/` and checked by "
            "`workbench.symbolic.proof`: identities by simplification (split into sign cases "
            "where `Abs`/`sign` occur), inequalities by a decomposition into terms shown "
            "nonnegative under the hypotheses, minimisers by solving the stationarity "
            "condition and showing convexity, closed forms by substitution into the ODE; "
            "then a seeded falsification search samples the hypotheses' set. REFUTED "
            "claims come with a counterexample; a claim marked *as printed* is the paper's "
            "form of an erratum and is expected to be refuted.")
    body = [_claim_section(m, r) for m, r in pairs]
    prov = ("## Provenance\n\n" + (ident + "\n\n" if ident else "")
            + f"sympy {metadata.version('sympy')}, numpy "
            f"{metadata.version('numpy')}; falsification seed fixed in "
            "`workbench/symbolic/falsify.py`. Generated by `workbench report`; do not edit "
            "by hand.")
    return "\n\n".join([head, _verdict(results), _findings(results),
                        "## Claims\n\n" + how + "\n\n" + table,
                        "## Checked steps", *body, _assumptions(pairs), prov,
                        _traceability(pairs)]) + "\n"


def report_files() -> list:
    """``ReportFiles`` of every paper: ``proofs-NNN`` (one per paper)."""
    from .report.markdown import github_math
    from .report.writer import ReportFiles
    from .project import find_project
    from .verify import pinned_versions, project_commit
    results = run_proofs()
    root = find_project().root
    commit = project_commit(root)
    pins = pinned_versions(root)
    out = []
    for paper in sorted({m.paper for m, _ in results}):
        pairs = [(m, r) for m, r in results if m.paper == paper]
        rs = [r for _, r in pairs]
        mods = sorted({m.name for m, _ in pairs})
        ident = "\n".join(
            [f"- Proof module: `proofs/{n}.py`, SHA-256 `"
             + hashlib.sha256((proofs_folder() / f"{n}.py").read_bytes()).hexdigest() + "`"
             for n in mods]
            + [f"- Project commit: {f'`{commit}`' if commit else 'uncommitted'}",
               "- Pinned versions (constraints.txt): " + ", ".join(
                   f"{p} {pins.get(p, '—')}" for p in ("sympy", "numpy"))])
        md = github_math(render_paper_report(paper, pairs, ident))
        out.append(ReportFiles(f"proofs-{paper}", md, (),
                               all(r.ok for r in rs), _summary(rs),
                               tuple(index_row(proof_summary(rs), decide(proof_items(rs)),
                                               PROOF_LABELS))))
    return out
