"""Chunked batch execution: a local process pool, or in-process.

A job is a list of plain-data payloads and a module-level worker function
(picklable by reference); each chunk is a pure function of its payload, so
the results do not depend on the pool, its size or the order chunks finish
in. Nothing here knows what is simulated: the studies provide the worker,
the payloads and what to make of the outputs (``collect``).
"""
from __future__ import annotations

import sys
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Callable

import numpy as np


def uniform_draws(n: int, seed: int, ranges: dict) -> dict:
    """n seeded uniform samples of each named range, ``{name: (lo, hi)}``.

    Sample i is row i of one (n, len(ranges)) draw of numpy's default
    generator seeded by ``SeedSequence(seed)``, so the first n samples of a
    larger draw with the same seed are the same.
    """
    u = np.random.default_rng(np.random.SeedSequence(seed)).uniform(size=(n, len(ranges)))
    return {k: lo + (hi - lo) * u[:, j] for j, (k, (lo, hi)) in enumerate(ranges.items())}


def _progress(done: int, total: int, t0: float, stream=sys.stderr) -> None:
    width = 30
    k = int(width * done / total)
    stream.write(f"\r[{'#' * k}{'.' * (width - k)}] {done}/{total} chunks, "
                 f"{time.perf_counter() - t0:.0f} s")
    if done == total:
        stream.write("\n")
    stream.flush()


class PendingBatch:
    """A batch job whose chunks are running (in a process pool, or still to
    run in-process); :meth:`result` waits for them and returns what
    ``collect(outputs, seconds, workers)`` makes of the outputs, in payload
    order.

    Parameters
    ----------
    worker : callable
        Module-level function, payload -> output (plain data).
    payloads : list
    collect : callable
    workers : int
        Pool size (capped at the number of payloads).
    pool : bool
        True: start the pool now (the caller can work meanwhile); False: run
        the chunks in-process in :meth:`result`.
    """

    def __init__(self, worker: Callable, payloads: list, collect, workers: int, pool: bool):
        self._worker = worker
        self._payloads, self._collect, self.workers = payloads, collect, workers
        self._t0 = time.perf_counter()
        self._pool = ProcessPoolExecutor(max_workers=min(workers, len(payloads))) if pool \
            else None
        self._futures = None if self._pool is None else [
            self._pool.submit(worker, p) for p in payloads]

    def result(self, progress: bool = False):
        n, outs = len(self._payloads), []
        if progress:
            _progress(0, n, self._t0)
        try:
            for i, p in enumerate(self._payloads):
                outs.append(self._worker(p) if self._pool is None
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
