"""Monte Carlo robustness sweep of an ``antiskid-run`` design.

Samples (seeded, numpy ``SeedSequence``): plant mass factor, adhesion
between the wet and the dry curve (a, b, c interpolated with s in [0, 1]:
s = 0 wet, s = 1 dry), true input delay in [0, h_max] (the predictor keeps
the design's h), initial speed. Sample i is row i of one (n, 4) uniform draw,
so the first n runs of a larger sweep with the same seed have the same
parameters. Each worker simulates one chunk of samples as a batch (arrays,
one pass of the fixed-step loop) and returns plain lists; a local process
pool runs the chunks; progress goes to stderr.

A batch halves a step for all its runs when one of them needs it
(:func:`workbench.controllers.antiskid003.stiff_step`), so a run's metrics
depend slightly on its chunk mates. The partition into chunks therefore
depends on the sample count (and ``chunk``) only, never on the worker count:
the same seed gives identical results with any number of workers.

The controller always uses the design's nominal model (dry rail, nominal
mass): the sweep measures robustness, not re-tuning.
"""
from __future__ import annotations

import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass

import numpy as np

#: Summary statistics reported per metric.
SUMMARY_METRICS = ("lam_max_over_opt", "t_cruise", "braking_duration")

#: Statistics of each summary metric (over its finite values).
STATISTICS = ("n_finite", "min", "median", "p95", "max")

#: Checks counted per run: key -> what a violation means.
VIOLATIONS = {"above_lambda_opt": "creep ratio above the sample's lambda_opt in traction",
              "diverged": "diverged (|lambda| >= 0.9)",
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
    in-process); :meth:`result` waits for them and returns the
    :class:`SweepResult`."""

    def __init__(self, payloads: list, collect, workers: int, pool: bool):
        self._payloads, self._collect, self.workers = payloads, collect, workers
        self._t0 = time.perf_counter()
        self._pool = ProcessPoolExecutor(max_workers=min(workers, len(payloads))) if pool \
            else None
        self._futures = None if self._pool is None else [
            self._pool.submit(_chunk_worker, p) for p in payloads]

    def result(self, progress: bool = False) -> SweepResult:
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


def start_sweep(design, samples: int, seed: int, *, workers: int | None = None,
                chunk: int | None = None, pool: bool | None = None,
                K: tuple | None = None) -> PendingSweep:
    """Draw the samples of an ``antiskid-run`` design's sweep and start its
    chunks (see :func:`sweep`); ``pool`` (default: ``workers > 1``) runs them
    in a process pool now, so the caller can work meanwhile, else in-process
    in :meth:`PendingSweep.result`. ``K``: the cruise gain if the caller has
    it (default: :func:`~workbench.studies.antiskid_run.gain_for`)."""
    import os

    from ..controllers.antiskid003 import PARAM_ORDER
    from ..plants.adhesion import NumericAdhesion
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
    workers = max(1, workers or os.cpu_count() or 1)
    chunk = chunk or max(1, math.ceil(samples / DEFAULT_CHUNKS))
    sc = spec.scenario
    cdict = asdict(cs)
    payloads = []
    for i0 in range(0, samples, chunk):
        sl = slice(i0, min(i0 + chunk, samples))
        payloads.append({"index": i0, "controller": cdict,
                         "plant": {k: v[sl].tolist() for k, v in plant.items()},
                         "h": draws["h"][sl].tolist(), "v0": draws["v0"][sl].tolist(),
                         "lambda0": sc["lambda0"], "u_init": sc["u_init"],
                         "t_end": sc["t_end"], "dt": spec.dt})

    def collect(outs: list, seconds: float, n_workers: int) -> SweepResult:
        raw = {k: np.concatenate([o["metrics"][k] for o in outs]) for k in outs[0]["metrics"]}
        lam_opt = np.array([NumericAdhesion.from_dict(
            {**base, "a": plant["a"][i], "b": plant["b"][i], "c": plant["c"][i]}).lambda_opt()
            for i in range(samples)])
        metrics = {"lam_max_over_opt": (raw["lam_max_traction"] / lam_opt).tolist(),
                   "t_cruise": raw["t_cruise"].tolist(),
                   "braking_duration": (raw["t_stop"] - sc["t_brake"]).tolist(),
                   "t_diverged": raw["t_diverged"].tolist()}
        viol = {"above_lambda_opt": (raw["lam_max_traction"] > lam_opt * 1.001).tolist(),
                "diverged": np.isfinite(raw["t_diverged"]).tolist(),
                "not_stopped": (~np.isfinite(raw["t_stop"])).tolist()}
        return SweepResult({k: v.tolist() for k, v in draws.items()}, metrics, viol, seconds,
                           n_workers)

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
              ("diverged (|lambda| >= 0.9)", div, "tab:red", "x"),
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
