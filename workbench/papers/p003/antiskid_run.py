"""Study ``antiskid-run``: the full runs of paper 003, section 4, in the time
domain (acceleration, cruise, braking with input delay), with the cruise
gain from the certified synthesis, a step-halving convergence check of every
reported metric, checks of the state at every phase switch, and linear
cross-checks of the LMI delay bound.

The design tables and what derives from them (controller settings, the
gain, the run of the scenario) are :mod:`workbench.papers.p003.antiskid_run_spec`;
the Monte Carlo part is :mod:`workbench.papers.p003.antiskid_montecarlo` and
:mod:`workbench.papers.p003.antiskid_halving`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ...controllers.antiskid003_settings import ControllerSettings
from ...errors import DesignError
from ...features.cli_plumbing import pick_named, timed, trajectory_csv, write_output
from ...features.comfort import COMFORT_QUANTITIES, comfort_of, comfort_quantities
from ...features.convergence import agree
from ...features.frozen_loop import FrozenLoop, freeze
from ...features.linear_delay_check import LinearDelayCheck, linear_delay_check
from ...features.quantities import Declared, DeclaredQuantities, Group, Part, determined
from ...jsonable import OMIT, json_method
from ...margins import DelayMargin
from ...reader import Reader
from ...sim.delay import SimResult
from ...sim.wheel_slip import model_functions
from .antiskid_basin_run import basin_quantities, basin_quantity_names, run_basin
from .antiskid_halving import QUANTITIES as HALVING_QUANTITIES
from .antiskid_halving import start_halving
from .antiskid_montecarlo import QUANTITIES as MONTECARLO_QUANTITIES
from .antiskid_montecarlo import start_sweep, sweep, traction_slope
from .antiskid_refine import (quarter_cases, refine_levels, three_level_metrics,
                              unconverged_reason)
from .antiskid_run_spec import (METRICS, Case, RunSpec, case_mesh, case_metrics,
                                controller_settings, gain_for, load_run_spec, nominal_cruise,
                                plant_values, run_settings, sampled_context)
from .antiskid_sampled import run_sampled, sampled_quantities, sampled_quantity_names
from .antiskid_scenario import simulate_antiskid

#: Record step (s) of the runs (figures, comfort) at dt and dt / 2.
RECORD_DT = 0.05


@dataclass(frozen=True)
class SwitchCheck(FrozenLoop):
    """The cruise loop frozen at x0 = (v, lambda) where cruise starts
    (:class:`~workbench.features.frozen_loop.FrozenLoop`; the render's names
    v, lam, A_loc), with the plant's adhesion slope d mu/d lambda there."""

    dmu_dlam: float = math.nan
    v = property(lambda s: s.x0[0])
    lam = property(lambda s: s.x0[1])
    A_loc = property(lambda s: s.A)


@dataclass(frozen=True)
class CaseResult:
    case: Case
    metrics: dict            # at dt / 2 (reported)
    metrics_coarse: dict     # at dt
    converged: dict          # metric -> bool
    run: SimResult           # recorded at dt / 2
    switch: SwitchCheck | None
    comfort: object = None         # features.comfort.RunComfort at dt / 2 (design with [comfort])
    comfort_coarse: object = None  # the same at dt
    #: The case at dt / 4 (:func:`quarter_cases`): (metrics, run, comfort), or None.
    quarter: tuple | None = None
    #: Metrics not converged over dt, dt/2, dt/4 (:func:`workbench.features.refinement.screen`).
    unconverged: tuple = ()
    #: Why they did not (:func:`~workbench.papers.p003.antiskid_refine.unconverged_reason`).
    why: str = ""


@dataclass(frozen=True)
class RunResult:
    lambda_opt: float
    lambda_d: float
    K: tuple
    K_how: str
    h_certified: float | None
    cases: tuple
    linear: LinearDelayCheck
    dt: float
    montecarlo: object = None   # antiskid_montecarlo.SweepResult or None
    halving: object = None      # antiskid_halving.HalvingCheck or None
    basin: object = None        # antiskid_basin_run.BasinResult or None
    sampled: object = None      # antiskid_sampled.SampledResult or None
    spec: RunSpec | None = None  # the design's (the quantities expand from it)

    def case(self, name: str) -> CaseResult:
        return next(c for c in self.cases if c.case.name == name)

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"lambda_opt": "lambda_opt", "lambda_d": "lambda_d", "K": "K",
                   "cases": lambda r: {c.case.name: c.metrics for c in r.cases},
                   "sampled": lambda r: OMIT if r.sampled is None else r.sampled}
    to_json = json_method


def switch_check(cs: ControllerSettings, v: float, lam: float) -> SwitchCheck:
    """Frozen linearisation of the cruise loop (eq 61 on the traction form)
    at (v, lambda), by central differences of the lambdified model
    (:func:`workbench.features.frozen_loop.freeze`)."""
    fn = model_functions("math")["traction"]
    p, c = cs.params, cs.lin

    def rhs(x):
        vv, ll = x
        y1, y2, y3, *_ = fn(vv, ll, *p)
        den = c["d4"] * (vv - cs.v_d) + c["d5"] * (ll - cs.lambda_d) + c["d6"]
        return np.array([y1, y2 - y3 / den * c["d3"]]), y3 / den

    gain = rhs(np.array([v, lam]))[1]
    Ad = gain * np.array([[0.0], [1.0]]) @ np.array([cs.K])
    fl = freeze(lambda x: rhs(x)[0], (v, lam), (1e-4 * max(v, 1.0), 1e-7), Ad)
    return SwitchCheck(fl.A, fl.abscissa, fl.margin, fl.x0,
                       float(traction_slope()(lam, *cs.params)))


def linear_check(spec: RunSpec, A, B, K) -> LinearDelayCheck:
    """The linear cross-check of the LMI delay bound on the cruise error system
    E' = A E + B K E(t - h), from E = (1, 0.01) (:func:`linear_delay_check`)."""
    return linear_delay_check(spec.linear, A, B, K, np.array([1.0, 0.01]))


#: Recording interval (s) of the trajectory ``workbench simulate --csv`` writes.
CSV_DT = 0.01


def simulate_design(design, case_name: str | None, dt: float | None,
                    record: bool = False) -> dict:
    """One case of an ``antiskid-run`` design at one step (for ``workbench
    simulate``): metrics, wall time and the real-time factor; with ``record``
    also the trajectory (``"run"``, a SimResult recorded every :data:`CSV_DT` s)."""
    spec: RunSpec = design.spec
    case = pick_named(spec.cases, case_name)
    dt = dt or spec.dt
    if not (dt > 0 and (dt <= spec.scenario["h"] or spec.scenario["h"] == 0)):
        raise DesignError("<cli>", "--dt", dt, "a positive step no larger than the delay (s)")
    K, how, _ = gain_for(spec)
    cs = controller_settings(spec, K, case)
    (run, m), wall = timed(lambda: simulate_antiskid(
        run_settings(spec, cs), dt, record_dt=max(CSV_DT, dt) if record else None,
        mesh=case_mesh(spec, case)))
    metrics = case_metrics(m, cs, spec.scenario["t_brake"])
    end = next(t for t in (m.t_stop, m.t_diverged, spec.scenario["t_end"]) if math.isfinite(t))
    return {"design": design.name, "case": case.name, "dt": dt, "K": list(K), "K_source": how,
            "metrics": metrics, "simulated_s": float(end), "wall_s": wall,
            "realtime_factor": float(end) / wall, **({"run": run} if record else {})}


def simulate_command(design, *, case: str | None, dt: float | None, as_json: bool,
                     csv: str | None = None) -> int:
    """``workbench simulate`` on a loaded ``antiskid-run`` design: print the
    metrics of one case (with ``csv`` also write its trajectory, every
    :data:`CSV_DT` s, :func:`~workbench.features.cli_plumbing.trajectory_csv`); exit 0."""
    from ...kinds.delay_feedback.cli import print_run
    from ...report.markdown import fmt
    out = simulate_design(design, case, dt, record=bool(csv))
    if csv:
        write_output(csv, trajectory_csv(out.pop("run")))
    print_run(out, f"{out['design']} / {out['case']}: dt = {fmt(out['dt'])} s, K = {out['K']} "
              f"({out['K_source']})", {k: v for k, v in out["metrics"].items()
                                       if not (isinstance(v, float) and math.isnan(v))}, as_json)
    if not as_json:
        print(f"simulated {fmt(out['simulated_s'], 4)} s in {out['wall_s']:.2f} s wall: "
              f"{out['realtime_factor']:.0f}x real time")
    return 0


def sweep_command(design, *, samples: int, seed: int, workers: int | None,
                  figure: str | None, as_json: bool, kernel: str | None = None,
                  scheduler: str | None = None, out: str | None = None,
                  resume: bool = False) -> int:
    """``workbench sweep`` on a loaded ``antiskid-run`` design: run, print summary statistics (and JSON), write
    the histogram figure; exit 0 (violations are reported, not failures)."""
    import json

    from ...features.cli_plumbing import check_sweep_flags, run_sweep, save_plot
    from .antiskid_montecarlo_render import WORDS
    check_sweep_flags(samples, workers, kernel)
    if design.spec.montecarlo is None:
        raise DesignError(design.path, "montecarlo", "<missing>",
                          "an antiskid-run design with a [montecarlo] table")
    res = run_sweep(lambda: sweep(design, samples, seed, workers=workers, kernel=kernel,
                                  progress=not as_json, scheduler=scheduler),
                    lambda: start_sweep(design, samples, seed, out=out, resume=resume,
                                        workers=workers, kernel=kernel, scheduler=scheduler),
                    out=out, resume=resume, scheduler=scheduler, progress=not as_json)
    if figure:
        save_plot(figure, "Monte Carlo histograms", lambda fig: WORDS.histograms(fig, res),
                  (9.0, 3.2))
    if as_json:
        print(json.dumps({"design": design.name, "samples": samples, "seed": seed,
                          "seconds": res.seconds, "workers": res.workers,
                          "draws": res.samples, "metrics": res.metrics,
                          "violations": res.violations}, default=lambda x: None))
        return 0
    print(f"{design.name}: {samples} runs, seed {seed}, {res.workers} worker(s), "
          f"{res.seconds:.1f} s")
    print(WORDS.tables(res, 4))
    if figure:
        print(f"wrote {figure}")
    return 0


def _cases(spec):
    return [{"c": c.name} for c in spec.cases]


def _case_metrics(spec):
    return [{"c": c.name, "m": m, "unit": u} for c in spec.cases for m, u in METRICS.items()]


def _factors(spec):
    return [{"f": f"{f:g}", "fac": f} for f in spec.linear.factors]


def _switch(r, c, field):
    sw = r.case(c).switch
    return None if sw is None else sw.margin.h if field == "margin" else getattr(sw, field)


def _comfort(r, c, k):
    cr = r.case(c)
    return None if cr.comfort is None else comfort_quantities(
        c, cr.comfort, cr.comfort_coarse, None if cr.quarter is None else cr.quarter[2]
    )[f"cases[{c}].{k}"]


#: Every claimable quantity of an ``antiskid-run`` design (:mod:`workbench.features.quantities`).
TABLE = (
    Declared("operating_point.lambda_opt", "1", lambda r: r.lambda_opt),
    Declared("operating_point.lambda_d", "1", lambda r: r.lambda_d),
    Declared("gain.K1", "1/m", lambda r: r.K[0]),      # u~ (1/s) per speed error (m/s)
    Declared("gain.K2", "1/s", lambda r: r.K[1]),      # per creep-ratio error
    Declared("gain.h_certified", "s", lambda r: r.h_certified),
    Declared("linear.finite.h_star", "s", lambda r: r.linear.finite_margin.h),
    Declared("linear.paper.exact_margin", "s", lambda r: r.linear.margin.h),
    Declared("linear.paper.max_envelope_ratio", "1",
             lambda r: max(x for _, x in r.linear.ratios)),
    Declared("linear.finite.ratio[{f}]", "1", lambda r, f, fac: next(
        (x for g, _, x in r.linear.ratios_finite if g == fac), None), over=_factors),
    Declared("cases[{c}].{m}", "{unit}", lambda r, c, m, unit: determined(r.case(c).metrics[m]),
             over=_case_metrics),
    Declared("cases[{c}].diverged", "", lambda r, c: "no" if math.isnan(
        r.case(c).metrics["t_diverged"]) else "yes", over=_cases),
    Declared("cases[{c}].stopped", "", lambda r, c: "yes" if math.isfinite(
        r.case(c).metrics["braking_duration"]) else "no", over=_cases),
    Declared("cases[{c}].converged", "", lambda r, c: None if r.case(c).quarter is None
             or r.case(c).unconverged else "yes", over=_cases),
    *(Declared(f"cases[{{c}}].switch.{f}", u, lambda r, c, f=f: _switch(r, c, f), over=_cases)
      for f, u in (("abscissa", "1/s"), ("margin", "s"), ("dmu_dlam", "1"))),
    Part((Declared("cases[{c}].{k}", "?", _comfort, over=lambda spec: [
        {"c": c.name, "k": k} for c in spec.cases for k in COMFORT_QUANTITIES]),),
         lambda spec: spec.comfort is not None),
    *MONTECARLO_QUANTITIES,
    *HALVING_QUANTITIES,
    Part((Group(lambda spec: basin_quantity_names([c.name for c in spec.cases]),
                lambda r: basin_quantities(r.basin.basin, r.basin.sweep,
                                           [c.case.name for c in r.cases], r.basin.brake)),),
         lambda spec: spec.basin is not None, lambda r: None if r.basin is None else r),
    Part((Group(lambda spec: sampled_quantity_names(spec.sampled), sampled_quantities),),
         lambda spec: spec.sampled is not None, lambda r: r.sampled),
)


class AntiskidRun(DeclaredQuantities):
    kind = "antiskid-run"
    TABLE = TABLE
    #: Findings' metrics refined three levels (issue 33, item 4) by :meth:`refine_levels`.
    refine_field, refine_unit = "dt", "s"

    def refine_levels(self, design, result, findings) -> dict:
        """The findings' metrics at three levels of their numerical parameter
        (:func:`workbench.papers.p003.antiskid_refine.refine_levels`)."""
        return refine_levels(design, result, findings, quantities=self.quantities,
                             record_dt=RECORD_DT)

    def unconverged(self, result: RunResult) -> dict[str, str]:
        """Claimed quantity ``cases[<case>].converged`` -> why its case did
        not converge over dt, dt/2, dt/4 (issue 33; :mod:`workbench.verify`
        puts it on the INCONCLUSIVE claim instead of "not determined")."""
        return {f"cases[{c.case.name}].converged": c.why for c in result.cases if c.why}

    def load(self, root: Reader) -> RunSpec:
        return load_run_spec(root)

    def start(self, design):
        """Start the Monte Carlo part of :meth:`run` (its process pools) now,
        so that it overlaps whatever the caller does next; returns the
        handle :meth:`run` takes as ``started`` (None: nothing to start)."""
        spec: RunSpec = design.spec
        if spec.montecarlo is None:
            return None
        K = gain_for(spec)[0]
        ms = spec.montecarlo
        pending = start_sweep(design, ms.samples, ms.seed, workers=ms.workers,
                              chunk=ms.chunk, pool=True, K=K)
        halving = None
        if ms.halving:    # its dt side is the sweep's first runs
            halving = start_halving(design, ms.halving, K=K, pool=True, coarse=False)
        return pending, halving

    def run(self, design, started=None) -> RunResult:
        """The cases, the linear checks and the Monte Carlo part (its chunks
        run in a pool while the cases run here; ``started``: the handle of
        :meth:`start` if it was started already)."""
        spec: RunSpec = design.spec
        nominal, lam_d, lin = nominal_cruise(spec)
        K, how, h_cert = gain_for(spec)
        if started is None:
            started = self.start(design)
        pending, halving = started or (None, None)
        try:
            cases = self._cases(spec, K, quarter_cases(design))
            lc = linear_check(spec, lin.A, lin.B, K)
            sampled = None
            if spec.sampled is not None:
                sampled = run_sampled(spec.sampled, sampled_context(spec, K), spec.dt)
        except BaseException:
            for p in (pending, halving):
                if p is not None:
                    p.cancel()
            raise
        mc = None if pending is None else pending.result()
        hc = None if halving is None else halving.result()(mc)
        bs = None if spec.basin is None else run_basin(
            spec.basin, plant_values(spec), spec.scenario["v_d"], K, nominal.lambda_opt(), cases,
            spec.mass_factor, profile=controller_settings(spec, K, spec.cases[0]).profile,
            k_de=spec.k_de)
        return RunResult(nominal.lambda_opt(), lam_d, tuple(K), how, h_cert, tuple(cases), lc,
                         spec.dt, mc, hc, bs, sampled, spec)

    def _cases(self, spec: RunSpec, K, quarter: frozenset = frozenset()) -> list[CaseResult]:
        cases, t_b = [], spec.scenario["t_brake"]
        for case in spec.cases:
            cs = controller_settings(spec, K, case)
            rs, mesh = run_settings(spec, cs), case_mesh(spec, case)
            # dt, dt / 2 and, for a claimed convergence, the third level dt / 4
            levels = [simulate_antiskid(rs, spec.dt / k, record_dt=RECORD_DT, mesh=mesh)
                      for k in ((1, 2, 4) if case.name in quarter else (1, 2))]
            runs, mets = [r for r, _ in levels], [case_metrics(m, cs, t_b) for _, m in levels]
            comfort = [None] * 3
            if spec.comfort is not None:
                u_peak = cs.u_range / spec.torque_range
                comfort = [comfort_of(r, spec.comfort, u_peak, RECORD_DT) for r in runs] + [None]
            coarse, fine = mets[:2]
            conv = {k: agree(coarse[k], fine[k], spec.conv_rtol, spec.conv_atol.get(k, 0.0))
                    for k in METRICS}
            q4, bad, why = None, (), ""
            if len(mets) == 3:
                conv, bad = three_level_metrics(spec, *mets)
                why = unconverged_reason(spec, case.name, *mets, bad)
                q4 = (mets[2], runs[2], comfort[2])
            sw = None   # state where the cruise law (61) takes over
            key = "handover" if case.cruise_entry == "creep" else "cruise"
            if math.isfinite(fine[f"lam_at_{key}"]):
                sw = switch_check(cs, fine[f"v_at_{key}"], fine[f"lam_at_{key}"])
            cases.append(CaseResult(case, fine, coarse, conv, runs[1], sw, comfort[1], comfort[0],
                                    quarter=q4, unconverged=bad, why=why))
        return cases

    def result_spec(self, res: RunResult) -> RunSpec:
        """The spec of the cases ``res`` holds (all of the design's, or one:
        :func:`~workbench.papers.p003.antiskid_refine.refine_levels`)."""
        return replace(res.spec, cases=tuple(c.case for c in res.cases))


STUDY = AntiskidRun()
