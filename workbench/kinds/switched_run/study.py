"""Compute a ``switched-run`` design: every scenario at its step, and the
features the design names.

* the nominal run of each scenario (recorded for the figures);
* ``[convergence]``: the scenario again at dt/2 and dt/4; every metric's
  three values go through :func:`workbench.features.convergence.level_checks`
  (Richardson), and every claim on a scenario metric through
  :func:`workbench.features.refinement` 's row check against the claim's tolerance (the
  distance to the bound for ``<=``/``>=``), as the findings of other kinds
  are: a claim whose metric has not converged is INCONCLUSIVE with the
  reason (:meth:`workbench.kinds.switched_run.SwitchedRun.unconverged`);
* ``[montecarlo]``: one batch of ``samples`` runs per scenario with the plant
  parameters drawn (:func:`workbench.features.montecarlo.draw`, seeded; the
  controller keeps the design's values), the metrics of every run, and per
  claim on a scenario metric the share of runs that pass it with its Wilson
  95 % interval (:func:`workbench.features.montecarlo.wilson_interval`) and,
  with no failure, the success-run bound 0.05**(1/n): 0 failures in
  n >= 299 runs show P >= 0.99 at 95 % confidence.

References
----------
E. B. Wilson, J. Am. Stat. Assoc. 22:209-212, 1927 (score interval).
L. F. Richardson, Phil. Trans. R. Soc. A 226:299-361, 1927.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ...jsonable import json_method
from .simulate import Batch, Compiled, simulate

__all__ = ["ALPHA", "ClaimRate", "MonteCarloRun", "P_SHOWN", "ScenarioRun", "SwitchedRunResult",
           "run", "runs_for"]

#: One-sided risk of the success-run bound (95 % confidence).
ALPHA = 0.05
#: The pass probability the report says how many failure-free runs show.
P_SHOWN = 0.99


def runs_for(p: float, alpha: float = ALPHA) -> int:
    """Fewest runs without a failure that show a pass probability >= ``p``
    with confidence 1 - ``alpha`` (success-run rule: p**n <= alpha); 299 for
    p = 0.99 at 95 %; ValueError unless 0 < p < 1 and 0 < alpha < 1."""
    for name, x in (("p", p), ("alpha", alpha)):
        if isinstance(x, bool) or not isinstance(x, (int, float)) or not 0 < x < 1:
            raise ValueError(f"runs_for: {name} = {x!r}; expected a probability in (0, 1)")
    return math.ceil(math.log(alpha) / math.log(p))


@dataclass(frozen=True)
class MonteCarloRun:
    """The Monte Carlo batch of one scenario: draws and metrics per run."""

    samples: int
    seed: int
    draws: dict = field(repr=False)       # parameter -> array of the drawn values
    metrics: dict = field(repr=False)     # metric -> array over the runs
    reasons: tuple = field(repr=False)


@dataclass(frozen=True)
class ClaimRate:
    """Runs of a Monte Carlo that pass one claim, and their Wilson interval."""

    claim_id: str
    scenario: str
    passes: int
    n: int
    p: float
    lo: float
    hi: float
    success_run_lower: float | None


@dataclass(frozen=True)
class ScenarioRun:
    """One scenario: the nominal run, its metrics, and the features' results."""

    scenario: object
    nominal: Batch = field(repr=False)
    values: dict = field(default_factory=dict)      # metric -> float (designed step)
    levels: tuple = ()                               # metric dicts at dt, dt/2, dt/4
    checks: tuple = ()                               # (metric, Refinement) of every metric
    montecarlo: MonteCarloRun | None = None


@dataclass(frozen=True)
class SwitchedRunResult:
    spec: object
    scenarios: tuple[ScenarioRun, ...]
    refinement: tuple = ()          # RefinementRow of every claim on a scenario metric
    claim_rates: tuple[ClaimRate, ...] = ()

    JSON_FIELDS = {"scenarios": lambda r: {s.scenario.name: s.values for s in r.scenarios},
                   "refinement": lambda r: {x.claim_id: x.outcome for x in r.refinement},
                   "montecarlo": lambda r: {c.claim_id: [c.passes, c.n] for c in r.claim_rates}}
    to_json = json_method


def _values(batch: Batch) -> dict:
    return {k: float(v[0]) for k, v in batch.metrics.items()}


def run(spec) -> SwitchedRunResult:
    """Compute a design (see the module docstring)."""
    from ...features.convergence import by_metric, claim_rows, level_checks, three_levels
    comp = Compiled(spec)
    out, rows, rates = [], [], []
    for sc in spec.scenarios:
        nominal = simulate(spec, comp, sc, sc.dt, record=True)
        values = _values(nominal)
        levels, checks = (), ()
        if spec.convergence:
            levels = three_levels(lambda h: _values(simulate(spec, comp, sc, h)), sc.dt,
                                  first=values)
            checks = tuple(level_checks(by_metric(levels)).items())
            rows += claim_rows(spec.claims, sc.name, levels)
        mc = None
        if spec.montecarlo is not None:
            mc = _montecarlo(spec, comp, sc)
            rates += [_rate(c, mc) for c in spec.claims if c.scenario == sc.name]
        out.append(ScenarioRun(sc, nominal, values, levels, checks, mc))
    return SwitchedRunResult(spec, tuple(out), tuple(rows), tuple(rates))


def _montecarlo(spec, comp, sc) -> MonteCarloRun:
    from ...features.montecarlo import drawn_factors
    mc = spec.montecarlo
    draws = drawn_factors(mc, tuple(spec.plant.parameters))
    metrics, reasons = drawn_runs(spec, comp, sc, draws)
    return MonteCarloRun(mc.samples, mc.seed, draws, metrics, tuple(reasons))


def drawn_runs(spec, comp, sc, draws) -> tuple[dict, list]:
    """(metrics, reasons) of one batch of runs of scenario ``sc`` at its step,
    the plant's parameters ``draws`` (name -> array over the runs)."""
    b = simulate(spec, comp, sc, sc.dt, plant_params=draws)
    return b.metrics, list(b.reasons)


def _rate(target, mc: MonteCarloRun) -> ClaimRate:
    """The share of runs passing ``target``'s claim (a run whose metric is not
    determined, e.g. a diverged one, counts as a failure)."""
    from ...claims import check_claim
    from ...features.montecarlo import wilson_interval
    from ...outcome import Verdict
    v = mc.metrics[target.metric]
    passes = sum(check_claim(target.claim, float(x)).verdict is Verdict.PASS for x in v)
    k, n, p, lo, hi = wilson_interval(passes, len(v))
    srl = ALPHA ** (1.0 / n) if passes == n else None
    return ClaimRate(target.claim.id, target.scenario, int(passes), n, p, lo, hi, srl)

