"""A forked worker process that computes items in order while this process
goes on (issue 36, item 4: the second half of each eps's row of
:func:`workbench.synthesis.synthesize_delay_bound`, overlapped with the
bisection of the next eps).

The worker is a ``fork`` of this process taken when the stage starts, so the
work function and everything it reaches (compiled problems, parameters) are
the parent's, and its results come back pickled (exact for floats and numpy
arrays) in the order submitted. Whatever the worker could not return (it
died, or its work raised) is computed in this process by the same function,
so an exception is raised here, as without the stage. A reader thread takes
the answers as they come, so the worker never waits on a full pipe while
this process waits on the other. ``gc.freeze()`` around the fork keeps the
worker's collector off this process's objects (fewer pages copied). No
stage (the caller works serially) where forking is unavailable or unwise:
one CPU, inside a worker of a process pool (its processes already use the
CPUs), or with other Python threads running.
"""
from __future__ import annotations

import gc
import multiprocessing as mp
import os
import threading
from typing import Callable

__all__ = ["ForkedStage"]


class ForkedStage:
    """``work(*item)`` for each submitted item in ONE forked worker process,
    in order, while this process goes on (module docstring)."""

    #: Stages started in this process.
    started = 0

    def __init__(self, work: Callable, warm: Callable | None):
        ctx = mp.get_context("fork")
        items_in, self.items = ctx.Pipe(duplex=False)      # (reader, writer)
        self.answers, answers_out = ctx.Pipe(duplex=False)
        self.pending, self.got = [], []
        self.proc = ctx.Process(target=self._serve, args=(items_in, answers_out, work, warm),
                                daemon=True)
        gc.freeze()        # the worker's collector then leaves this process's objects
        try:               # (and the pages they are on) alone: fewer pages copied
            self.proc.start()
        finally:
            gc.unfreeze()
        ForkedStage.started += 1
        items_in.close()
        answers_out.close()
        # a thread here takes every answer as it comes, so the worker never waits
        # on a full pipe while this process waits on the other (no deadlock)
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self) -> None:
        while True:
            try:
                self.got.append(self.answers.recv())
            except (EOFError, OSError):            # the worker is done (or died)
                return

    @classmethod
    def start(cls, work: Callable, n_items: int, warm: Callable | None = None
              ) -> "ForkedStage | None":
        """A stage whose worker first calls ``warm()``, or None (do the work
        here) for fewer than two items, without ``fork`` or a second CPU, inside a worker of a process pool (``workbench check --jobs``:
        its processes already use the CPUs, and the stage costs some CPU of its
        own: the fork and the pages the worker copies), or in a process with
        other threads (a notebook kernel, a GUI: forking it is not safe)."""
        if (n_items < 2 or "fork" not in mp.get_all_start_methods() or (os.cpu_count() or 1) < 2
                or mp.parent_process() is not None or threading.active_count() > 1):
            return None
        try:
            return cls(work, warm)
        except OSError:                  # no process to spare: serial
            return None

    @staticmethod
    def _serve(items, answers, work: Callable, warm: Callable | None) -> None:
        if warm is not None:
            try:
                warm()
            except Exception:   # noqa: BLE001 - only a head start: the items decide
                pass
        while True:
            try:
                item = items.recv()
            except EOFError:
                break
            if item is None:
                break
            try:
                out = (True, work(*item))
            except BaseException as exc:   # noqa: BLE001 - re-raised by the serial retry
                out = (False, repr(exc))
            answers.send(out)
        answers.close()

    def submit(self, *item) -> None:
        """Queue ``work(*item)`` in the worker."""
        self.pending.append(item)
        try:
            self.items.send(item)
        except OSError:
            pass                         # computed here in :meth:`results`

    def results(self, work: Callable) -> tuple:
        """The results of every submitted item, in order (``work`` here for any
        the worker did not return); the worker is stopped."""
        self.close()
        out = []
        for i, item in enumerate(self.pending):
            ok, res = self.got[i] if i < len(self.got) else (False, None)
            out.append(res if ok else work(*item))
        return tuple(out)

    def close(self, finish: bool = True) -> None:
        """Stop the worker: after the items sent (``finish``), or now."""
        if not finish:
            self.proc.kill()
        try:
            self.items.send(None)
        except OSError:
            pass
        self.items.close()
        self.reader.join()
        self.answers.close()
        self.proc.join(timeout=5)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()
