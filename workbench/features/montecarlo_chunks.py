"""Chunked, resumable Monte Carlo sweeps: the runs cut into chunks, each chunk
computed by a per-chunk run function (in-process, in a local process pool or
on Dask, :class:`workbench.sim.batch.PendingBatch`) and written to its own
file in a folder as it finishes; ``resume`` skips the chunks already there
(issue 35, item 1: Monte Carlo "chunked and resumable").

Nothing here knows what a run is. A study gives the chunks (file, payload,
runs), the run function (payload -> output; module-level when it runs in a
pool or on Dask), how an output is written and what to make of the written
chunks. The folder's ``sweep.json`` records what identifies the sweep (the
manifest); a folder holding files is refused unless ``resume`` is set and its
manifest is this sweep's (:func:`claim_folder`). Every chunk file is written
atomically (a temporary name, then renamed), so a crash never leaves a
half-written chunk and resuming needs no index.

A sweep held in memory is cut the same way (:func:`start_batches`). Two
chunk formats: ``.npz`` arrays (:func:`write_npz`, :func:`read_npz`; the
streaming driver :func:`start_streaming` writes one ``chunk-<i0>-<i1>.npz``
per range of runs and :func:`read_streamed` reads a finished folder back) and
the CSV of :func:`run_chunks`, ``workbench sweep --out DIR [--resume]`` of
every kind whose sweep is a batch of independent runs (``switched-run``,
``stop-accuracy``, ``delay-feedback``): runs cut into chunks of :data:`CHUNK`
in draw order, ``DIR/<group>-chunk-NNNN.csv`` with one row per run (its draws,
its metrics and, when the kind has one, why it ended; ``repr`` floats, so a
file reads back bit for bit); the draws are made once for all samples and
sliced, so a resumed sweep writes the same files as an uninterrupted one.
"""
from __future__ import annotations

import csv
import io
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

__all__ = ["CHUNK", "DEFAULT_CHUNKS", "MANIFEST", "MAX_CHUNK", "Chunk", "ChunkRuns",
           "FolderTaken", "Group", "check_resume", "chunk_file", "chunk_ranges", "claim_folder",
           "default_chunk", "read_npz", "read_streamed", "run_chunks", "run_groups", "start_batches",
           "start_chunks", "start_streaming", "write_npz"]

#: The manifest of a sweep's folder.
MANIFEST = "sweep.json"
#: Default number of chunks a parallel sweep is cut into (independent of the workers)...
DEFAULT_CHUNKS = 4
#: ... unless a chunk would hold more runs than this: a large sweep streams,
#: resumes and reports progress in chunks of at most MAX_CHUNK runs, and a
#: worker's memory does not grow with the sweep.
MAX_CHUNK = 500
#: Runs per chunk file of :func:`run_chunks` (``sweep --out`` of the kinds).
CHUNK = 50


def default_chunk(samples: int) -> int:
    """Runs per chunk when the caller gives none: samples / DEFAULT_CHUNKS,
    at most MAX_CHUNK, at least 1."""
    return max(1, min(math.ceil(samples / DEFAULT_CHUNKS), MAX_CHUNK))


def chunk_ranges(n: int, chunk: int) -> list[tuple[int, int]]:
    """(i0, i1) of each chunk of runs ``0 <= i < n``, ``chunk`` runs each
    (the last may hold fewer); the partition depends on n and chunk only."""
    return [(i0, min(i0 + chunk, n)) for i0 in range(0, n, chunk)]


def start_batches(run: Callable, payload: Callable, samples: int, chunk: int,
                  collect: Callable, *, workers: int = 1, pool: bool = False,
                  scheduler: str | None = None, before_pool: Callable | None = None):
    """Start a sweep held in memory: runs ``0 <= i < samples`` cut into
    chunks of ``chunk`` runs (:func:`chunk_ranges`), one batch each.

    Parameters
    ----------
    run : callable
        ``run(payload) -> output``: one chunk's runs (module-level when it
        runs in a pool or on Dask).
    payload : callable
        ``payload(i0, i1)``: the payload of runs ``i0 <= i < i1``.
    collect : callable
        ``collect(outputs, seconds, workers)``: the result, from the chunks'
        outputs in run order.
    workers, pool, scheduler
        As :class:`workbench.sim.batch.PendingBatch`.
    before_pool : callable, optional
        Called once before more than one chunk is run in a local pool (e.g. to
        compile a kernel the forked workers inherit).

    Returns
    -------
    workbench.sim.batch.PendingBatch
    """
    from ..sim.batch import PendingBatch
    ranges = chunk_ranges(samples, chunk)
    payloads = [payload(i0, i1) for i0, i1 in ranges]
    if before_pool is not None and pool and len(payloads) > 1 and scheduler is None:
        before_pool()
    return PendingBatch(run, payloads, collect, workers, pool,
                        sizes=[i1 - i0 for i0, i1 in ranges], unit="run", scheduler=scheduler)


class FolderTaken(FileExistsError):
    """A sweep's folder holds files: ``other`` is False when ``resume`` was
    not asked for, True when the folder's manifest is not this sweep's."""

    def __init__(self, message: str, other: bool):
        super().__init__(message)
        self.other = other


def claim_folder(folder, manifest: dict, resume: bool, indent: int = 1) -> None:
    """Make ``folder`` this sweep's: a new or empty folder, or with ``resume``
    one whose manifest equals ``manifest``; write the manifest.

    Raises
    ------
    FolderTaken
        The folder holds files and ``resume`` is false, or its manifest is
        missing, unreadable or another sweep's.
    """
    from ..report.files import atomic_write
    folder = Path(folder)
    mpath = folder / MANIFEST
    if folder.exists() and any(folder.iterdir()):
        if not resume:
            raise FolderTaken(f"{folder} already holds a sweep; resume it or choose a new "
                              "folder", other=False)
        try:
            old = json.loads(mpath.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            old = None
        if old != manifest:
            raise FolderTaken(f"{folder} holds another sweep ({old}); expected {manifest}",
                              other=True)
    folder.mkdir(parents=True, exist_ok=True)
    atomic_write(mpath, json.dumps(manifest, indent=indent) + "\n")


@dataclass(frozen=True)
class Chunk:
    """One chunk of a sweep: its file, the run function's payload, its runs."""

    path: Path
    payload: object
    runs: int


def start_chunks(folder, manifest: dict, chunks, run: Callable, write: Callable,
                 collect: Callable, *, resume: bool, workers: int = 1, pool: bool = False,
                 scheduler: str | None = None, indent: int = 1):
    """Claim ``folder`` (:func:`claim_folder`) and start the chunks whose file
    is not written yet.

    Parameters
    ----------
    folder, manifest, resume
        As :func:`claim_folder`.
    chunks : sequence of Chunk
    run : callable
        ``run(payload) -> output``: one chunk's runs.
    write : callable
        ``write(path, output) -> object``: writes a chunk's file as it
        finishes; what it returns goes to ``collect`` (not the output).
    collect : callable
        ``collect(written, seconds, workers)``, as :class:`PendingBatch`.
    workers, pool, scheduler
        As :class:`workbench.sim.batch.PendingBatch`.

    Returns
    -------
    workbench.sim.batch.PendingBatch
    """
    from ..sim.batch import PendingBatch
    claim_folder(folder, manifest, resume, indent)
    todo = [c for c in chunks if not Path(c.path).exists()]
    return PendingBatch(run, [c.payload for c in todo], collect, workers, pool,
                        sizes=[c.runs for c in todo], unit="run", scheduler=scheduler,
                        sink=lambda i, out: write(todo[i].path, out))


def write_npz(path, arrays: dict) -> Path:
    """Write the named arrays to ``path`` (``.npz``) atomically."""
    from ..report.files import atomic_write
    return atomic_write(Path(path), lambda fh: np.savez(fh, **arrays))


def read_npz(paths, select: Callable) -> dict:
    """The arrays of the ``.npz`` files ``paths`` whose name ``select(name)``
    accepts, each concatenated over the files in order."""
    cols: dict = {}
    for p in paths:
        with np.load(p) as z:
            for k in z.files:
                if select(k):
                    cols.setdefault(k, []).append(z[k])
    return {k: np.concatenate(v) for k, v in cols.items()}


def chunk_file(out, i0: int, i1: int) -> Path:
    """The ``.npz`` file of runs ``i0 <= i < i1`` of a streamed sweep."""
    return Path(out) / f"chunk-{i0:09d}-{i1:09d}.npz"


def start_streaming(out, manifest: dict, payload: Callable, run: Callable, collect: Callable,
                    *, resume: bool, workers: int = 1, scheduler: str | None = None,
                    before_pool: Callable | None = None):
    """Start a sweep whose chunks are written to ``out`` as ``.npz`` files
    (:func:`chunk_file`) as they finish.

    Parameters
    ----------
    out, resume
        As :func:`claim_folder`.
    manifest : dict
        What identifies the sweep; it holds at least ``samples`` (the runs)
        and ``chunk`` (runs per file), which fix the files
        (:func:`chunk_ranges`).
    payload : callable
        ``payload(i0, i1)``: the run function's payload of runs ``i0 <= i < i1``.
    run : callable
        ``run(payload) -> dict`` of arrays: one chunk file's contents
        (module-level when it runs in a pool or on Dask).
    collect : callable
        ``collect(seconds, workers)``: the result, once every chunk is written
        (typically from :func:`read_streamed`).
    workers, scheduler, before_pool
        As :func:`start_batches` (a pool when ``workers > 1``).

    Returns
    -------
    workbench.sim.batch.PendingBatch
    """
    chunks = [Chunk(chunk_file(out, i0, i1), payload(i0, i1), i1 - i0)
              for i0, i1 in chunk_ranges(manifest["samples"], manifest["chunk"])]
    if before_pool is not None and scheduler is None and workers > 1 and \
            sum(not c.path.exists() for c in chunks) > 1:
        before_pool()
    return start_chunks(out, manifest, chunks, run, write_npz,
                        lambda paths, seconds, n_workers: collect(seconds, n_workers),
                        resume=resume, workers=workers, pool=workers > 1, scheduler=scheduler)


def read_streamed(out, select: Callable) -> tuple[dict, dict]:
    """(manifest, arrays) of a streamed sweep's folder: the arrays whose
    name ``select(name)`` accepts, concatenated over the chunk files in run
    order (:func:`read_npz`).

    Raises
    ------
    FileNotFoundError
        A chunk file is missing (the sweep is to be resumed).
    """
    out = Path(out)
    man = json.loads((out / MANIFEST).read_text())
    ranges = chunk_ranges(man["samples"], man["chunk"])
    missing = [r for r in ranges if not chunk_file(out, *r).exists()]
    if missing:
        raise FileNotFoundError(f"{out}: {len(missing)} of {len(ranges)} chunks not written "
                                f"(first: runs {missing[0][0]}-{missing[0][1] - 1}); "
                                "resume the sweep")
    return man, read_npz([chunk_file(out, *r) for r in ranges], select)


@dataclass(frozen=True)
class Group:
    """One set of runs of a :func:`run_chunks` sweep.

    Attributes
    ----------
    name : str
        The file prefix (``<name>-chunk-NNNN.csv``): letters, digits, ``_``,
        ``-`` and ``.``.
    draws : dict
        Drawn factor -> array over the group's runs (all samples, in order).
    """

    name: str
    draws: dict


@dataclass(frozen=True)
class ChunkRuns:
    """A group's runs read back from its chunk files.

    Attributes
    ----------
    metrics : dict
        Metric -> array over the runs.
    reasons : list of str
        Why each run ended (empty when the kind has no such column).
    """

    metrics: dict
    reasons: list


def check_resume(out, resume: bool) -> None:
    """``--resume`` without ``--out`` is bad input (exit 2)."""
    from ..errors import DesignError
    if resume and not out:
        raise DesignError("<cli>", "--resume", True, "with --out DIR (the folder to resume)")


def run_chunks(folder: Path, manifest: dict, groups, compute: Callable, resume: bool
               ) -> dict[str, ChunkRuns]:
    """Run (in-process) and write the CSV chunks not yet in ``folder``; read
    every chunk back.

    Parameters
    ----------
    folder : Path
        ``--out``: a new or empty folder, or with ``resume`` a folder of the
        same sweep (its ``sweep.json`` equal to ``manifest`` plus the chunk size).
    manifest : dict
        What identifies the sweep (JSON-serialisable).
    groups : sequence of Group
    compute : callable
        ``compute(group, draws) -> (metrics, reasons)``: the runs of one chunk
        (``draws`` the group's draws sliced to the chunk; ``metrics`` a dict of
        arrays, ``reasons`` a sequence of str or None).
    resume : bool

    Returns
    -------
    dict
        Group name -> :class:`ChunkRuns`.
    """
    from ..errors import DesignError
    from ..report.files import atomic_write
    manifest = dict(manifest) | {"chunk": CHUNK}
    files, chunks = {}, []
    for g in groups:
        files[g.name] = []
        for k, (lo, hi) in enumerate(chunk_ranges(len(next(iter(g.draws.values()))), CHUNK)):
            path = Path(folder) / f"{g.name}-chunk-{k:04d}.csv"
            files[g.name].append(path)
            chunks.append(Chunk(path, (g, {p: v[lo:hi] for p, v in g.draws.items()}), hi - lo))
    try:
        start_chunks(folder, manifest, chunks, lambda gp: (gp[1], *compute(*gp)),
                     lambda path, out: atomic_write(path, _chunk_csv(*out)),
                     lambda *a: None, resume=resume, indent=2).result()
        return {g.name: _read_chunks(files[g.name], len(g.draws)) for g in groups}
    except FolderTaken as e:
        raise DesignError("<cli>", "--out", str(folder),
                          f"a folder of this sweep to resume ({MANIFEST}: "
                          f"{json.dumps(manifest)})" if e.other else
                          "a new or empty folder, or --resume") from None
    except OSError as e:
        raise DesignError("<cli>", "--out", str(folder), f"a folder the chunks can be "
                          f"written to ({type(e).__name__}: {e})") from None


def run_groups(groups, compute: Callable, folder=None, manifest: dict | None = None,
               resume: bool = False) -> dict[str, ChunkRuns]:
    """The runs of every group, the one Monte Carlo path of a kind's report
    and of its ``sweep [--out DIR [--resume]]``: without ``folder`` each
    group's runs are one batch ``compute(group, group.draws)`` held in
    memory; with it they go through the chunk files of :func:`run_chunks`
    (``manifest``, ``resume``: as there).

    Returns
    -------
    dict
        Group name -> :class:`ChunkRuns`.
    """
    if folder is not None:
        return run_chunks(Path(folder), manifest, groups, compute, resume)
    out = {}
    for g in groups:
        metrics, reasons = compute(g, g.draws)
        out[g.name] = ChunkRuns(dict(metrics), [] if reasons is None else list(reasons))
    return out


def _chunk_csv(draws, metrics, reasons) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow([*draws, *metrics, *(["ended"] if reasons is not None else [])])
    n = len(next(iter(draws.values())))
    for j in range(n):
        w.writerow([*(repr(float(v[j])) for v in draws.values()),
                    *(repr(float(v[j])) for v in metrics.values()),
                    *([reasons[j]] if reasons is not None else [])])
    return buf.getvalue()


def _read_chunks(files, ndrawn: int) -> ChunkRuns:
    metrics, reasons = {}, []
    for path in files:
        rows = list(csv.reader(path.read_text(encoding="utf-8").splitlines()))
        head = rows[0]
        end = len(head) - 1 if head[-1] == "ended" else len(head)
        for row in rows[1:]:
            for name, v in zip(head[ndrawn:end], row[ndrawn:end]):
                metrics.setdefault(name, []).append(float(v))
            if end < len(head):
                reasons.append(row[-1])
    return ChunkRuns({k: np.array(v) for k, v in metrics.items()}, reasons)
