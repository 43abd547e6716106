"""Monte Carlo robustness sweep of an ``antiskid-run`` design.

Samples (seeded, numpy ``SeedSequence``): plant mass factor, adhesion
between the wet and the dry curve (a, b, c interpolated with s in [0, 1]:
s = 0 wet, s = 1 dry), true input delay in [0, h_max] (the predictor keeps
the design's h), initial speed. Each worker simulates one chunk of samples
as a batch (arrays, one pass of the fixed-step loop) and returns plain lists;
a local process pool runs the chunks; progress goes to stderr.

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


@dataclass(frozen=True)
class SweepSpec:
    """Ranges of the sweep (from the design's ``[montecarlo]`` table)."""

    mass: tuple[float, float]
    wet: dict               # a, b, c of the wet curve
    adhesion: tuple[float, float]
    h: tuple[float, float]
    v0: tuple[float, float]
    case: str


@dataclass(frozen=True)
class SweepResult:
    samples: dict           # name -> list of floats
    metrics: dict           # name -> list of floats
    violations: dict        # claim-like check -> list of bool
    seconds: float
    workers: int

    def summary_rows(self) -> list[list]:
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


def draw_samples(n: int, seed: int, spec: SweepSpec) -> dict:
    """n samples of (mass factor, adhesion s, delay h, v0), uniform, seeded."""
    rng = np.random.default_rng(np.random.SeedSequence(seed))
    u = lambda lo_hi: rng.uniform(lo_hi[0], lo_hi[1], n)
    return {"mass": u(spec.mass), "adhesion": u(spec.adhesion), "h": u(spec.h), "v0": u(spec.v0)}


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
        Samples per batch (default: samples / (2 workers), at least 1).
    progress : bool
        Progress bar on stderr.
    """
    import os

    from ..controllers.antiskid003 import PARAM_ORDER
    from ..plants.adhesion import NumericAdhesion
    from ..studies.antiskid_run import _plant_values, controller_settings, gain_for

    spec = design.spec
    ms: SweepSpec = spec.montecarlo
    case = next(c for c in spec.cases if c.name == ms.case)
    K = gain_for(spec)[0]
    cs = controller_settings(spec, K, case)
    draws = draw_samples(samples, seed, ms)
    base = _plant_values(spec)
    plant = {k: np.full(samples, base[k], float) for k in PARAM_ORDER}
    s = draws["adhesion"]
    for k in ("a", "b", "c"):
        plant[k] = ms.wet[k] + s * (base[k] - ms.wet[k])
    plant["m"] = base["m"] * draws["mass"]
    workers = max(1, workers or os.cpu_count() or 1)
    chunk = chunk or max(1, math.ceil(samples / (2 * workers)))
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
    t0 = time.perf_counter()
    outs = []
    if progress:
        _progress(0, len(payloads), t0)
    if workers == 1:
        for p in payloads:
            outs.append(_chunk_worker(p))
            if progress:
                _progress(len(outs), len(payloads), t0)
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            for out in pool.map(_chunk_worker, payloads):
                outs.append(out)
                if progress:
                    _progress(len(outs), len(payloads), t0)
    seconds = time.perf_counter() - t0
    outs.sort(key=lambda o: o["index"])
    raw = {k: np.concatenate([o["metrics"][k] for o in outs]) for k in outs[0]["metrics"]}
    lam_opt = np.array([NumericAdhesion.from_dict(
        {**base, "a": plant["a"][i], "b": plant["b"][i], "c": plant["c"][i]}).lambda_opt()
        for i in range(samples)])
    t_b = sc["t_brake"]
    metrics = {"lam_max_over_opt": (raw["lam_max_traction"] / lam_opt).tolist(),
               "t_cruise": raw["t_cruise"].tolist(),
               "braking_duration": (raw["t_stop"] - t_b).tolist(),
               "t_diverged": raw["t_diverged"].tolist()}
    viol = {"creep ratio above the sample's lambda_opt in traction":
            (raw["lam_max_traction"] > lam_opt * 1.001).tolist(),
            "diverged (|lambda| >= 0.9)": np.isfinite(raw["t_diverged"]).tolist(),
            "not stopped by t_end": (~np.isfinite(raw["t_stop"])).tolist()}
    return SweepResult({k: v.tolist() for k, v in draws.items()}, metrics, viol, seconds, workers)


def draw_histograms(fig, res: SweepResult) -> None:
    """Histograms of the summary metrics (pure)."""
    axes = fig.subplots(1, len(SUMMARY_METRICS))
    for ax, k in zip(axes, SUMMARY_METRICS):
        x = np.asarray(res.metrics[k], float)
        x = x[np.isfinite(x)]
        if x.size:
            ax.hist(x, bins=30, color="tab:blue")
        ax.set_title(f"{k} (n = {x.size})", fontsize=8)
        ax.set_xlabel(k)


def sweep_command(path: str, *, samples: int, seed: int, workers: int | None,
                  figure: str | None, as_json: bool) -> int:
    """``workbench sweep``: run, print summary statistics (and JSON), write
    the histogram figure; exit 0 (violations are reported, not failures)."""
    import json
    from pathlib import Path

    from ..design import load_design
    from ..errors import DesignError
    from ..report.markdown import Figure, fmt, md_table
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
    print(md_table(["metric", "n finite", "min", "median", "95 %", "max"],
                   [[r[0], r[1]] + [fmt(x, 4) for x in r[2:]] for r in res.summary_rows()],
                   "lrrrrr"))
    print()
    print(md_table(["violation", "runs", "fraction"],
                   [[k, sum(v), fmt(sum(v) / samples, 3)] for k, v in res.violations.items()],
                   "lrr"))
    if figure:
        print(f"wrote {figure}")
    return 0
