"""Claims: machine-checkable statements in design files, and their verdicts.

A claim in a design file::

    [[claims]]
    id = "table3-eps0.35-h"
    description = "Table 3: h_m = 0.0433 s at eps = 0.35"
    quantity = "synthesis.rows[eps=0.35].h_certified"
    compare = "=="            # ">=", "<=", "==", "within"
    value = 0.0433            # a number, "inf", or a word (e.g. "certified")
    digits = 4                # "==" on numbers: compare at the printed digits
    rounding = "truncate"     # how the source printed them: "round" | "truncate"
    tolerance = 0.0           # "within": |got - value| <= tolerance
    source = "paper 003, Table 3"
    allow_inconclusive = false
    expect = "pass"           # or "fail" with `reason`: a known, documented
    reason = "..."            #   discrepancy (like pytest's strict xfail)
    severity = "minor"        # required with expect = "fail"; on a passing claim
                              #   it makes the claim a workbench finding
    origin = "paper"          # "paper" | "workbench" (default: from `source`)
    requirement = "R-003-H1"  # requirement id (default: "R-" + the claim id)
    criterion = "..."         # acceptance criterion (default: quantity, compare, value)
    basis = "paper"           # where the requirement comes from: "paper" | "standard"
                              #   | "customer" | "our choice" (default: "paper" for a
                              #   paper claim, else "our choice")
    standard = "EN 15595, 4.2"  # name and clause; required with basis = "standard"
    hazard = "HZ-003-LOCK"    # the hazard a safety finding shows (an id of [[hazards]])
    untested = "..."          # the check holds but cannot test the requirement (why):
                              #   the requirement counts as not tested
    severity_reason = "..."   # why this severity (shown with the finding)
    converged_instead = "..." # a quantity of the design to use when this finding's
                              #   metric has not converged (issue 33, item 4)

Traceability (issue 33, item 2): a claim with no ``requirement`` traces to a
requirement of its own, ``R-<claim id>``; with no ``criterion`` its
acceptance criterion is its comparison (``quantity compare value``); with no
``basis`` it is ``paper`` when the claim states the paper's result and ``our
choice`` otherwise. A workbench finding's claim states the defect, so its
derived criterion is the negation of its comparison. :attr:`Claim.derived`
names the fields so derived, and the report marks them.

A design's hazard log and assumptions register (issue 33, item 3)::

    [[hazards]]
    id = "HZ-003-LOCK"
    hazard = "wheel lock in braking"
    cause = "..."
    consequence = "..."
    mitigation = "..."
    status = "open"           # "open" | "mitigated" | "closed" (HAZARD_STATUSES)

    [[assumptions]]
    text = "we chose ..."
    effect = "..."            # its effect on the result

A ``description`` or ``reason`` never types a measured number: it names it,
``{quantity}`` or ``{quantity:N}`` (N significant digits, default 4;
``{quantity:N%}`` prints 100 x the value, for a fraction written in per
cent), and the field is filled from the design's results when the claim is
evaluated (:func:`fill_claim`); a field naming no quantity of the design is
bad input. ``{{`` and ``}}`` write a brace (``{{V <= c}}``). ``tests/test_typed_numbers.py`` states what a text may type.

Severities form a closed set, mildest first (:data:`SEVERITIES`):

``rounding``
    within the precision the paper printed: checked — the claim is not ok
    unless |got - value| <= 1e-3 |value| (the size of a paper's rounding of
    printed intermediate values);
``minor``
    a difference that changes no conclusion;
``changes-the-result``
    a printed number or conclusion does not hold;
``safety``
    divergence, wheel lock or spin, instability, a string-unstable platoon.

A claim with a severity is a *finding*: a paper claim that is not reproduced
(``expect = "fail"``), or a defect the workbench shows and the paper does not
state (a passing claim whose origin is the workbench). Each report opens with
its findings, most severe first.

Verdicts form a closed set: PASS, FAIL, INCONCLUSIVE. A claim is *ok* when it
passes, is inconclusive and allows it (whether it was expected to pass or to
fail: a finding whose metric has not converged, issue 33 item 4), or fails
and was expected to fail; a
claim expected to fail that passes is not ok (the discrepancy went away, so
the design must be updated).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import ROUND_DOWN, ROUND_HALF_EVEN, Decimal, localcontext
from typing import Any

from .jsonable import json_method
from .outcome import Verdict
from .reader import Reader

COMPARES = (">=", "<=", "==", "within")


@dataclass(frozen=True)
class Claim:
    """One claim of a design (see module docstring)."""

    id: str
    description: str
    quantity: str
    compare: str
    value: float | str
    tolerance: float
    digits: int | None
    rounding: str
    source: str
    allow_inconclusive: bool
    expect: str
    reason: str
    severity: str | None = None
    origin: str = "paper"
    requirement: str = ""
    criterion: str = ""
    basis: str = "paper"
    standard: str = ""
    hazard: str | None = None
    derived: tuple[str, ...] = ()
    untested: str = ""
    severity_reason: str = ""
    converged_instead: str = ""

    @property
    def is_finding(self) -> bool:
        """A severity makes the claim a finding (see the module docstring)."""
        return self.severity is not None


#: Severities of findings, mildest first (module docstring).
SEVERITIES = ("rounding", "minor", "changes-the-result", "safety")
#: Where a claim comes from: a statement of a paper, or the workbench's own check.
ORIGINS = ("paper", "workbench")
#: Where a requirement comes from (issue 33, item 2).
BASES = ("paper", "standard", "customer", "our choice")
#: Status of a hazard: no mitigation yet; a mitigation named but not shown by
#: this design's claims; mitigation shown (the hazard no longer blocks a verdict).
HAZARD_STATUSES = ("open", "mitigated", "closed")
#: Relative size of a "rounding" discrepancy.
ROUNDING_RTOL = 1e-3
_PAPER_SOURCE = re.compile(r"^(paper\s*)?\d{3}\b", re.I)


def origin_of(source: str) -> str:
    """Default origin: "paper" when ``source`` cites a paper ("003 Table 3",
    "paper 002 §4"), else "workbench"."""
    return "paper" if _PAPER_SOURCE.match(source.strip()) else "workbench"


@dataclass(frozen=True)
class ClaimResult:
    """A claim with what was measured and its verdict."""

    claim: Claim
    got: float | str | None
    verdict: Verdict
    note: str = ""
    #: Peak error that sets the noise floor of ``got`` when it is a final or
    #: minimum error (:func:`workbench.report.markdown.noise_cell`), else None.
    peak: float | None = None

    @property
    def severity_holds(self) -> bool:
        """False only for a ``rounding`` finding whose measured value is not
        within :data:`ROUNDING_RTOL` of the claimed one."""
        c = self.claim
        if c.severity != "rounding" or isinstance(c.value, str) or isinstance(self.got, str) \
                or self.got is None:
            return True
        return abs(float(self.got) - c.value) <= ROUNDING_RTOL * abs(c.value)

    @property
    def ok(self) -> bool:
        c = self.claim
        if not self.severity_holds:
            return False
        if self.verdict is Verdict.INCONCLUSIVE:
            return c.allow_inconclusive
        return self.verdict is (Verdict.FAIL if c.expect == "fail" else Verdict.PASS)

    #: The JSON of a checked claim (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"id": "claim.id", "quantity": "claim.quantity", "compare": "claim.compare",
                   "expected": "claim.value", "tolerance": "claim.tolerance", "got": "got",
                   "verdict": "verdict", "ok": "ok", "expect": "claim.expect",
                   "source": "claim.source", "note": "note", "severity": "claim.severity",
                   "origin": "claim.origin"}
    to_json = json_method


_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.=+-]*$")
#: A template field of a claim's text: ``{quantity}``, ``{quantity:N}`` or ``{quantity:N%}``;
#: ``{{`` and ``}}`` are escaped braces (no group matched).
TEMPLATE_FIELD = re.compile(r"\{\{|\}\}|\{([^{}:]+)(?::(\d+)?(%)?)?\}")


def fill_text(text: str, quantities: dict, fmt) -> str:
    """``text`` with each ``{quantity:N}`` replaced by ``fmt(value, N)``
    (``{quantity:N%}``: by ``fmt(100 value, N)``)."""
    def one(m):
        if m[1] is None:
            return m[0][0]
        v = quantities.get(m[1].strip())
        if m[3] and isinstance(v, (int, float)) and not isinstance(v, bool):
            v = 100 * v
        return fmt(v, int(m[2] or 4))
    return TEMPLATE_FIELD.sub(one, text)


def fill_claim(claim: Claim, quantities: dict, fmt) -> Claim:
    """The claim with its description and reason filled from ``quantities``
    (``fmt(value, digits) -> str`` prints a value)."""
    from dataclasses import replace
    return replace(claim, description=fill_text(claim.description, quantities, fmt),
                   reason=fill_text(claim.reason, quantities, fmt))


def _check_fields(r: Reader, key: str, text: str, names: set[str]) -> None:
    for m in TEMPLATE_FIELD.finditer(text):
        if m[1] is None:
            continue
        if m[1].strip() not in names:
            raise r.fail(key, m[0], "template fields {quantity}, {quantity:N} or "
                         "{quantity:N%} naming a quantity this design computes")
        if m[2] is not None and not 1 <= int(m[2]) <= 12:
            raise r.fail(key, m[0], "N from 1 to 12 significant digits in {quantity:N}")
    if "{" in TEMPLATE_FIELD.sub("", text) or "}" in TEMPLATE_FIELD.sub("", text):
        raise r.fail(key, text, "braces only around template fields {quantity}, "
                     "{quantity:N} or {quantity:N%} ({{ and }} for a brace)")


def parse_claims(root: Reader, study, spec) -> list[Claim]:
    """Validate the ``[[claims]]`` of a design against the study's quantities."""
    names = study.quantity_names(spec)
    out, seen = [], set()
    for r in root.tables("claims", default=[]):
        cid = r.string("id")
        if not _ID.match(cid):
            raise r.fail("id", cid, "letters, digits and _ . = + - only")
        if cid in seen:
            raise r.fail("id", cid, "an id not used by another claim")
        seen.add(cid)
        desc = r.string("description")
        q = r.string("quantity")
        if q not in names:
            near = sorted(names)[:8]
            raise r.fail("quantity", q, "a quantity this design computes, e.g. "
                         + ", ".join(near) + (" ..." if len(names) > 8 else ""))
        cmp_ = r.string("compare", choices=COMPARES)
        raw = r.raw("value")
        if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
            raise r.fail("value", raw, 'a number, "inf" or a word')
        value: float | str
        if isinstance(raw, str):
            value = math.inf if raw == "inf" else raw
            if isinstance(value, str) and cmp_ != "==":
                raise r.fail("compare", cmp_, '"==" for a word value')
        else:
            value = float(raw)
            if not math.isfinite(value):
                raise r.fail("value", raw, "a finite number (or the string \"inf\")")
        tol = r.number("tolerance", default=0.0, nonneg=True)
        if cmp_ == "within" and not r.has("tolerance"):
            raise r.fail("tolerance", "<missing>", 'a tolerance for compare = "within"')
        digits = r.number("digits", default=None, integer=True, lo=0, hi=12,
                          what="integer number of printed decimals")
        rounding = r.string("rounding", default="round", choices=("round", "truncate"))
        src = r.string("source")
        allow = r.boolean("allow_inconclusive", default=False)
        expect = r.string("expect", default="pass", choices=("pass", "fail"))
        reason = r.string("reason", default="")
        if expect == "fail" and not reason:
            raise r.fail("reason", "<missing>", 'a reason when expect = "fail"')
        for key, text in (("description", desc), ("reason", reason)):
            _check_fields(r, key, text, names)
        severity = r.string("severity", default=None, choices=SEVERITIES)
        if expect == "fail" and severity is None:
            raise r.fail("severity", "<missing>",
                         'a severity for a known discrepancy: one of ' + ", ".join(SEVERITIES))
        origin = r.string("origin", default=origin_of(src), choices=ORIGINS)
        if severity is not None and expect == "pass" and origin == "paper":
            raise r.fail("severity", severity, 'no severity on a reproduced paper claim '
                         '(a finding is expect = "fail", or origin = "workbench")')
        meta = _traceability(r, cid, q, cmp_, value, tol, digits, rounding, origin, severity)
        instead = r.string("converged_instead", default="")
        if instead and instead not in names:
            raise r.fail("converged_instead", instead, "a quantity this design computes")
        r.finish()
        out.append(Claim(cid, desc, q, cmp_, value, tol, digits, rounding, src, allow,
                         expect, reason, severity, origin, **meta, converged_instead=instead))
    return out


def criterion_text(quantity: str, compare: str, value, tolerance: float,
                   digits: int | None, rounding: str) -> str:
    """A claim's comparison as an acceptance criterion: ``quantity == 0.0255
    (4 decimals, truncated)``, ``quantity within 10.5 ± 0.105``."""
    def fmt(x, sig=6):
        if isinstance(x, str):
            return x
        return ("∞" if x > 0 else "−∞") if math.isinf(x) else f"{x:.{sig}g}"
    want = f"{quantity} {compare} {fmt(value)}"
    if compare == "within" or (compare != "==" and tolerance):
        want += f" ± {fmt(tolerance, 4)}"
    if digits is not None:
        want += f" ({digits} decimals, {'truncated' if rounding == 'truncate' else 'rounded'})"
    return want


def _traceability(r: Reader, cid, q, cmp_, value, tol, digits, rounding, origin,
                  severity) -> dict:
    """The requirement keys of one claim, with the defaults of the module
    docstring (``derived`` names those the file left out)."""
    derived = tuple(k for k in ("requirement", "criterion", "basis") if not r.has(k))
    req = r.string("requirement", default=f"R-{cid}")
    if not _ID.match(req):
        raise r.fail("requirement", req, "letters, digits and _ . = + - only")
    crit = r.string("criterion", default=None) or criterion_text(q, cmp_, value, tol, digits,
                                                                 rounding)
    if not r.has("criterion") and severity is not None and r.raw("expect", "pass") == "pass":
        crit = f"not ({crit}): the claim shows the defect"
    basis = r.string("basis", default="paper" if origin == "paper" else "our choice",
                     choices=BASES)
    standard = r.string("standard", default="")
    if basis == "standard" and not standard:
        raise r.fail("standard", "<missing>", 'the standard and clause (e.g. "EN 15595, '
                     'wheel slide protection") when basis = "standard"')
    if standard and basis != "standard":
        raise r.fail("standard", standard, 'no standard unless basis = "standard"')
    hazard = r.string("hazard", default=None)
    if hazard is not None and severity != "safety":
        raise r.fail("hazard", hazard, 'a hazard only on a finding with severity = "safety"')
    untested = r.string("untested", default="")
    why = r.string("severity_reason", default="")
    if why and severity is None:
        raise r.fail("severity_reason", why, "a severity_reason only on a claim with a severity")
    return dict(requirement=req, criterion=crit, basis=basis, standard=standard,
                hazard=hazard, derived=derived, untested=untested, severity_reason=why)


@dataclass(frozen=True)
class Hazard:
    """One entry of a design's hazard log (module docstring)."""

    id: str
    hazard: str
    cause: str
    consequence: str
    mitigation: str
    status: str


@dataclass(frozen=True)
class Assumption:
    """One entry of a design's assumptions register: what was assumed or
    chosen, and its effect on the result."""

    text: str
    effect: str


def parse_register(root: Reader, claims) -> tuple[tuple[Hazard, ...], tuple[Assumption, ...]]:
    """The ``[[hazards]]`` and ``[[assumptions]]`` of a design (both
    optional); every ``hazard`` a claim names must be in the log."""
    hazards, seen = [], set()
    for r in root.tables("hazards", default=[]):
        hid = r.string("id")
        if not _ID.match(hid) or hid in seen:
            raise r.fail("id", hid, "a hazard id (letters, digits, _ . = + -) used once")
        seen.add(hid)
        hazards.append(Hazard(hid, r.string("hazard"), r.string("cause"),
                              r.string("consequence"), r.string("mitigation"),
                              r.string("status", choices=HAZARD_STATUSES)))
        r.finish()
    assumptions = []
    for r in root.tables("assumptions", default=[]):
        assumptions.append(Assumption(r.string("text"), r.string("effect")))
        r.finish()
    for i, c in enumerate(claims):
        if c.hazard is not None and c.hazard not in seen:
            raise root.fail(f"claims[{i}].hazard", c.hazard,
                            "the id of a [[hazards]] entry of this design")
    return tuple(hazards), tuple(assumptions)


def _printed(x: float, digits: int, rounding: str) -> Decimal:
    mode = ROUND_DOWN if rounding == "truncate" else ROUND_HALF_EVEN
    with localcontext() as ctx:     # 1e308 at 12 decimals: 321 digits (default 28 raises)
        ctx.prec = 340
        return Decimal(repr(x)).quantize(Decimal(1).scaleb(-digits), rounding=mode)


def check_claim(claim: Claim, got: Any) -> ClaimResult:
    """Compare a measured value with a claim.

    ``got`` is a number, ``inf``, a word, or ``None`` (not determined:
    INCONCLUSIVE).
    """
    if got is None or (isinstance(got, float) and math.isnan(got)):
        return ClaimResult(claim, None, Verdict.INCONCLUSIVE, "not determined")
    v = claim.value
    if isinstance(v, str) or isinstance(got, str):
        ok = str(got) == str(v)
        return ClaimResult(claim, got, Verdict.PASS if ok else Verdict.FAIL)
    got = float(got)
    if claim.compare == ">=":
        ok = got >= v - claim.tolerance
    elif claim.compare == "<=":
        ok = got <= v + claim.tolerance
    elif claim.compare == "within":
        ok = abs(got - v) <= claim.tolerance if math.isfinite(got) else got == v
    else:  # "=="
        if math.isinf(v) or math.isinf(got):
            ok = got == v
        elif claim.digits is not None:
            ok = _printed(got, claim.digits, claim.rounding) == _printed(v, claim.digits, "round")
        else:
            ok = abs(got - v) <= claim.tolerance
    return ClaimResult(claim, got, Verdict.PASS if ok else Verdict.FAIL)
