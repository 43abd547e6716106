"""The convergence check of the simulating designs (issues 35 and 33): one
implementation of the step refinement, for any model.

A kind or a paper gives a ``metrics_at(step)`` callback (metric name ->
value of its runs at that numerical step); this module does the rest:

* :func:`three_levels` calls it at dt, dt/2 and dt/4 (:data:`LEVELS`), and
  :func:`level_checks` gives each metric its observed order and Richardson
  error estimate (:func:`workbench.sim.convergence.refinement_check`, the
  numerical check with its guards);
* the verdict is :class:`~workbench.sim.convergence.Convergence`, one enum:
  CONVERGED, NOT_CONVERGED, or INCONCLUSIVE (not determined);
* ``[convergence]`` of a design: :func:`load_convergence` reads the table (no
  keys), :func:`claim_targets` picks the claims on a scenario metric
  (``<prefix><scenario>.<metric>``), :func:`claim_rows` / :func:`rows_of`
  check each claim's metric at the three levels against the claim's
  tolerance (:func:`workbench.features.refinement.refinement_row`, tolerance by
  :func:`workbench.features.refinement.claim_tolerance`), :func:`unconverged` says
  which claims are then INCONCLUSIVE and why (a kind's
  ``unconverged(result)``, applied by :mod:`workbench.verify`;
  :func:`not_converged_text` the words for one metric), and
  :func:`claim_table` is the report's table of those rows;
* the dt-halving comparison of two levels: :func:`agree` (one value),
  :func:`compare_steps` (per-run metrics and outcomes at dt and dt/2) and
  its result with the runs that agree, :class:`StepComparison`;
* :func:`share_levels` (of :mod:`workbench.features.refinement`, re-exported
  here): a claim on the share of runs with an outcome, when all runs ran at
  dt and only the first n again at dt/2 and dt/4.

Used by ``switched-run``, ``delay-feedback``, ``stop-accuracy`` and paper
003 (which keeps only which of its quantities are refined at which step).
The numerical check and its enum stay in :mod:`workbench.sim.convergence`
(the sim layer's pure function) and the claim-level check (tolerance,
reason, the rows of a study's findings, the share bound) is
:mod:`workbench.features.refinement`, which this module owns (the reports
name both files).

References
----------
L. F. Richardson, Phil. Trans. R. Soc. A 226:299-361, 1927.
P. J. Roache, Annu. Rev. Fluid Mech. 29:123-160, 1997 (three-grid observed order).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ..sim.convergence import LEVELS, Convergence, Refinement, refinement_check
from .refinement import not_converged_text, refinement_row, share_levels

__all__ = ["LEVELS", "ClaimTarget", "Convergence", "StepComparison", "agree", "by_metric",
           "claim_rows", "claim_table", "claim_targets", "compare_steps", "level_checks",
           "load_convergence", "not_converged_text", "rows_of", "share_levels", "three_levels",
           "unconverged"]

def three_levels(metrics_at, step: float, *, first: dict | None = None) -> tuple:
    """The metrics at ``step``, ``step / 2`` and ``step / 4``.

    Parameters
    ----------
    metrics_at : callable
        ``step -> dict`` (metric name -> value) of the model's runs at that
        numerical step; everything else stays as designed.
    step : float
        The designed step.
    first : dict, optional
        The metrics at ``step`` when the caller has them already (not run again).

    Returns
    -------
    tuple of dict
        One metric dict per level of :data:`LEVELS`.
    """
    return tuple(first if k == 0 and first is not None else metrics_at(step / 2 ** k)
                 for k in LEVELS)


def by_metric(levels) -> dict:
    """metric -> (q1, q2, q4), from the metric dicts of :func:`three_levels`
    (the metrics of the first level, in its order)."""
    return {m: tuple(lv[m] for lv in levels) for m in levels[0]}


def level_checks(values: dict, *, tolerance: float = math.inf,
                 finite: bool = False) -> dict[str, Refinement]:
    """metric -> observed order and Richardson estimate of its three values
    (:func:`workbench.sim.convergence.refinement_check` against
    ``tolerance``; ``finite``: only the metrics finite at every level)."""
    return {m: refinement_check(*v, tolerance=tolerance) for m, v in values.items()
            if not finite or all(math.isfinite(x) for x in v)}


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
    return rows_of(((c.claim, tuple(lv[c.metric] for lv in levels)) for c in targets
                    if c.scenario == scenario), reported)


def rows_of(pairs, reported: int = 0, *, determined=lambda x: not math.isnan(x)) -> list:
    """The refinement row (:func:`workbench.features.refinement.refinement_row`) of
    every ``(claim, (q1, q2, q4))`` of ``pairs`` whose value at level
    ``reported`` is ``determined`` (the others are left out: their claim is
    INCONCLUSIVE already)."""
    from .refinement import refinement_row
    return [refinement_row(c, vals, "dt", vals[reported]) for c, vals in pairs
            if determined(vals[reported])]


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


def agree(a: float, b: float, rtol: float, atol: float) -> bool:
    """A value at dt and at dt/2 agree: |a - b| <= atol + rtol max(|a|, |b|);
    two NaNs agree (not reached at either step), NaN and a number do not."""
    if math.isnan(a) and math.isnan(b):
        return True
    return abs(a - b) <= atol + rtol * max(abs(a), abs(b))


def compare_steps(coarse: dict, fine: dict, rtol: float, atol: dict, metrics,
                  outcomes=(), masked: dict | None = None) -> tuple[dict, dict, dict]:
    """Per-run values at dt (``coarse``) and dt/2 (``fine``) compared.

    Parameters
    ----------
    coarse, fine : dict
        name -> values per run, for every name of ``metrics`` (numbers) and
        ``outcomes`` (booleans).
    rtol : float
    atol : dict
        Metric -> absolute tolerance (missing: 0).
    metrics, outcomes : sequence of str
    masked : dict, optional
        Metric -> per-run flags: a flagged run's metric is NaN at both steps
        (not compared; e.g. a value a run did not determine at one step).

    Returns
    -------
    (coarse, fine, agree) : dict, dict, dict
        The values as tuples of float / bool, metrics first, and per name
        a tuple of per-run agree flags (:func:`agree` for a metric,
        equality for an outcome).
    """
    c, f = ({**{k: tuple(float(x) for x in vals[k]) for k in metrics},
             **{k: tuple(bool(x) for x in vals[k]) for k in outcomes}} for vals in (coarse, fine))
    for k, flags in (masked or {}).items():
        for vals in (c, f):
            vals[k] = tuple(math.nan if m else x for x, m in zip(vals[k], flags))
    same = {k: tuple(agree(a, b, rtol, atol.get(k, 0.0)) for a, b in zip(c[k], f[k]))
            for k in metrics}
    same.update({k: tuple(a == b for a, b in zip(c[k], f[k])) for k in outcomes})
    return c, f, same


@dataclass(frozen=True)
class StepComparison:
    """The runs of a batch at dt and dt/2 compared (:func:`compare_steps`):
    ``coarse``, ``fine`` and ``agree`` map a metric or outcome to one entry
    per run; ``rtol`` and ``atol`` (metric -> absolute tolerance) are the
    tolerances of the comparison."""

    dt: float
    rtol: float
    atol: dict
    coarse: dict
    fine: dict
    agree: dict

    @property
    def n(self) -> int:
        return len(next(iter(self.agree.values()), ()))

    @property
    def run_agree(self) -> tuple:
        """Per run: every metric and outcome agrees."""
        return tuple(all(self.agree[k][i] for k in self.agree) for i in range(self.n))

    def quantities(self, prefix: str) -> dict:
        """``<prefix>.runs``, ``.agree`` (runs whose every metric and outcome
        agrees) and ``.fraction_agree``."""
        k = sum(self.run_agree)
        return {f"{prefix}.runs": self.n, f"{prefix}.agree": k,
                f"{prefix}.fraction_agree": k / self.n}
