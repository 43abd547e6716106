"""Monte Carlo robustness sweep of an ``antiskid-run`` design.

Samples (seeded, numpy ``SeedSequence``): plant mass factor, adhesion
between the wet and the dry curve (a, b, c interpolated with s in [0, 1]:
s = 0 wet, s = 1 dry), true input delay in [0, h_max] (the predictor keeps
the design's h), initial speed. Sample i is row i of one (n, 4) uniform draw,
so the first n runs of a larger sweep with the same seed have the same
parameters. Each worker simulates one chunk of samples as a batch (arrays,
one pass of the fixed-step loop) and returns plain lists; a local process
pool runs the chunks; progress goes to stderr.

A batch halves a step only for the runs that need it
(:func:`workbench.controllers.antiskid003.stiff_step`), so a run's metrics
do not depend on its chunk mates (up to rounding: the batch evaluates the
model with numpy, a single run with ``math``). The partition into chunks
depends on the sample count (and ``chunk``) only, never on the worker count.

The controller always uses the design's nominal model (dry rail, nominal
mass): the sweep measures robustness, not re-tuning.

Step-size check (issue 5, item 1): :func:`start_halving` simulates the first
n runs of the sweep (the same draws) as one batch at the design's dt and as
one batch at dt / 2, and compares their metrics and outcomes per run with
the design's convergence tolerances (:class:`HalvingCheck`,
:func:`halving_section`).
"""
from __future__ import annotations

import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field

import numpy as np

#: Summary statistics reported per metric. The time to the stop (v <= v_stop)
#: is not one: after omega <= 3 rad/s the desired creep speed steps to 0 and
#: the train coasts on running resistance, ~46 s per m/s of speed left when the
#: creep is released; that release is a transient at dt |J| ~ 40 which the
#: fixed step resolves for the nominal plant (the design's braking time agrees
#: with a refined mesh) but not for mismatched plants (dt / 2 moved it by up
#: to 13 s in the halving check). The stop itself is the ``not_stopped``
#: outcome; ``omega3_after_brake`` (the end of creep-controlled braking, the
#: paper's "about 350 s") is converged.
SUMMARY_METRICS = ("lam_max_over_opt", "t_cruise", "omega3_after_brake")

#: Statistics of each summary metric (over its finite values).
STATISTICS = ("n_finite", "min", "median", "p95", "max")

#: Checks counted per run: key -> what a violation means.
VIOLATIONS = {"above_lambda_opt": "creep ratio above the sample's lambda_opt in traction",
              "diverged": "diverged (|lambda| >= 0.9, torque out of range, or step not resolved)",
              "not_stopped": "not stopped by t_end"}

#: Default number of chunks a sweep is cut into (independent of the workers).
DEFAULT_CHUNKS = 4


@dataclass(frozen=True)
class SweepSpec:
    """The design's ``[montecarlo]`` table: ranges of the sweep and the run of
    the study (``samples`` runs with ``seed``, ``chunk`` samples per batch,
    ``workers`` processes)."""

    mass: tuple[float, float]
    wet: dict               # a, b, c of the wet curve
    adhesion: tuple[float, float]
    h: tuple[float, float]
    v0: tuple[float, float]
    case: str
    samples: int
    seed: int
    workers: int
    chunk: int | None = None
    halving: int = 0        # first runs re-checked at dt and dt / 2 (:func:`start_halving`)
    dt: float | None = None  # step of the sweep's runs (None: the design's [numerics] dt)


@dataclass(frozen=True)
class SweepResult:
    samples: dict           # name -> list of floats
    metrics: dict           # name -> list of floats
    violations: dict        # key of VIOLATIONS -> list of bool
    seconds: float
    workers: int

    @property
    def n(self) -> int:
        return len(self.metrics["t_cruise"])

    def summary_rows(self) -> list[list]:
        """[metric, n finite, min, median, 95th percentile, max] per summary
        metric (None where no run has a finite value)."""
        rows = []
        for k in SUMMARY_METRICS:
            x = np.asarray(self.metrics[k], float)
            ok = x[np.isfinite(x)]
            if ok.size == 0:
                rows.append([k, 0, None, None, None, None])
                continue
            rows.append([k, int(ok.size), float(ok.min()), float(np.median(ok)),
                         float(np.percentile(ok, 95)), float(ok.max())])
        return rows

    def statistics(self) -> dict:
        """``{"<metric>.<statistic>": value}`` from :meth:`summary_rows` and
        ``{"fraction.<violation>": value}`` (fraction of all runs)."""
        out = {f"{r[0]}.{s}": x for r in self.summary_rows() for s, x in zip(STATISTICS, r[1:])}
        out.update({f"fraction.{k}": sum(v) / self.n for k, v in self.violations.items()})
        return out


def montecarlo_quantity_names() -> set[str]:
    """Quantities of a sweep run by the ``antiskid-run`` study:
    ``montecarlo.samples``, ``montecarlo.<metric>.<statistic>`` and
    ``montecarlo.fraction.<violation>``."""
    return ({"montecarlo.samples"}
            | {f"montecarlo.{m}.{s}" for m in SUMMARY_METRICS for s in STATISTICS}
            | {f"montecarlo.fraction.{k}" for k in VIOLATIONS})


def montecarlo_quantities(res: SweepResult) -> dict:
    """The values of :func:`montecarlo_quantity_names` (None: no finite value)."""
    return {"montecarlo.samples": res.n,
            **{f"montecarlo.{k}": v for k, v in res.statistics().items()}}


def draw_samples(n: int, seed: int, spec: SweepSpec) -> dict:
    """n samples of (mass factor, adhesion s, delay h, v0), uniform, seeded;
    sample i does not depend on n."""
    u = np.random.default_rng(np.random.SeedSequence(seed)).uniform(size=(n, 4))
    names = ("mass", "adhesion", "h", "v0")
    return {k: lo + (hi - lo) * u[:, j]
            for j, (k, (lo, hi)) in enumerate(zip(names, (spec.mass, spec.adhesion, spec.h,
                                                          spec.v0)))}


def _chunk_worker(payload: dict) -> dict:
    """Simulate one chunk (plain data in, plain data out)."""
    from ..controllers.antiskid003 import (PARAM_ORDER, ControllerSettings, CreepSpeedProfile,
                                           RunSettings, simulate_antiskid)
    cs_d = dict(payload["controller"])
    cs_d["profile"] = CreepSpeedProfile(**cs_d["profile"])
    cs_d["params"] = tuple(cs_d["params"])
    cs_d["K"] = tuple(cs_d["K"])
    cs = ControllerSettings(**cs_d)
    plant = tuple(np.asarray(payload["plant"][k], float) for k in PARAM_ORDER)
    n = len(payload["h"])
    run = RunSettings(plant, cs, np.asarray(payload["h"], float),
                      (np.asarray(payload["v0"], float), payload["lambda0"]),
                      payload["u_init"], payload["t_end"])
    _, m = simulate_antiskid(run, payload["dt"], record_dt=None, batch=n)
    return {"index": payload["index"], "metrics": {k: np.asarray(v, float).tolist()
                                                   for k, v in vars(m).items()}}


def _progress(done: int, total: int, t0: float, stream=sys.stderr) -> None:
    width = 30
    k = int(width * done / total)
    stream.write(f"\r[{'#' * k}{'.' * (width - k)}] {done}/{total} chunks, "
                 f"{time.perf_counter() - t0:.0f} s")
    if done == total:
        stream.write("\n")
    stream.flush()


class PendingSweep:
    """A sweep whose chunks are running (in a process pool, or still to run
    in-process); :meth:`result` waits for them and returns what ``collect``
    makes of their outputs (:class:`SweepResult`, or :class:`HalvingCheck`
    for :func:`start_halving`)."""

    def __init__(self, payloads: list, collect, workers: int, pool: bool):
        self._payloads, self._collect, self.workers = payloads, collect, workers
        self._t0 = time.perf_counter()
        self._pool = ProcessPoolExecutor(max_workers=min(workers, len(payloads))) if pool \
            else None
        self._futures = None if self._pool is None else [
            self._pool.submit(_chunk_worker, p) for p in payloads]

    def result(self, progress: bool = False):
        n, outs = len(self._payloads), []
        if progress:
            _progress(0, n, self._t0)
        try:
            for i, p in enumerate(self._payloads):
                outs.append(_chunk_worker(p) if self._pool is None
                            else self._futures[i].result())
                if progress:
                    _progress(len(outs), n, self._t0)
        finally:
            self.cancel()
        return self._collect(outs, time.perf_counter() - self._t0, self.workers)

    def cancel(self) -> None:
        """Stop the pool (chunks not yet started are dropped)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)


def _sweep_inputs(design, samples: int, seed: int, K: tuple | None) -> dict:
    """The first ``samples`` runs of the design's sweep with ``seed`` as
    plain data: ``draws``, per-run ``plant`` parameters, the nominal values
    ``base``, the ``controller`` (``asdict`` of the case's settings), the
    ``scenario`` and ``dt``; ``K``: the cruise gain if the caller has it
    (default: :func:`~workbench.studies.antiskid_run.gain_for`)."""
    from ..controllers.antiskid003 import PARAM_ORDER
    from ..studies.antiskid_run import _plant_values, controller_settings, gain_for

    spec = design.spec
    ms: SweepSpec = spec.montecarlo
    case = next(c for c in spec.cases if c.name == ms.case)
    K = gain_for(spec)[0] if K is None else K
    cs = controller_settings(spec, K, case)
    draws = draw_samples(samples, seed, ms)
    base = _plant_values(spec)
    plant = {k: np.full(samples, base[k], float) for k in PARAM_ORDER}
    s = draws["adhesion"]
    for k in ("a", "b", "c"):
        plant[k] = ms.wet[k] + s * (base[k] - ms.wet[k])
    plant["m"] = base["m"] * draws["mass"]
    return {"draws": draws, "plant": plant, "base": base, "controller": asdict(cs),
            "scenario": spec.scenario, "dt": ms.dt or spec.dt}


def _payload(inp: dict, i0: int, i1: int, dt: float) -> dict:
    """The :func:`_chunk_worker` payload of runs ``i0 <= i < i1`` at step ``dt``."""
    sl, sc, d = slice(i0, i1), inp["scenario"], inp["draws"]
    return {"index": i0, "controller": inp["controller"],
            "plant": {k: v[sl].tolist() for k, v in inp["plant"].items()},
            "h": d["h"][sl].tolist(), "v0": d["v0"][sl].tolist(),
            "lambda0": sc["lambda0"], "u_init": sc["u_init"], "t_end": sc["t_end"], "dt": dt}


def _lambda_opt(inp: dict) -> np.ndarray:
    """lambda_opt of each run's own adhesion curve."""
    from ..plants.adhesion import NumericAdhesion
    base, plant = inp["base"], inp["plant"]
    return np.array([NumericAdhesion.from_dict(
        {**base, "a": plant["a"][i], "b": plant["b"][i], "c": plant["c"][i]}).lambda_opt()
        for i in range(len(plant["a"]))])


def _per_run(raw: dict, lam_opt: np.ndarray, t_brake: float) -> tuple[dict, dict]:
    """(metrics, violations) per run, as arrays, from a batch's raw
    :class:`~workbench.controllers.antiskid003.RunMetrics` arrays."""
    from ..controllers.antiskid003 import BRAKE_IN
    # the max over the phase a run diverged in is where the test fired
    in_traction = raw["phase_diverged"] < BRAKE_IN      # NaN (not diverged): False
    metrics = {"lam_max_over_opt": np.where(in_traction, np.nan,
                                            raw["lam_max_traction"] / lam_opt),
               "t_cruise": raw["t_cruise"],
               "omega3_after_brake": raw["t_omega3"] - t_brake,
               "t_diverged": raw["t_diverged"],
               "phase_diverged": raw["phase_diverged"]}
    viol = {"above_lambda_opt": raw["lam_max_traction"] > lam_opt * 1.001,
            "diverged": np.isfinite(raw["t_diverged"]),
            "not_stopped": ~np.isfinite(raw["t_stop"])}
    return metrics, viol


def start_sweep(design, samples: int, seed: int, *, workers: int | None = None,
                chunk: int | None = None, pool: bool | None = None,
                K: tuple | None = None) -> PendingSweep:
    """Draw the samples of an ``antiskid-run`` design's sweep and start its
    chunks (see :func:`sweep`); ``pool`` (default: ``workers > 1``) runs them
    in a process pool now, so the caller can work meanwhile, else in-process
    in :meth:`PendingSweep.result`. ``K``: the cruise gain if the caller has
    it (default: :func:`~workbench.studies.antiskid_run.gain_for`)."""
    import os

    inp = _sweep_inputs(design, samples, seed, K)
    workers = max(1, workers or os.cpu_count() or 1)
    chunk = chunk or max(1, math.ceil(samples / DEFAULT_CHUNKS))
    payloads = [_payload(inp, i0, min(i0 + chunk, samples), inp["dt"])
                for i0 in range(0, samples, chunk)]

    def collect(outs: list, seconds: float, n_workers: int) -> SweepResult:
        raw = {k: np.concatenate([o["metrics"][k] for o in outs]) for k in outs[0]["metrics"]}
        metrics, viol = _per_run(raw, _lambda_opt(inp), inp["scenario"]["t_brake"])
        return SweepResult({k: v.tolist() for k, v in inp["draws"].items()},
                           {k: v.tolist() for k, v in metrics.items()},
                           {k: v.tolist() for k, v in viol.items()}, seconds, n_workers)

    return PendingSweep(payloads, collect, workers, workers > 1 if pool is None else pool)


def sweep(design, samples: int, seed: int, *, workers: int | None = None,
          chunk: int | None = None, progress: bool = True) -> SweepResult:
    """Run the Monte Carlo sweep of an ``antiskid-run`` design.

    Parameters
    ----------
    design : workbench.design.Design
        Of kind ``antiskid-run`` with a ``[montecarlo]`` table.
    samples, seed : int
    workers : int, optional
        Process count (default: CPU count); 1 runs in-process.
    chunk : int, optional
        Samples per batch (default: samples / DEFAULT_CHUNKS, at least 1).
        The results depend on it, not on ``workers``.
    progress : bool
        Progress bar on stderr.
    """
    return start_sweep(design, samples, seed, workers=workers, chunk=chunk).result(progress)


# ---- step-halving check of the sweep's runs ------------------------------------------

#: Metrics compared at dt and dt / 2 by :func:`start_halving`.
HALVING_METRICS = SUMMARY_METRICS + ("t_diverged",)

#: Outcomes compared (as booleans) at dt and dt / 2.
HALVING_OUTCOMES = ("diverged", "stopped", "above_lambda_opt")


@dataclass(frozen=True)
class HalvingCheck:
    """The first ``n`` runs of a design's sweep at dt and at dt / 2.

    Attributes
    ----------
    case : str
        The sweep's case.
    seed : int
    dt : float
        The sweep's step (s): the n runs at dt (the sweep's own, or one
        batch) and at dt / 2 (one batch).
    rtol : float
    atol : dict
        Metric -> absolute tolerance (0 where the design gives none).
    draws : dict
        Sample name -> tuple of n draws (as :func:`draw_samples`).
    coarse, fine : dict
        Metric or outcome -> tuple of n values at dt and at dt / 2
        (``lam_max_over_opt`` NaN for a run that diverged in traction at
        either step: see :func:`compare_steps`).
    agree : dict
        Metric or outcome -> tuple of n bools.
    seconds : float
        Wall time (not compared).
    workers : int
        Processes (not compared).
    """

    case: str
    seed: int
    dt: float
    rtol: float
    atol: dict
    draws: dict
    coarse: dict
    fine: dict
    agree: dict
    seconds: float = field(default=math.nan, compare=False)
    workers: int = field(default=1, compare=False)

    @property
    def n(self) -> int:
        return len(self.draws["h"])

    @property
    def run_agree(self) -> tuple:
        """Per run: every metric and outcome agrees."""
        return tuple(all(self.agree[k][i] for k in self.agree) for i in range(self.n))


def compare_steps(coarse: dict, fine: dict, rtol: float, atol: dict) -> tuple[dict, dict, dict]:
    """Compare per-run values at dt (``coarse``) and dt / 2 (``fine``).

    Parameters
    ----------
    coarse, fine : dict
        :data:`HALVING_METRICS` -> floats per run, :data:`HALVING_OUTCOMES`
        -> bools per run, and ``phase_diverged`` (phase index where the run
        diverged, NaN if it did not).
    rtol : float
    atol : dict
        Metric -> absolute tolerance (missing: 0).

    Returns
    -------
    (coarse, fine, agree) : dict, dict, dict
        Values (tuples per run) and agree flags. A metric agrees by
        :func:`workbench.studies.antiskid_run._agree` (both NaN agree, one
        NaN disagrees); an outcome when it is equal. ``lam_max_over_opt``
        is set NaN at both steps (not compared) for a run that diverged in
        a traction phase (``phase_diverged`` < BRAKE_IN) at either step:
        its maximum there is where the divergence test fired, as for the
        nominal cases (:func:`~workbench.studies.antiskid_run.case_metrics`).
    """
    from ..controllers.antiskid003 import BRAKE_IN
    from ..studies.antiskid_run import _agree

    traction = (np.asarray(coarse["phase_diverged"], float) < BRAKE_IN) | (
        np.asarray(fine["phase_diverged"], float) < BRAKE_IN)
    out = []
    for vals in (coarse, fine):
        d = {k: tuple(float(x) for x in vals[k]) for k in HALVING_METRICS}
        d["lam_max_over_opt"] = tuple(math.nan if t else x
                                      for x, t in zip(d["lam_max_over_opt"], traction))
        d.update({k: tuple(bool(x) for x in vals[k]) for k in HALVING_OUTCOMES})
        out.append(d)
    c, f = out
    agree = {k: tuple(_agree(a, b, rtol, atol.get(k, 0.0)) for a, b in zip(c[k], f[k]))
             for k in HALVING_METRICS}
    agree.update({k: tuple(a == b for a, b in zip(c[k], f[k])) for k in HALVING_OUTCOMES})
    return c, f, agree


def _step_values(metrics: dict, viol: dict) -> dict:
    """Per-run metrics and outcomes of one step, as :func:`compare_steps` takes them."""
    return {**{k: np.asarray(metrics[k], float) for k in HALVING_METRICS + ("phase_diverged",)},
            "diverged": np.asarray(viol["diverged"], bool),
            "stopped": ~np.asarray(viol["not_stopped"], bool),
            "above_lambda_opt": np.asarray(viol["above_lambda_opt"], bool)}


def start_halving(design, n: int, *, K: tuple | None = None, pool: bool = True,
                  coarse: bool = True) -> PendingSweep:
    """Start the step-halving check of the first ``n`` runs of an
    ``antiskid-run`` design's sweep (its ``[montecarlo]`` seed and draws).

    The n runs are simulated as one batch at the sweep's dt and as one
    batch at dt / 2. ``pool``: the batches run in a process pool now, so
    the caller can work meanwhile, else in-process in
    :meth:`PendingSweep.result`, which returns the :class:`HalvingCheck`.
    ``coarse=False``: only the dt / 2 batch runs and ``result()`` returns a
    function of the sweep's :class:`SweepResult` (whose first n runs are the
    dt side: each run of a batch follows its single-run trajectory, whatever
    its chunk) that makes the :class:`HalvingCheck`. ``K``: as
    :func:`start_sweep`.
    """
    spec = design.spec
    ms: SweepSpec = spec.montecarlo
    if not n >= 1:
        raise ValueError(f"halving check of {n} runs: need at least 1")
    inp = _sweep_inputs(design, n, ms.seed, K)
    payloads = ([_payload(inp, 0, n, inp["dt"])] if coarse else []) + [
        _payload(inp, 0, n, inp["dt"] / 2)]
    atol = {k: spec.conv_atol.get(k, 0.0) for k in HALVING_METRICS}

    def check(steps: list, seconds: float, n_workers: int) -> HalvingCheck:
        c, f, agree = compare_steps(*steps, spec.conv_rtol, atol)
        return HalvingCheck(ms.case, ms.seed, inp["dt"], spec.conv_rtol, atol,
                            {k: tuple(v.tolist()) for k, v in inp["draws"].items()},
                            c, f, agree, seconds, n_workers)

    def collect(outs: list, seconds: float, n_workers: int):
        lam_opt = _lambda_opt(inp)
        steps = []
        for o in outs:
            raw = {k: np.asarray(v, float) for k, v in o["metrics"].items()}
            steps.append(_step_values(*_per_run(raw, lam_opt, inp["scenario"]["t_brake"])))
        if coarse:
            return check(steps, seconds, n_workers)

        def with_sweep(res: SweepResult) -> HalvingCheck:
            if res.n < n:
                raise ValueError(f"the sweep has {res.n} runs; the check needs its first {n}")
            first = _step_values({k: v[:n] for k, v in res.metrics.items()},
                                 {k: v[:n] for k, v in res.violations.items()})
            return check([first, steps[0]], seconds, n_workers)
        return with_sweep

    return PendingSweep(payloads, collect, len(payloads) if pool else 1, pool)


def halving_quantity_names() -> set[str]:
    """Quantities of :func:`halving_quantities`."""
    return {"montecarlo.halving.runs", "montecarlo.halving.agree",
            "montecarlo.halving.fraction_agree"}


def halving_quantities(hc: HalvingCheck) -> dict:
    """Runs checked, runs whose every metric and outcome agrees, and their
    fraction."""
    k = sum(hc.run_agree)
    return {"montecarlo.halving.runs": hc.n, "montecarlo.halving.agree": k,
            "montecarlo.halving.fraction_agree": k / hc.n}


#: Column labels of the draws in :func:`halving_section`.
_DRAW_LABELS = (("mass", "mass factor"), ("adhesion", "adhesion s"), ("h", "h (s)"),
                ("v0", "v(0) (m/s)"))


def halving_section(hc: HalvingCheck, spec=None, sig: int = 3) -> str:
    """Markdown (no heading) of a :class:`HalvingCheck`: what was done, a
    row per metric (runs finite at both steps, runs that agree, largest
    |difference| over the runs finite at both), a row per outcome, and the
    disagreeing runs (``sig`` significant digits for their values).
    ``spec``: the design's ``RunSpec``, for the size of the sweep (optional;
    the tolerances are the check's own)."""
    from ..report.markdown import fmt, md_table
    n, k = hc.n, sum(hc.run_agree)
    of = "the sweep's runs" if spec is None or spec.montecarlo is None else \
        f"the sweep's {spec.montecarlo.samples} runs"
    tol = ", ".join(f"`{m}` {fmt(a)}" for m, a in hc.atol.items() if a > 0) or "none"
    text = (f"The first {n} of {of} (seed {hc.seed}, case `{hc.case}`, the same draws), "
            f"run at the sweep's dt = {fmt(hc.dt)} s, were simulated again as one batch at "
            f"dt / 2 (each run of a batch follows its single-run trajectory, so a run's "
            f"values do not depend on its chunk). A metric agrees when "
            f"|a − b| <= atol + rtol max(|a|, |b|), rtol = {fmt(hc.rtol)}, atol: {tol} "
            f"(else 0); two missing values agree, a missing and a finite one do not; "
            f"`lam_max_over_opt` is not compared for a run that diverged in traction at "
            f"either step. An outcome agrees when it is the same at both steps. "
            f"**{k} of {n} runs agree in every metric and outcome.**\n\n")
    rows = []
    for m in HALVING_METRICS:
        a, b = np.asarray(hc.coarse[m], float), np.asarray(hc.fine[m], float)
        both = np.isfinite(a) & np.isfinite(b)
        diff = float(np.max(np.abs(a[both] - b[both]))) if both.any() else None
        rows.append([f"`{m}`", fmt(hc.atol[m]), int(both.sum()), sum(hc.agree[m]),
                     fmt(diff, 2)])
    text += md_table(["metric", "atol", "finite at both", f"agree (of {n})",
                      "largest |difference|"], rows, "lrrrr")
    text += "\n\n" + md_table(
        ["outcome", "runs at dt", "runs at dt / 2", f"agree (of {n})"],
        [[f"`{o}`", sum(hc.coarse[o]), sum(hc.fine[o]), sum(hc.agree[o])]
         for o in HALVING_OUTCOMES], "lrrr")
    bad = [[i] + [fmt(hc.draws[d][i], 4) for d, _ in _DRAW_LABELS]
           + [f"`{key}`", fmt(hc.coarse[key][i], sig), fmt(hc.fine[key][i], sig)]
           for i in range(n) for key in hc.agree if not hc.agree[key][i]]
    text += "\n\nRuns that disagree:"
    if not bad:
        return text + " none."
    return text + "\n\n" + md_table(["run"] + [lab for _, lab in _DRAW_LABELS]
                                    + ["metric or outcome", "at dt", "at dt / 2"],
                                    bad, "rrrrrlrr")


def draw_histograms(fig, res: SweepResult) -> None:
    """Histograms of the summary metrics (pure)."""
    axes = fig.subplots(1, len(SUMMARY_METRICS))
    for ax, k in zip(axes, SUMMARY_METRICS):
        x = np.asarray(res.metrics[k], float)
        x = x[np.isfinite(x)]
        if x.size:
            ax.hist(x, bins=int(np.clip(2 * np.sqrt(x.size), 5, 30)), color="tab:blue")
        if k == "lam_max_over_opt":
            ax.axvline(1.0, color="k", ls="--", lw=0.8, label="lambda_opt")
            ax.legend(fontsize=7)
        ax.set_title(f"{k} (n = {x.size})", fontsize=8)
        ax.set_xlabel(k + {"lam_max_over_opt": " (-)"}.get(k, " (s)"))


def draw_outcomes(fig, res: SweepResult) -> None:
    """Each run at its (adhesion s, true delay h) and (mass factor, v0),
    marked by its outcome: stopped, diverged, or neither (pure)."""
    d = {k: np.asarray(v, float) for k, v in res.samples.items()}
    div = np.asarray(res.violations["diverged"], bool)
    stuck = np.asarray(res.violations["not_stopped"], bool) & ~div
    groups = (("stopped", ~div & ~stuck, "tab:blue", "o"),
              ("diverged", div, "tab:red", "x"),
              ("not stopped, not diverged", stuck, "tab:gray", "s"))
    for ax, (kx, ky, lx, ly) in zip(fig.subplots(1, 2), (
            ("adhesion", "h", "adhesion s (0 wet, 1 dry)", "true input delay h (s)"),
            ("mass", "v0", "plant mass / nominal", "v(0) (m/s)"))):
        for label, sel, color, marker in groups:
            if sel.any():
                ax.scatter(d[kx][sel], d[ky][sel], s=14, c=color, marker=marker,
                           label=f"{label}: {int(sel.sum())}")
        ax.set_xlabel(lx)
        ax.set_ylabel(ly)
    fig.axes[0].legend(fontsize=7)


def sweep_command(path: str, *, samples: int, seed: int, workers: int | None,
                  figure: str | None, as_json: bool) -> int:
    """``workbench sweep``: run, print summary statistics (and JSON), write
    the histogram figure; exit 0 (violations are reported, not failures)."""
    import json
    from pathlib import Path

    from ..design import load_design
    from ..errors import DesignError
    from ..report.markdown import Figure
    if not samples >= 1:
        raise DesignError("<cli>", "--samples", samples, "a positive integer")
    if workers is not None and not workers >= 1:
        raise DesignError("<cli>", "--workers", workers, "a positive integer")
    design = load_design(path)
    if design.kind != "antiskid-run" or design.spec.montecarlo is None:
        raise DesignError(design.path, "montecarlo", "<missing>",
                          "an antiskid-run design with a [montecarlo] table")
    res = sweep(design, samples, seed, workers=workers)
    if figure:
        from ..report.figures import save_figure
        save_figure(Figure(Path(figure).stem, "Monte Carlo histograms",
                           lambda fig: draw_histograms(fig, res), (9.0, 3.2)), Path(figure))
    if as_json:
        print(json.dumps({"design": design.name, "samples": samples, "seed": seed,
                          "seconds": res.seconds, "workers": res.workers,
                          "draws": res.samples, "metrics": res.metrics,
                          "violations": res.violations}, default=lambda x: None))
        return 0
    print(f"{design.name}: {samples} runs, seed {seed}, {res.workers} worker(s), "
          f"{res.seconds:.1f} s")
    print(summary_tables(res, 4))
    if figure:
        print(f"wrote {figure}")
    return 0


def summary_tables(res: SweepResult, sig: int) -> str:
    """Markdown: the summary statistics and the violation fractions (``sig``
    significant digits), as printed by ``workbench sweep`` and in reports."""
    from ..report.markdown import fmt, md_table
    stats = md_table(["metric", "n finite", "min", "median", "95 %", "max"],
                     [[f"`{r[0]}`", r[1]] + [fmt(x, sig) for x in r[2:]]
                      for r in res.summary_rows()], "lrrrrr")
    viol = md_table(["violation", "runs", "fraction"],
                    [[VIOLATIONS[k], sum(v), fmt(sum(v) / res.n, 3)]
                     for k, v in res.violations.items()], "lrr")
    return stats + "\n\n" + viol
