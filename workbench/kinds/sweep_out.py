"""``workbench sweep --out DIR [--resume]`` for every kind whose sweep is a
batch of independent runs (issue 35, item 1: Monte Carlo "chunked and
resumable"): ``switched-run``, ``stop-accuracy`` and ``delay-feedback``.

The runs of a sweep are cut into chunks of :data:`CHUNK` (in draw order);
each chunk is computed on its own and written, as it finishes, to
``DIR/<group>-chunk-NNNN.csv`` (one row per run: its draws, its metrics and,
when the kind has one, why it ended; ``repr`` floats, so a file reads back
bit for bit). ``DIR/sweep.json`` records what a resumed sweep must match (the
design, samples, seed, chunk size and the kind's own keys); ``--resume``
skips the chunks already in DIR, so a resumed sweep writes the same files as
an uninterrupted one (the draws are made once for all samples and sliced).
The summary is read back from the files.

A kind calls :func:`run_chunks` with one :class:`Group` per set of runs
(a scenario; a speed and controller) and a function computing one chunk.
"""
from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

__all__ = ["CHUNK", "ChunkRuns", "Group", "check_resume", "run_chunks"]

#: Runs per chunk file of ``sweep --out``.
CHUNK = 50


@dataclass(frozen=True)
class Group:
    """One set of runs of a sweep.

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
    """Run and write the chunks not yet in ``folder``; read every chunk back.

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
    mpath = folder / "sweep.json"
    try:
        if folder.exists() and any(folder.iterdir()):
            if not resume:
                raise DesignError("<cli>", "--out", str(folder), "a new or empty folder, "
                                  "or --resume")
            try:
                old = json.loads(mpath.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                old = None
            if old != manifest:
                raise DesignError("<cli>", "--out", str(folder), f"a folder of this sweep "
                                  f"to resume ({mpath.name}: {json.dumps(manifest)})")
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write(mpath, json.dumps(manifest, indent=2) + "\n")
        out = {}
        for g in groups:
            n = len(next(iter(g.draws.values())))
            files = []
            for k, lo in enumerate(range(0, n, CHUNK)):
                path = folder / f"{g.name}-chunk-{k:04d}.csv"
                files.append(path)
                if path.is_file():
                    continue
                part = {p: v[lo:lo + CHUNK] for p, v in g.draws.items()}
                m, why = compute(g, part)
                atomic_write(path, _chunk_csv(part, m, why))
            out[g.name] = _read_chunks(files, len(g.draws))
        return out
    except OSError as e:
        raise DesignError("<cli>", "--out", str(folder), f"a folder the chunks can be "
                          f"written to ({type(e).__name__}: {e})") from None


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
