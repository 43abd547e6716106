"""The ``[convergence]`` feature of the simulating kinds: every claimed
scenario metric at the step dt, dt/2 and dt/4 (issue 35, item 1).

One implementation for ``switched-run`` and ``delay-feedback``:

* :func:`load_convergence` reads the table (no keys);
* :func:`claim_targets` picks, from the design's ``[[claims]]``, those on a
  scenario metric (``<prefix><scenario>.<metric>``), each as a
  :class:`ClaimTarget` with the project's :class:`~workbench.claims.Claim`;
* :func:`claim_rows` gives each such claim its three-level check
  (:func:`workbench.refinement.refinement_row`: Richardson's estimate
  against the claim's tolerance, :func:`workbench.refinement.claim_tolerance`);
* :func:`unconverged` says which claims are then INCONCLUSIVE and why (the
  kind's ``unconverged(result)``, applied by :mod:`workbench.verify`);
* :func:`claim_table` is the report's table of those rows.

References
----------
L. F. Richardson, Phil. Trans. R. Soc. A 226:299-361, 1927.
P. J. Roache, Annu. Rev. Fluid Mech. 29:123-160, 1997 (three-grid observed order).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["LEVELS", "ClaimTarget", "claim_rows", "claim_table", "claim_targets",
           "load_convergence", "unconverged"]

#: Refinement levels of ``[convergence]``: dt / 2**k.
LEVELS = (0, 1, 2)


@dataclass(frozen=True)
class ClaimTarget:
    """A claim on a scenario metric (read for Monte Carlo pass rates and the
    convergence tolerance; :func:`workbench.claims.parse_claims` validates
    the full claim)."""

    claim: object            # workbench.claims.Claim
    scenario: str
    metric: str


def load_convergence(root) -> bool:
    """True when the design has a ``[convergence]`` table (it takes no keys:
    an unknown key is a design error)."""
    if not root.has("convergence"):
        return False
    root.table("convergence").finish()
    return True


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def claim_targets(root, prefix: str, metrics_of) -> tuple[ClaimTarget, ...]:
    """The claims of ``root`` whose quantity is ``<prefix><scenario>.<metric>``
    with a numeric value, ``metrics_of(scenario)`` the metric names of a
    scenario (an empty set for an unknown one). Built with the project's
    :class:`~workbench.claims.Claim`; only well-typed claims are kept (the
    others are rejected by :func:`workbench.claims.parse_claims` after this).
    """
    from ..claims import Claim
    raw = root.data.get("claims", [])
    out = []
    for c in raw if isinstance(raw, list) else []:
        q, cid = (c.get("quantity"), c.get("id")) if isinstance(c, dict) else (None, None)
        if not (isinstance(q, str) and isinstance(cid, str) and q.startswith(prefix)):
            continue
        scen, _, metric = q[len(prefix):].partition(".")
        v, tol = c.get("value"), c.get("tolerance", 0.0)
        cmp_, digits = c.get("compare"), c.get("digits")
        ok = (metric in metrics_of(scen) and _number(v) and _number(tol) and tol >= 0
              and cmp_ in (">=", "<=", "==", "within")
              and (digits is None or isinstance(digits, int) and not isinstance(digits, bool)))
        if ok:
            claim = Claim(cid, "", q, cmp_, float(v), float(tol), digits,
                          c.get("rounding", "round") if c.get("rounding") in ("round", "truncate")
                          else "round", "", False, "pass", "")
            out.append(ClaimTarget(claim, scen, metric))
    return tuple(out)


def claim_rows(targets, scenario: str, levels, reported: int = 0) -> list:
    """The refinement row of every claim of ``targets`` on a metric of
    ``scenario``: ``levels`` are the metric dicts at dt, dt/2, dt/4 and
    ``reported`` the index of the level whose value the claim compares (0
    for ``switched-run``; 1 for ``delay-feedback``, which reports dt/2). A
    metric that is not determined (nan at the reported level) is left out:
    its claim is INCONCLUSIVE already."""
    from ..refinement import refinement_row
    rows = []
    for c in targets:
        if c.scenario != scenario:
            continue
        vals = tuple(lv[c.metric] for lv in levels)
        if math.isnan(vals[reported]):
            continue
        rows.append(refinement_row(c.claim, vals, "dt", vals[reported]))
    return rows


def unconverged(rows) -> dict[str, str]:
    """claim id -> reason, for the rows whose metric did not converge."""
    return {r.claim_id: r.reason for r in rows if not r.converged}


def claim_table(rows) -> str:
    """Markdown: every claim on a scenario metric against its tolerance, or a
    line saying there is none."""
    from ..report.markdown import fmt, md_table
    crow = [[f"`{x.claim_id}`", f"`{x.quantity}`", fmt(x.tolerance, 2),
             "—" if x.check is None or x.check.estimate is None else fmt(x.check.estimate, 2),
             f"**{x.outcome}**" + (f": {x.reason}" if x.reason else "")]
            for x in rows]
    return (md_table(["claim", "quantity", "tolerance", "estimate", "outcome"], crow, "llrrl")
            if crow else "_No claim on a scenario metric._")
