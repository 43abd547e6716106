"""``workbench check --jobs N``: every study once, on N processes.

The check's work is the studies (and the proofs); the verdicts and the report
comparison that follow are cheap once the results exist. With ``N > 1`` each
design (and each proof module) is a task of a process pool, slowest first:
the worker runs the study (:func:`workbench.verify.evaluate_design`), compares
that design's committed report with the one it renders (Markdown and every
figure, :func:`workbench.report.writer.check_reports`) and leaves the study
result in the run folder (:mod:`workbench.memo`, ``WORKBENCH_STUDY_CACHE``).
The parent then prints ``workbench verify``'s table from those results,
checks the index and the reports the workers did not, and prints the time of
every task. A test session with the same run folder (``make test``) reads
the same results instead of computing them again: started beside the check,
it runs its first test once the file named by ``WORKBENCH_STUDIES_DONE``
exists, which the check creates as soon as every study result is in the run
folder (before the verdicts and the index, which the tests do not need).
"""
from __future__ import annotations

import os
import shutil
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

from .memo import CACHE_ENV

__all__ = ["TaskTime", "check_parallel", "prefetch", "report_parallel", "run_folder",
           "task_times_table"]

#: Kinds whose studies take longest, started first (the rest by file size).
_SLOW_KINDS = ("antiskid-run", "delay-benchmark", "antiskid-robust", "platoon")
#: Kinds whose studies compile the numba kernels on a cold disk cache.
_COMPILED_KINDS = ("antiskid-run",)
#: Environment variable naming the file created once every study result is in
#: the run folder (see the module docstring).
DONE_ENV = "WORKBENCH_STUDIES_DONE"


@dataclass(frozen=True)
class TaskTime:
    """Wall and CPU seconds of one task in its worker process."""

    name: str
    kind: str
    wall: float
    cpu: float


@contextmanager
def run_folder():
    """The run folder of shared study results: ``WORKBENCH_STUDY_CACHE`` if
    set (kept), else a new temporary folder removed on exit."""
    if os.environ.get(CACHE_ENV):
        yield Path(os.environ[CACHE_ENV])
        return
    folder = tempfile.mkdtemp(prefix="workbench-run-")
    os.environ[CACHE_ENV] = folder
    try:
        yield Path(folder)
    finally:
        os.environ.pop(CACHE_ENV, None)
        shutil.rmtree(folder, ignore_errors=True)


def _cpu() -> float:
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _design_task(path: str, out: str, write: bool = False):
    """Worker: the study of one design and the check of its report (or,
    ``write``, the writing of it)."""
    from .design import load_design
    from .report.writer import check_reports, write_reports
    from .verify import evaluate_design, report_files
    w0, c0 = time.perf_counter(), _cpu()
    d = load_design(path)
    files = report_files(evaluate_design(d))
    if write:
        problems = [f"wrote {p}" for p in write_reports([files], Path(out), index=False)]
    else:
        problems = check_reports([files], Path(out), index=False)
    return d.name, problems, TaskTime(d.name, d.kind, time.perf_counter() - w0, _cpu() - c0)


def _proof_task(module: str):
    """Worker: every claim of one proof module (results cached in the run folder)."""
    from .prove import run_proofs
    w0, c0 = time.perf_counter(), _cpu()
    run_proofs([module])
    name = f"proofs/{module}"
    return name, [], TaskTime(name, "proof", time.perf_counter() - w0, _cpu() - c0)


def _task_order(designs, jobs: int) -> list:
    """Slow kinds first, larger files first; but only one compiled-kernel
    study among the first ``jobs`` tasks: on a cold disk cache the others
    would wait on its compilation (the lock of :mod:`workbench.sim.jit_cache`)
    instead of running another study."""
    order = sorted(designs, key=lambda d: (d.kind not in _SLOW_KINDS,
                                            -Path(d.path).stat().st_size, d.name))
    head = [d for d in order if d.kind in _COMPILED_KINDS][:1]
    head += [d for d in order if d.kind not in _COMPILED_KINDS][:max(jobs - 1, 0)]
    return head + [d for d in order if not any(d is h for h in head)]


def prefetch(designs, proof_modules, out: Path, jobs: int, *, write: bool = False):
    """Run every design's study and report check (``write``: its report
    written), and every proof module, on ``jobs`` processes. Returns (names
    of designs whose reports were checked or written, their problems or the
    paths written, task times)."""
    import multiprocessing as mp
    order = _task_order(designs, jobs)
    checked, problems, times = set(), [], []
    from .sim.batch import die_with_parent   # workers die with the check (issue 32)
    with ProcessPoolExecutor(jobs, mp_context=mp.get_context("fork"),
                             initializer=die_with_parent, initargs=(os.getpid(),)) as ex:
        futs = [ex.submit(_design_task, str(d.path), str(out), write) for d in order]
        futs += [ex.submit(_proof_task, m) for m in proof_modules]
        for f in as_completed(futs):
            name, probs, t = f.result()
            if t.kind != "proof":
                checked.add(name)
            problems += probs
            times.append(t)
    return checked, problems, times


def task_times_table(times, jobs: int, wall: float) -> str:
    """Markdown table of the tasks' times, slowest first, with the total."""
    from .report.markdown import md_table
    rows = [[t.name, t.kind, f"{t.wall:.1f}", f"{t.cpu:.1f}"]
            for t in sorted(times, key=lambda t: (-t.wall, t.name))]
    rows.append(["total", "", f"{sum(t.wall for t in times):.1f}",
                 f"{sum(t.cpu for t in times):.1f}"])
    return (f"\nper-task time on {jobs} processes (a task: one design's study and its report "
            f"check, or one proof module; cpu includes the task's own pool workers; "
            f"{wall:.1f} s wall for the whole check):\n"
            + md_table(["task", "kind", "wall s", "cpu s"], rows, "llrr"))


def check_parallel(designs, out: str | None, jobs: int, verify, report) -> int:
    """``workbench check --jobs N`` (N > 1): :func:`prefetch` in a run folder,
    then ``verify()`` and ``report(checked, problems)`` (the CLI's verbs, which
    find every study result in the folder); the task times on stderr."""
    import sys
    from .reader import display_path
    from .project import find_project
    from .prove import proof_modules
    t0 = time.perf_counter()
    folder = Path(out or display_path(find_project().reports))
    with run_folder():
        checked, problems, times = prefetch(designs, [m.name for m in proof_modules()],
                                            folder, jobs)
        if os.environ.get(DONE_ENV):
            Path(os.environ[DONE_ENV]).touch()
        code = verify()
        print()
        code = max(code, report(checked, problems))
    print(task_times_table(times, jobs, time.perf_counter() - t0), file=sys.stderr)
    return code


def report_parallel(designs, args, jobs: int, finish) -> int:
    """``workbench report --jobs N``: each design's study and report (written,
    or checked with ``--check``) on a pool of N processes, then
    ``finish(names, lines)`` (the CLI's verb) writes or checks the rest: the
    index, the hazard log and the proof reports."""
    from .reader import display_path
    from .project import find_project
    folder = Path(args.out or display_path(find_project().reports))
    with run_folder():
        done, lines, _ = prefetch(designs, [], folder, jobs, write=not args.check)
        return finish(done, lines)
