"""A Monte Carlo sweep whose chunks return named arrays (issue 35: one Monte
Carlo driver): held in memory, or streamed to a folder and resumable.

Nothing here knows what a run is. A study gives a module-level run
function ``run(payload) -> dict of arrays`` (one chunk of runs, typically a
batch simulated by its kernel), the payload of runs ``i0 <= i < i1`` and
``result_of(columns, seconds, workers)``, its result from the chunks'
arrays concatenated in run order. :func:`start_array_sweep` cuts the runs
into chunks (:func:`~workbench.features.montecarlo_chunks.chunk_ranges`;
the partition depends on the run count and the chunk size only, never on
the worker count) and runs them in-process, in a local process pool or on
Dask (:class:`~workbench.sim.batch.PendingBatch`; progress on stderr).

With ``out`` each chunk is written as it finishes to its own ``.npz`` file
(:func:`~workbench.features.montecarlo_chunks.start_streaming`), ``resume``
skipping the files already written and a folder of another sweep (its
``sweep.json`` manifest differs) refused; the result is then read back
from the files. Why ``.npz`` per chunk and not one Parquet file: each chunk
is one atomic file that numpy reads without a new dependency (~50 kB for
250 runs). Either way the result is made from the same arrays, so a
streamed sweep equals the in-memory one bit for bit.

The chunk file convention of :func:`chunk_arrays`: ``index`` (the runs),
``draw.<name>`` (the samples, :func:`draws_of` reads them back) and
``raw.<field>`` (what the run function computed), plus the study's own
columns; :class:`ArrayRuns` makes the runs' metrics, outcome flags and
result from them (in memory or read back from the files).
"""
from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .montecarlo_chunks import default_chunk, read_streamed, start_batches, start_streaming

__all__ = ["ArrayRuns", "chunk_arrays", "concat_chunks", "draws_of", "inputs_digest",
           "start_array_sweep"]


def chunk_arrays(i0: int, i1: int, draws: dict, raw: dict, **extra) -> dict:
    """The arrays of the chunk of runs ``i0 <= i < i1`` (module docstring):
    ``index``, ``draw.<name>`` of ``draws``, ``raw.<field>`` of ``raw``
    (floats) and ``extra`` as given."""
    arrays = {"index": np.arange(i0, i1), **extra}
    arrays.update({f"draw.{k}": np.asarray(v) for k, v in draws.items()})
    arrays.update({f"raw.{k}": np.asarray(v, float) for k, v in raw.items()})
    return arrays


def draws_of(columns: dict) -> dict:
    """Sample name -> list of the runs' draws, from the ``draw.<name>``
    columns of a sweep (:func:`chunk_arrays`)."""
    return {k[5:]: v.tolist() for k, v in columns.items() if k.startswith("draw.")}


@dataclass(frozen=True)
class ArrayRuns:
    """How a study's runs are made from its sweep's columns (:func:`chunk_arrays`).

    Attributes
    ----------
    per_run : callable
        ``per_run(raw, *own, *context) -> (metrics, violations)``: per-run
        arrays from ``raw`` (field -> the ``raw.<field>`` column of each
        field of ``read``), the study's ``own`` columns and ``context`` (what
        every run shares, e.g. a scenario time).
    read : tuple of str
        The raw fields the runs are made from.
    own : tuple of str
        The study's own columns they are made from.
    result : type
        The result (a :class:`~workbench.features.montecarlo_stats.RunsResult`
        subclass).
    """

    per_run: Callable
    read: tuple
    own: tuple
    result: type

    def select(self, name: str) -> bool:
        """The columns the runs are made from (all a streamed sweep reads back)."""
        return name in self.own or name.startswith("draw.") or name in {f"raw.{k}"
                                                                        for k in self.read}

    def runs(self, columns: dict, *context) -> tuple[dict, dict]:
        """(metrics, violations) per run of ``columns``."""
        return self.per_run({k: columns[f"raw.{k}"] for k in self.read},
                            *(columns[k] for k in self.own), *context)

    def result_of(self, columns: dict, seconds: float, workers: int, *context):
        """The sweep's :attr:`result` (draws, metrics and flags as lists)."""
        metrics, viol = self.runs(columns, *context)
        return self.result(draws_of(columns), {k: v.tolist() for k, v in metrics.items()},
                           {k: v.tolist() for k, v in viol.items()}, seconds, workers)

    def start(self, run: Callable, payload: Callable, samples: int, context: tuple = (), **kw):
        """:func:`start_array_sweep` of ``run`` (``payload``, ``samples`` and
        the keywords ``kw`` as there) whose result is :meth:`result_of` with
        ``context``; a streamed sweep reads back the :meth:`select` columns."""
        return start_array_sweep(run, payload, samples, lambda columns, seconds, workers:
                                 self.result_of(columns, seconds, workers, *context),
                                 select=self.select, **kw)

    def load(self, out, context: Callable):
        """The result of a streamed sweep read back from its folder ``out``
        (only the :meth:`select` columns); ``context(manifest)``: the
        ``context`` of :attr:`per_run` from the folder's ``sweep.json``."""
        man, columns = read_streamed(out, self.select)
        return self.result_of(columns, math.nan, 0, *context(man))


def concat_chunks(outputs: list) -> dict:
    """The chunks' arrays (dicts with the same names) concatenated in run order."""
    return {k: np.concatenate([o[k] for o in outputs]) for k in outputs[0]}


def inputs_digest(shared: dict) -> str:
    """SHA-256 (hex) of the data every run of a sweep shares (JSON with
    sorted keys, ``repr`` of what JSON cannot hold): the part of a
    manifest that tells one sweep's inputs from another's."""
    return hashlib.sha256(json.dumps(shared, sort_keys=True, default=repr).encode()).hexdigest()


def start_array_sweep(run: Callable, payload: Callable, samples: int, result_of: Callable, *,
                      chunk: int | None = None, workers: int | None = None,
                      pool: bool | None = None, scheduler: str | None = None,
                      before_pool: Callable | None = None, out=None,
                      manifest: Callable | None = None, resume: bool = False,
                      select: Callable = lambda name: True):
    """Start a sweep of ``samples`` runs (module docstring).

    Parameters
    ----------
    run : callable
        ``run(payload) -> dict`` of arrays of one chunk's runs
        (module-level when it runs in a pool or on Dask).
    payload : callable
        ``payload(i0, i1)``: the payload of runs ``i0 <= i < i1``.
    samples : int
    result_of : callable
        ``result_of(columns, seconds, workers)``: the sweep's result from
        its columns (:func:`concat_chunks` of the chunks' arrays).
    chunk : int, optional
        Runs per chunk (default:
        :func:`~workbench.features.montecarlo_chunks.default_chunk`). The
        results depend on it, not on ``workers``.
    workers : int, optional
        Process count (default: the CPUs granted,
        :func:`~workbench.sim.batch.available_cpus`); 1 runs in-process.
    pool : bool, optional
        Run the chunks in a process pool now, so the caller can work
        meanwhile (default: ``workers > 1``), else in-process in
        :meth:`~workbench.sim.batch.PendingBatch.result`.
    scheduler : str, optional
        Run the chunks on a Dask distributed cluster: ``"local"`` (a
        LocalCluster of ``workers`` processes) or a scheduler address.
    before_pool : callable, optional
        Called once before more than one chunk runs in a local pool (e.g. to
        compile a kernel the forked workers inherit).
    out : path, optional
        Write each chunk to this folder as it finishes (a pool when
        ``workers > 1``); the result is read back from the files.
    manifest : callable, optional
        With ``out``: ``manifest(chunk) -> dict``, what identifies the sweep
        (its folder's ``sweep.json``; it holds ``samples`` and ``chunk``).
    resume : bool
        With ``out``: skip the chunk files already written.
    select : callable
        With ``out``: ``select(name)``, the columns read back from the files.

    Returns
    -------
    workbench.sim.batch.PendingBatch

    Raises
    ------
    FileExistsError
        ``out`` holds chunk files and ``resume`` is false, or it holds
        another sweep (its ``sweep.json`` differs).
    """
    from ..sim.batch import available_cpus
    workers = max(1, workers or available_cpus())
    chunk = chunk or default_chunk(samples)
    if out is not None:
        return start_streaming(out, manifest(chunk), payload, run,
                               lambda seconds, n_workers: result_of(
                                   read_streamed(out, select)[1], seconds, n_workers),
                               resume=resume, workers=workers, scheduler=scheduler,
                               before_pool=before_pool)
    return start_batches(run, payload, samples, chunk,
                         lambda outs, seconds, n_workers: result_of(concat_chunks(outs), seconds,
                                                                    n_workers),
                         workers=workers, pool=workers > 1 if pool is None else pool,
                         scheduler=scheduler, before_pool=before_pool)
