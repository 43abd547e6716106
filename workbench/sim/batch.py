"""Chunked batch execution: a local process pool, in-process, or a Dask cluster.

A job is a list of plain-data payloads and a module-level worker function
(picklable by reference); each chunk is a pure function of its payload, so
the results do not depend on the pool, its size or the order chunks finish
in, nor the machine they ran on: a chunk lost with a Dask worker is simply
run again elsewhere (the scheduler does it). Nothing here knows what is simulated: the studies provide the worker,
the payloads and what to make of the outputs (``collect``). Progress is a
:func:`workbench.sim.progress.progress` bar (terminal only).
"""
from __future__ import annotations

import os
import signal
import sys
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Callable

import numpy as np

from .progress import progress as progress_bar


class SchedulerUnreachable(ConnectionError):
    """The Dask scheduler could not be reached (raised only while connecting,
    so an error of a chunk or of writing its file is never taken for it)."""


def die_with_parent(parent: int) -> None:
    """Pool worker initializer: the worker is killed when its parent dies
    (Linux ``prctl(PR_SET_PDEATHSIG, SIGKILL)``), so a killed ``sweep`` leaves
    no workers behind; if the parent is already gone, the worker exits.
    The signal fires when the *thread* that started the worker ends, so a
    pool is started by the thread that waits for it (as here: submit in
    :class:`PendingBatch`, the fork start method launching every worker at once)."""
    if sys.platform.startswith("linux"):
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent:
        os._exit(1)


def available_cpus() -> int:
    """CPUs this process may use, the default number of pool workers.

    ``os.cpu_count()`` counts the host's CPUs; in a container or a CI runner
    limited by a cgroup CPU quota or an affinity mask that can be many times
    the CPUs actually granted, and a pool that large only multiplies the
    start-up cost and starves the other processes. joblib's count (loky's)
    takes the affinity mask, the cgroup quota (v1 and v2) and the
    ``LOKY_MAX_CPU_COUNT`` override into account.
    """
    from joblib import cpu_count
    return max(1, int(cpu_count(only_physical_cores=False)))


def uniform_draws(n: int, seed: int, ranges: dict, start: int = 0) -> dict:
    """Seeded uniform samples ``start <= i < n`` of each named range,
    ``{name: (lo, hi)}``.

    Sample i is row i of one (n, len(ranges)) draw of numpy's default
    generator (PCG64) seeded by ``SeedSequence(seed)``, so the first n
    samples of a larger draw with the same seed are the same. Each uniform
    takes one 64-bit output of the generator, so rows from ``start`` on are
    drawn directly after advancing it by ``start * len(ranges)`` outputs: a
    chunk of a sweep draws its own samples, the same as the whole draw's.
    """
    if not 0 <= start <= n:
        raise ValueError(f"start = {start!r}; expected 0 <= start <= n = {n}")
    bits = np.random.PCG64(np.random.SeedSequence(seed))
    bits.advance(start * len(ranges))
    u = np.random.Generator(bits).uniform(size=(n - start, len(ranges)))
    return {k: lo + (hi - lo) * u[:, j] for j, (k, (lo, hi)) in enumerate(ranges.items())}


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
    sizes : list of int, optional
        Units of work in each payload (e.g. runs), for the progress bar's
        count, rate and ETA (default: 1 per payload).
    unit : str
        What ``sizes`` count.
    scheduler : str, optional
        Run the chunks on a Dask distributed cluster instead (``pool`` is
        then ignored): ``"local"`` starts a ``distributed.LocalCluster`` of
        ``workers`` single-threaded worker processes on this machine, any
        other value is the address of a running scheduler
        (``tcp://host:8786``), whose workers must have this package
        installed. Needs the ``scale`` extra (dask, distributed).
    sink : callable, optional
        ``sink(i, output)`` is called as each chunk finishes (e.g. to write
        it to a file); ``collect`` then receives what it returned instead of
        the outputs, so they are not all held in memory.

    Raises
    ------
    SchedulerUnreachable
        The scheduler cannot be reached.
    """

    def __init__(self, worker: Callable, payloads: list, collect, workers: int, pool: bool,
                 sizes: list | None = None, unit: str = "chunk", scheduler: str | None = None,
                 sink: Callable | None = None):
        self._worker = worker
        self._sizes = [1] * len(payloads) if sizes is None else list(sizes)
        self._unit = unit
        self._sink = sink or (lambda i, out: out)
        self._payloads, self._collect, self.workers = payloads, collect, workers
        self._t0 = time.perf_counter()
        self._pool = self.client = self._cluster = None
        self._futures = None
        if scheduler is not None:
            self._start_dask(scheduler)
        elif pool and payloads:
            self._pool = ProcessPoolExecutor(max_workers=min(workers, len(payloads)),
                                             initializer=die_with_parent,
                                             initargs=(os.getpid(),))
            self._futures = [self._pool.submit(worker, p) for p in payloads]

    def _start_dask(self, scheduler: str) -> None:
        from distributed import Client, LocalCluster
        try:
            if scheduler == "local":
                self._cluster = LocalCluster(n_workers=self.workers, threads_per_worker=1,
                                             processes=True, dashboard_address=None)
                self.client = Client(self._cluster)
            else:
                self.client = Client(scheduler, timeout="10s")
        except OSError as exc:
            self.cancel()
            raise SchedulerUnreachable(str(exc)) from exc
        except BaseException:
            self.cancel()
            raise
        self.workers = len(self.client.scheduler_info().get("workers", {})) or self.workers
        # pure=False: a fresh key per chunk; a chunk whose worker dies is re-run by the scheduler
        self._futures = self.client.map(self._worker, self._payloads, pure=False)

    def result(self, progress: bool = False):
        """Wait for every chunk; ``progress``: a bar on stderr (terminal only)."""
        n = len(self._payloads)
        outs = [None] * n
        bar = progress_bar(total=sum(self._sizes), unit=self._unit, enabled=progress)
        try:
            if self.client is not None:
                from distributed import as_completed
                index = {f.key: i for i, f in enumerate(self._futures)}
                for f in as_completed(self._futures):
                    outs[index[f.key]] = self._sink(index[f.key], f.result())
                    bar.update(self._sizes[index[f.key]])
            elif self._pool is None:
                for i, p in enumerate(self._payloads):
                    outs[i] = self._sink(i, self._worker(p))
                    bar.update(self._sizes[i])
            else:
                index = {f: i for i, f in enumerate(self._futures)}
                pending = set(self._futures)
                while pending:
                    done, pending = wait(pending, return_when=FIRST_COMPLETED)
                    for f in done:
                        outs[index[f]] = self._sink(index[f], f.result())
                        bar.update(self._sizes[index[f]])
        finally:
            bar.close()
            self.cancel()
        return self._collect(outs, time.perf_counter() - self._t0, self.workers)

    def cancel(self) -> None:
        """Stop the pool or leave the cluster (chunks not yet started are
        dropped; a LocalCluster started here is closed)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
        if self.client is not None:
            if self._futures is not None:
                self.client.cancel(self._futures)
            self.client.close()
            self.client = None
        if self._cluster is not None:
            self._cluster.close()
            self._cluster = None
