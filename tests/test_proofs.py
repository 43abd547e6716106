"""The shipped proofs: verdicts, erratum pairs, counterexamples, CLI, verify and reports."""
import json
import re
from pathlib import Path

import pytest
import sympy as sp

from workbench import cli
from workbench.cli import main
from workbench.prove import proof_modules, report_files, run_proofs
from workbench.symbolic.proof import Verdict

CLAIMS = [(m.name, c) for m in proof_modules() for c in m.claims]
IDS = {c.id: c for _, c in CLAIMS}
#: The mathematical errata of ../shared/SEEDS.md (not label typos), and the
#: lead's finding on eq 55 of paper 003: each needs an as-printed claim.
ERRATA = ["smarc-eq19-printed", "smarc-eq20-printed", "smarc-eq21-24-printed",
          "brake-model-eq1-printed", "ntsm-eq5-printed", "lin-eq25-printed",
          "lmi-eq55-printed"]


@pytest.fixture(scope="module")
def results():
    return {r.claim.id: r for _, r in run_proofs()}


def test_ids_are_unique():
    assert len(IDS) == len(CLAIMS)


@pytest.mark.parametrize("cid", sorted(IDS))
def test_shipped_claim_has_its_expected_verdict(results, cid):
    r = results[cid]
    want = Verdict.REFUTED if r.claim.expect == "refuted" else Verdict.PROVED
    assert r.verdict is want, r.remaining


@pytest.mark.parametrize("cid", ERRATA)
def test_every_erratum_has_a_refuted_printed_and_proved_corrected_form(results, cid):
    assert results[cid].verdict is Verdict.REFUTED and results[cid].counterexample is not None
    partner = cid.replace("-printed", "-corrected")
    if partner not in IDS:  # the note names the corrected claim
        partner = next(i for i in re.findall(r"[a-z0-9]+-[a-z0-9-]+", IDS[cid].note)
                       if i in IDS)
    assert results[partner].verdict is Verdict.PROVED


def test_every_printed_claim_is_expected_refuted():
    for cid, c in IDS.items():
        assert ("printed" in cid) == (c.expect == "refuted"), cid


def _residual_at(claim, cex):
    lhs, rhs = claim.lhs, claim.rhs
    diff = (sp.Matrix(lhs) - sp.Matrix(rhs)) if isinstance(lhs, sp.MatrixBase) else \
        sp.sympify(rhs) - sp.sympify(lhs)
    for s, e in claim.given:
        diff = diff.subs(s, e)
    names = {sp.latex(s): s for s in diff.free_symbols}
    vals = {names[n]: sp.Float(v, 30) for n, v in cex if n in names}
    entries = list(diff) if isinstance(diff, sp.MatrixBase) else [diff]
    # the counterexample names the symbols of the entry that fails
    return [complex(sp.N(e.subs(vals), 30)) for e in entries if e.free_symbols <= set(vals)]


@pytest.mark.parametrize("cid", [c for c in sorted(IDS) if IDS[c].kind in
                                 ("identity", "inequality") and IDS[c].expect == "refuted"])
def test_counterexamples_really_fail(results, cid):
    r = results[cid]
    vals = _residual_at(r.claim, r.counterexample)
    if r.claim.kind == "identity":
        assert max(abs(v) for v in vals) > 1e-9
    else:  # margin rhs - lhs negative
        assert min(v.real for v in vals) < -1e-9


def test_prove_cli(capsys):
    assert main(["prove", "002"]) == 0
    out = capsys.readouterr().out
    assert "mfac-eq6-control" in out and "PROVED" in out
    assert main(["prove", "--json", "smarc-eq25", "lmi-eq55-printed"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [p["verdict"] for p in data["proofs"]] == ["PROVED", "REFUTED"]
    assert data["proofs"][1]["counterexample"]
    assert main(["prove", "no-such-claim"]) == 2
    assert "PROOF" in capsys.readouterr().err


def test_verify_includes_every_proof_claim():
    extra = cli._extra_verifications(None)
    assert len(extra["rows"]) == len(CLAIMS) and extra["bad"] == 0
    assert len(extra["json"]["proofs"]) == len(CLAIMS)
    assert {row[1] for row in extra["rows"]} == set(IDS)


def test_reports_one_per_paper_with_counterexamples():
    files = {f.name: f for f in report_files()}
    assert sorted(files) == [f"proofs-{p}" for p in ("000", "001", "002", "003", "004")]
    for m, c in CLAIMS:
        md = files[f"proofs-{next(x.paper for x in proof_modules() if x.name == m)}"].markdown
        section = md.split(f"### `{c.id}`")[1].split("\n### ")[0]
        assert ("**Counterexample**" in section) == (c.expect == "refuted"), c.id
    assert all(f.ok for f in files.values())
    assert [f.markdown for f in report_files()] == [f.markdown for f in files.values()]


def test_proofs_never_parse_strings():
    for p in sorted(Path("proofs").glob("*.py")):
        text = p.read_text()
        for banned in ("eval(", "exec(", "sympify(", "parse_expr", "S(\""):
            assert banned not in text, f"{p}: {banned}"


# -- severities of errata and the Findings block (issue 19) ------------------------------
def test_errata_carry_a_severity_with_a_reason():
    from workbench.claims import SEVERITIES
    for cid, c in IDS.items():
        assert c.severity in (*SEVERITIES, None), cid
        assert bool(c.severity) == bool(c.severity_reason.strip()), cid
        if c.severity:
            assert c.expect == "refuted" and "\n" not in c.severity_reason, cid
        # a corrected form is the workbench's, never a step the paper printed
        assert ("corrected" in cid) <= (c.origin == "workbench"), cid


def test_a_rounding_erratum_is_checked(results):
    from dataclasses import replace

    from workbench.prove import rounding_holds
    r = results["brake-difference-printed"]       # 004 sec. 2.3: 40.754 printed, 40.751 exact
    assert r.claim.severity == "rounding" and rounding_holds(r) and r.ok
    # 2 % off is not a rounding
    far = replace(r, counterexample=(("computed", 41.6),))
    assert not rounding_holds(far)
    assert not replace(far, severity_holds=rounding_holds(far)).ok


@pytest.mark.parametrize("severity, expect, kind, reason, key", [
    ("huge", "refuted", "value", "why", "severity"),
    ("minor", "proved", "value", "why", "severity"),
    ("rounding", "refuted", "identity", "why", "severity"),
    ("minor", "refuted", "value", "", "severity_reason"),
])
def test_a_bad_proof_severity_is_bad_input(severity, expect, kind, reason, key):
    from workbench.errors import DesignError
    from workbench.prove import check_proof_severity
    from workbench.symbolic.proof import Claim
    c = Claim("x-printed", "004", "1", "s", kind, sp.Integer(1), 1.0, digits=1, expect=expect,
              severity=severity, severity_reason=reason)
    with pytest.raises(DesignError) as e:
        check_proof_severity(Path("proofs/p.py"), c)
    msg = str(e.value)
    assert len(msg.splitlines()) == 1 and f"claims()[x-printed].{key}" in msg and "expected" in msg


def test_proof_reports_open_with_the_verdict_then_findings():
    for f in report_files():
        md = f.markdown
        heads = re.findall(r"^## .*$", md, re.M)
        assert heads[:2] == ["## Design verdict", "## Findings"], f.name
        assert heads[-1] == "## Traceability" and "Coverage: " in md, f.name
        assert "Verified" not in md and "- Project commit: " in md, f.name
        assert f.index[0] in ("**accept**", "**accept with conditions**", "**reject**")
        findings = md.split("## Findings")[1].split("\n## ")[0]
        errata = [c for m in proof_modules() if f"proofs-{m.paper}" == f.name
                  for c in m.claims if c.expect == "refuted"]
        for c in errata:   # each erratum a row with its severity and a link to its section
            row = next(line for line in findings.splitlines() if f"`{c.id}`" in line)
            assert f"**{c.severity or 'not assessed'}**" in row
            assert f"(#{c.id}--refuted)" in row
        assert f.index[2] != "none" or not errata
