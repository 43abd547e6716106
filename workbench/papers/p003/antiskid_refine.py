"""Three-level refinement of the findings of an ``antiskid-run`` design
(issue 33, item 4).

The study computes every case at dt and dt/2 (reporting dt/2), its
sampled-data rates on a plant mesh of sub-step ``plant_step`` (checked at
``plant_step / 2`` up to 1 kHz) and its Monte Carlo runs at the sweep's dt
(its first runs again at dt/2). :func:`refine_levels` adds the one missing
level of what enters a finding, and only that:

* ``cases[<case>].*``: the case once more at dt/4 (the same scenario, the
  same mesh rule); the three levels are dt, dt/2 (reported) and dt/4, the
  comfort peaks included;
* ``switch.cruise[<case>].in_basin`` / ``switch.brake[<case>].in_basin``:
  the basin verdict of the switch state of the run at each of the three
  levels;
* ``sampled.<variant>.rate[<f>].*``: the levels are plant_step (reported),
  plant_step/2 and plant_step/4; at a rate up to 1 kHz the study has run
  them already (its three-level check of every claimed rate metric,
  :func:`~workbench.features.rate_sweep.sweep_variant`), above it
  the rate is run here at /2 and /4;
* ``montecarlo.*``: a share claim is refined on the outcome behind it,
  per run: all N runs of the sweep at its dt, the first n
  (``halving_samples``) again at dt/2 (the halving check) and at dt/4 (run
  here, compiled kernel when the sweep uses it), the other N - n runs
  bounding the count, not run
  (:func:`workbench.features.montecarlo_halving.sweep_share_levels`; our
  choice: all 64 runs at dt/2 and dt/4 cost about 6 and 18 CPU s, against
  1.2 and 2.7 s for the first 16);
* ``basin.*`` of the k2 sweep: no step (a certificate at the printed switch
  state (v_d, lambda_opt)), the same value at every level.

A finding whose metric is not among these is INCONCLUSIVE
(:func:`workbench.features.refinement.refine_by_readers`).

Why this stays in the paper: it says which of paper 003's quantities are
refined at which step (:data:`READERS`, quantity pattern -> metric reader)
and runs its kernels to read them, and which case metric to claim instead
of one that does not converge (:data:`CONVERGED_INSTEAD`). The checks
themselves (three levels against the claim's tolerance, the screen of the
case metrics, the share bound over partly refined runs, the dispatch on
the quantity, the readers of a share of Monte Carlo runs and of a metric
without a step) are :mod:`workbench.features.convergence`,
:mod:`workbench.features.refinement` and
:mod:`workbench.features.montecarlo_halving`.
"""
from __future__ import annotations

import dataclasses
import re

from ...features.comfort import comfort_of
from ...features.montecarlo_halving import sweep_share_levels
from ...features.refinement import (Levels, claimed_members, refine_by_readers, screen_levels,
                                    screen_reason, unstepped_levels)
from ...sim.kernel_path import default_kernel
from .antiskid_basin import cruise_basin
from .antiskid_basin_run import brake_points, switch_points
from .antiskid_halving import _step_values
from .antiskid_montecarlo import RUNS, range_worker
from .antiskid_run_spec import (METRICS, case_mesh, case_metrics, controller_settings,
                                plant_values, run_settings, sampled_context)
from .antiskid_sampled import SECTION, model
from .antiskid_scenario import simulate_antiskid

__all__ = ["CONVERGED_INSTEAD", "READERS", "quarter_cases",
           "refine_levels", "three_level_metrics", "unconverged_reason"]
#: Monte Carlo quantity -> per-run outcome behind it (HalvingCheck keys).
MC_OUTCOMES = {"montecarlo.fraction.diverged": "diverged",
               "montecarlo.wilson.diverged.lo": "diverged",
               "montecarlo.fraction.above_lambda_opt": "above_lambda_opt"}


def refine_levels(design, result, findings, *, quantities, record_dt: float) -> dict:
    """claim id -> :class:`workbench.features.refinement.Levels` for every
    finding of an ``antiskid-run`` design (module docstring), read by
    :data:`READERS`.

    Parameters
    ----------
    design : workbench.design.Design
    result : RunResult
        The study's result (its dt and dt/2 runs are reused).
    findings : list of ClaimResult
        The findings (claims with a severity) and their values.
    quantities : callable
        The study's ``RunResult -> quantities`` (applied to one case per level).
    record_dt : float
        Record step (s) of the study's runs (the comfort peaks).
    """
    cache: dict = {"quantities": quantities, "record_dt": record_dt}
    return refine_by_readers(findings, READERS, design, result, cache)


def _case_levels(spec, result, cache, name):
    """The case at dt, dt/2 (the study's) and dt/4 (run here) as CaseResults."""
    key = ("case", name)
    if key in cache:
        return cache[key]
    cr = result.case(name)
    if cr.quarter is not None:   # the study's own dt/4 run (a claimed convergence)
        q4, run4, c4 = cr.quarter
    else:
        cs = controller_settings(spec, result.K, cr.case)
        rec = cache["record_dt"]
        run4, m4 = simulate_antiskid(run_settings(spec, cs), spec.dt / 4, record_dt=rec,
                                     mesh=case_mesh(spec, cr.case))
        q4 = case_metrics(m4, cs, spec.scenario["t_brake"])
        c4 = comfort_of(run4, spec.comfort, cs.u_range / spec.torque_range, rec)
    coarse = dataclasses.replace(cr, metrics=cr.metrics_coarse, switch=None,
                                 comfort=cr.comfort_coarse, quarter=None)
    quarter = dataclasses.replace(cr, metrics=q4, metrics_coarse=q4, run=run4, switch=None,
                                  comfort=c4, comfort_coarse=c4, quarter=None)
    cache[key] = (coarse, cr, quarter)
    return cache[key]


def _case_quantity(design, result, cache, m, r) -> Levels:
    """A case quantity at dt, dt/2, dt/4 (the study's quantities of the case
    at each level)."""
    bare = dataclasses.replace(result, montecarlo=None, halving=None, basin=None, sampled=None)
    return Levels(tuple(cache["quantities"](dataclasses.replace(bare, cases=(c,))).get(
        r.claim.quantity) for c in _case_levels(design.spec, result, cache, m.group(1))),
        "dt", design.spec.dt)


def _switch_levels(design, result, cache, m, r) -> Levels:
    """The basin verdict of the case's switch state at dt, dt/2, dt/4, by
    the study's own method: the cruise switch judged in one
    :func:`~workbench.papers.p003.antiskid_basin.cruise_basin` call with the
    study's switch states (the weight is chosen over all of them, as in the
    study) plus this case's at dt and dt/4; the brake switch by
    :func:`~workbench.papers.p003.antiskid_basin_brake.brake_switch` at dt and
    dt/4 (dt/2: the study's verdict, the finding's value)."""
    spec, (which, name), got = design.spec, m.groups(), r.got
    if spec.basin is None:
        return Levels((), reason="the design has no basin check")
    levels = _case_levels(spec, result, cache, name)
    v_d = spec.scenario["v_d"]
    pts = [switch_points([c]) if which == "cruise" else brake_points([c], v_d) for c in levels]
    if which == "cruise":
        extra = [(f"{name}@{k}", p[0][1]) for k, p in zip(("dt", "dt/4"), (pts[0], pts[2]))
                 if p]
        basin = cruise_basin(plant_values(spec), v_d, result.K,
                             switch_points(result.cases) + extra, seed=spec.basin.seed,
                             n_traj=0)
        by = {p.label: p.verdict.outcome.name for p in basin.check.points}
        vals = (by.get(f"{name}@dt", "none"), by.get(name, "none"), by.get(f"{name}@dt/4", "none"))
    else:
        from .antiskid_basin_brake import brake_switch
        prof = controller_settings(spec, result.K, spec.cases[0]).profile
        judge = lambda p: "none" if not p else brake_switch(
            plant_values(spec), name, p[0][1], profile=prof, k_de=spec.k_de,
            seed=spec.basin.seed).outcome.name
        vals = (judge(pts[0]), got, judge(pts[2]))
    return Levels(vals, "dt", spec.dt)


def _rate_levels(design, result, cache, m, r) -> Levels:
    """A sampled rate's metric at plant_step (reported), /2 and /4
    (:meth:`workbench.features.rate_sweep_quantities.Section.levels`), a
    level the study has not run made here by the sampled kernel
    (:func:`~workbench.papers.p003.antiskid_sampled.model`)."""
    if "rates" not in cache:
        cache["rates"] = model(sampled_context(design.spec, result.K),
                               design.spec.sampled.predictor_step)
    return SECTION.levels(result.sampled, r.claim.quantity, *cache["rates"])


def _mc_levels(design, result, cache, m, r) -> Levels:
    """A Monte Carlo share finding at the sweep's dt, dt/2, dt/4 (the runs
    the halving check refines,
    :func:`workbench.features.montecarlo_halving.sweep_share_levels`; dt/4:
    the first n runs by the sweep's own chunk function,
    :func:`~workbench.papers.p003.antiskid_montecarlo.range_worker`)."""
    def quarter():
        if "mc" not in cache:
            hc = result.halving
            out = range_worker({"design": design, "K": tuple(result.K), "i0": 0, "i1": hc.n,
                                "seed": design.spec.montecarlo.seed, "step": hc.dt / 4,
                                "kernel": default_kernel()})
            cache["mc"] = _step_values(*RUNS.runs(out, design.spec.scenario["t_brake"]))
        return cache["mc"]
    return sweep_share_levels(r, lambda k: result.montecarlo.violations[k], result.halving,
                              MC_OUTCOMES, quarter, "montecarlo")


def quarter_cases(design) -> frozenset:
    """Names of the cases whose convergence a claim of ``design`` states
    (``cases[NAME].converged`` or ``.comfort_converged``): only they are run
    a third time, at dt / 4 (the refinement of the findings reuses that run)."""
    return claimed_members(design.claims, r"cases\[([^\]]+)\]\.(?:converged|comfort_converged)")


def three_level_metrics(spec, coarse: dict, fine: dict, quarter: dict) -> tuple:
    """(metric -> converged, metrics not converged) of the case metrics over
    dt, dt/2, dt/4: :func:`workbench.features.refinement.screen_levels` with
    the design's two-level screen (rtol, atol)."""
    return screen_levels({k: (coarse[k], fine[k], quarter[k]) for k in METRICS},
                         spec.conv_rtol, spec.conv_atol)


#: Paper 003: the case metric to claim instead of one that does not converge
#: over dt, dt/2, dt/4 (the braking time to v_stop moves back and forth; the
#: time to omega = 3 rad/s converges, as the designs' stop-duration claim says).
CONVERGED_INSTEAD = {"braking_duration": "omega3_after_brake"}


def unconverged_reason(spec, name: str, coarse: dict, fine: dict, quarter: dict,
                       bad: tuple) -> str:
    """Why ``cases[<name>].converged`` is INCONCLUSIVE (issue 33): every
    metric of ``bad`` (:func:`three_level_metrics`) by
    :func:`workbench.features.refinement.screen_reason`, with the quantity
    to use instead (:data:`CONVERGED_INSTEAD`; "" when every metric
    converged)."""
    return screen_reason({k: (coarse[k], fine[k], quarter[k]) for k in bad}, spec.conv_rtol,
                         spec.conv_atol, lambda k: f"cases[{name}].{k}", CONVERGED_INSTEAD,
                         "a metric of the case that converges")


#: Quantity pattern -> metric reader ``(design, result, cache, match, finding)
#: -> Levels`` of the findings this study refines (module docstring).
READERS = ((re.compile(r"switch\.(cruise|brake)\[([^\]]+)\]\.in_basin$"), _switch_levels),
           (re.compile(r"cases\[([^\]]+)\]\."), _case_quantity),
           (re.compile(r"sampled\.([a-z_]+)\.rate\[([^\]]+)\]\."), _rate_levels),
           (re.compile("(" + "|".join(map(re.escape, MC_OUTCOMES))
                       + r"|montecarlo\.halving\.fraction_agree)$"), _mc_levels),
           (re.compile(r"basin\."), lambda d, res, cache, m, r: unstepped_levels(
               r, "none (a certificate at the printed switch state, no step)")))
