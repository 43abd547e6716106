"""Streaming Monte Carlo sweep of an ``antiskid-run`` design: one ``.npz`` file
per chunk, written as chunks finish; summaries read back from the files.

A chunk is a pure function of (design, gain, seed, sample range): its
worker draws its own samples (:func:`~workbench.sim.batch.uniform_draws`
from ``start``), so a payload is a few kilobytes whatever the sweep's size,
and neither the payloads nor the results of the whole sweep are held in
memory. ``resume`` skips the chunks whose file is already written, so an
interrupted 10^6-run sweep goes on where it stopped; a folder holding
another sweep (other design data, seed, size, chunking or step path) is
refused.

Why ``.npz`` per chunk and not one Parquet file: each chunk is one atomic
file, numpy reads it without a new dependency (pyarrow is a ~40 MB wheel); a
chunk of 250 runs is ~50 kB. The streaming driver (the chunk files, the
folder and its manifest, resuming, reading back, the executors) is the
general :func:`workbench.features.montecarlo_chunks.start_streaming`; this
module keeps what is paper 003's: what a chunk file holds, what identifies
its sweep, and how the sweep's metrics and outcomes are made from the files.

File ``chunk-<i0>-<i1>.npz`` (runs i0 <= i < i1): ``index``, ``draw.<name>``
(the samples), ``raw.<field>`` (the :class:`RunMetrics` of each run) and
``lambda_opt`` (of each run's adhesion curve). ``sweep.json``: what the
folder holds (design, size, seed, chunking, step path, t_brake and a hash of
the data every run shares).
"""
from __future__ import annotations

import hashlib
import json
import math

import numpy as np

from ...features.montecarlo_chunks import default_chunk, read_streamed
from ...features.montecarlo_chunks import start_streaming as stream
from ...sim.batch import PendingBatch, available_cpus
from .antiskid_montecarlo import (SweepResult, chunk_payload, chunk_worker, lambda_opt_of,
                                  per_run, sweep_inputs)

#: Raw metrics :func:`load_sweep` reads (what :func:`per_run` needs).
READ = ("lam_max_traction", "t_cruise", "t_omega3", "t_diverged", "phase_diverged", "t_stop")


def range_worker(payload: dict) -> dict:
    """Simulate runs ``i0 <= i < i1`` of a design's sweep (payload: design,
    K, seed, i0, i1, kernel) and return the arrays of its chunk file."""
    d, i0, i1 = payload["design"], payload["i0"], payload["i1"]
    inp = sweep_inputs(d, i1, payload["seed"], payload["K"], start=i0)
    out = chunk_worker(chunk_payload(inp, 0, i1 - i0, inp["dt"], payload["kernel"]))
    arrays = {"index": np.arange(i0, i1), "lambda_opt": lambda_opt_of(inp["plant"])}
    arrays.update({f"draw.{k}": np.asarray(v) for k, v in inp["draws"].items()})
    arrays.update({f"raw.{k}": np.asarray(v, float) for k, v in out["metrics"].items()})
    return arrays


def _manifest(design, samples: int, seed: int, chunk: int, kernel: str, K) -> dict:
    ms = design.spec.montecarlo
    inp = sweep_inputs(design, 1, seed, K)      # the data every run shares
    shared = {k: inp[k] for k in ("base", "controller", "scenario", "dt")}
    shared["ranges"] = [ms.mass, ms.adhesion, ms.h, ms.v0, sorted(ms.wet.items())]
    if ms.perturb is not None:      # absent: the digest of a sweep without perturbations
        shared["perturb"] = ms.perturb
    digest = hashlib.sha256(json.dumps(shared, sort_keys=True, default=repr).encode())
    return {"design": design.name, "samples": samples, "seed": seed, "chunk": chunk,
            "kernel": kernel, "t_brake": inp["scenario"]["t_brake"],
            "inputs_sha256": digest.hexdigest()}


def start_streaming(design, samples: int, seed: int, out, *, resume: bool = False,
                    workers: int | None = None, chunk: int | None = None,
                    kernel: str | None = None, scheduler: str | None = None,
                    K: tuple | None = None) -> PendingBatch:
    """Start a sweep whose chunks are written to the folder ``out`` as they
    finish (module docstring); :meth:`PendingBatch.result` returns the
    :class:`SweepResult` read back from the files.

    Raises
    ------
    FileExistsError
        ``out`` holds chunk files or another sweep and ``resume`` is false,
        or it holds another sweep (its ``sweep.json`` differs).
    """
    from .antiskid_kernel import compile_kernel, default_kernel
    from .antiskid_run_spec import gain_for
    workers = max(1, workers or available_cpus())
    chunk = chunk or default_chunk(samples)
    kernel = kernel or default_kernel()
    K = tuple(gain_for(design.spec)[0] if K is None else K)

    def collect(seconds: float, n_workers: int) -> SweepResult:
        res = load_sweep(out)
        return SweepResult(res.samples, res.metrics, res.violations, seconds, n_workers)

    return stream(out, _manifest(design, samples, seed, chunk, kernel, K),
                  lambda i0, i1: {"design": design, "K": K, "seed": seed, "i0": i0, "i1": i1,
                                  "kernel": kernel},
                  range_worker, collect, resume=resume, workers=workers, scheduler=scheduler,
                  before_pool=compile_kernel if kernel == "compiled" else None)


def load_sweep(out) -> SweepResult:
    """The :class:`SweepResult` of a streamed sweep, from its chunk files
    (only the columns the summaries use are read)."""
    keep = {"lambda_opt", *(f"raw.{k}" for k in READ)}
    man, col = read_streamed(out, lambda k: k in keep or k.startswith("draw."))
    raw = {k: col[f"raw.{k}"] for k in READ}
    metrics, viol = per_run(raw, col["lambda_opt"], float(man["t_brake"]))
    draws = {k[5:]: v.tolist() for k, v in col.items() if k.startswith("draw.")}
    return SweepResult(draws, {k: v.tolist() for k, v in metrics.items()},
                       {k: v.tolist() for k, v in viol.items()}, math.nan, 0)
