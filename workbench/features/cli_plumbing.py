"""Plumbing of the ``workbench simulate`` and ``workbench sweep`` commands
(issue 35): picking the ``--case``, timing a run, writing an output file or
a figure (``--csv``, ``--figure``), the trajectory CSV of a recorded
:class:`~workbench.sim.delay.SimResult`, the checks of the sweep's flags
(``--kernel`` among :data:`workbench.sim.kernel_path.KERNELS`), and
the translation of a sweep's failures (an unreachable Dask scheduler, an
``--out`` folder that cannot be written) into one clear
:class:`~workbench.errors.DesignError` each (exit 2, no traceback).

The driver of a sweep with ``--out`` / ``--resume`` / ``--scheduler``,
:func:`run_sweep`, takes the study's two ways to run (in memory, or streamed
to a folder) as callbacks and owns the flag checks and the failures.

Who uses what today: ``switched-run`` uses :func:`pick_named` and :func:`timed`; the
``antiskid-run`` commands use all of it (the only sweep with ``--scheduler``)
but :func:`pick_case`.
The ``delay-feedback`` and ``switched-run`` CSVs keep their own format
(``repr`` floats, :func:`workbench.kinds.delay_feedback.cli.csv_text`), which
their users' files already read; :func:`trajectory_csv` prints nine digits.
"""
from __future__ import annotations

from contextlib import contextmanager

import numpy as np

from ..errors import DesignError

__all__ = ["check_scheduler", "check_sweep_flags", "pick_case", "pick_named", "run_sweep",
           "save_plot", "sweep_errors", "timed", "trajectory_csv", "write_output"]


def pick_case(names, case: str | None) -> str:
    """``case`` if it is one of ``names``, the first name when None;
    DesignError on ``--case`` otherwise."""
    if case is not None and case not in names:
        raise DesignError("<cli>", "--case", case, "one of " + ", ".join(names))
    return case if case is not None else names[0]


def pick_named(items, case: str | None):
    """The item of ``items`` (each with a ``name``) named ``case``, the first
    when None (:func:`pick_case`)."""
    names = [x.name for x in items]
    return items[names.index(pick_case(names, case))]


def timed(run):
    """(``run()``, the wall-clock seconds it took)."""
    import time
    t0 = time.perf_counter()
    out = run()
    return out, time.perf_counter() - t0


def write_output(path: str, text: str) -> None:
    """``text`` written to the file ``path`` (atomically), and ``wrote <path>`` printed."""
    from pathlib import Path

    from ..report.files import atomic_write
    atomic_write(Path(path), text)
    print(f"wrote {path}")


def save_plot(path: str, caption: str, draw, size: tuple[float, float]) -> None:
    """The figure ``draw(fig)`` (``size`` in inches) as a PNG at ``path``,
    named by the file's stem (:func:`workbench.report.figures.save_figure`)."""
    from pathlib import Path

    from ..report.figures import save_figure
    from ..report.markdown import Figure
    save_figure(Figure(Path(path).stem, caption, draw, size), Path(path))


def trajectory_csv(run) -> str:
    """CSV of a recorded run: ``t_s``, the states, u(t) and u(t - h) (columns
    ``<input>_applied``), nine significant digits; states and inputs without
    names are ``x0``, ``x1``, ... and ``u0``, ..."""
    names = list(run.state_names) or [f"x{i}" for i in range(run.x.shape[0])]
    ins = list(run.input_names) or [f"u{i}" for i in range(run.u.shape[0])]
    head = ["t_s"] + names + ins + [f"{u}_applied" for u in ins]
    cols = np.vstack([run.t[None, :], run.x, run.u, run.u_applied])
    return ",".join(head) + "\n" + "".join(",".join(f"{v:.9g}" for v in row) + "\n"
                                          for row in cols.T)


def check_sweep_flags(samples, workers, kernel: str | None = None) -> None:
    """``--samples`` and ``--workers`` (None: the default) positive integers;
    ``--kernel`` (None: the default) one of :data:`~workbench.sim.kernel_path.KERNELS`,
    "compiled" only where numba is installed."""
    from ..sim.kernel_path import KERNELS, compiled_available
    if not samples >= 1:
        raise DesignError("<cli>", "--samples", samples, "a positive integer")
    if workers is not None and not workers >= 1:
        raise DesignError("<cli>", "--workers", workers, "a positive integer")
    if kernel is not None and kernel not in KERNELS:
        raise DesignError("<cli>", "--kernel", kernel, " or ".join(KERNELS))
    if kernel == "compiled" and not compiled_available():
        raise DesignError("<cli>", "--kernel", kernel,
                          "numpy here: numba is not installed "
                          "(pip install 'traincontrol-workbench[fast]')")


def check_scheduler(scheduler) -> None:
    """``--scheduler`` (None: none) only where dask.distributed is installed."""
    if scheduler is not None:
        from importlib.util import find_spec
        if find_spec("distributed") is None:
            raise DesignError("<cli>", "--scheduler", scheduler,
                              "no flag here: dask.distributed is not installed "
                              "(pip install 'traincontrol-workbench[scale]')")


@contextmanager
def sweep_errors(out: str | None, scheduler: str | None):
    """Around a sweep: an unreachable ``--scheduler``
    (:class:`~workbench.sim.batch.SchedulerUnreachable`) and, with ``--out``,
    an OSError writing its chunks become a DesignError on that flag; any
    other error passes."""
    from ..sim.batch import SchedulerUnreachable
    try:
        yield
    except SchedulerUnreachable as e:
        raise DesignError("<cli>", "--scheduler", scheduler,
                          f"'local' or the address of a running Dask scheduler ({e})") from None
    except OSError as e:       # writing a chunk file (--out), not the scheduler
        if not out:
            raise
        raise DesignError("<cli>", "--out", out, f"a folder the chunks can be written to "
                          f"({type(e).__name__}: {e})") from None


def run_sweep(direct, streamed, *, out: str | None, resume: bool, scheduler: str | None,
              progress: bool):
    """The result of a sweep, ``--scheduler``, ``--out`` and ``--resume`` checked.

    Parameters
    ----------
    direct : callable
        ``direct() -> result``: the sweep held in memory (no ``--out``).
    streamed : callable
        ``streamed() -> pending``: the sweep written to the folder ``out`` as
        it runs; ``pending.result(progress=...)`` waits for it. A
        FileExistsError (a folder of another sweep, or without ``--resume``)
        becomes a DesignError on ``--out``.
    out, resume, scheduler : the flags
    progress : bool
        Show the streamed sweep's progress.

    Returns
    -------
    The sweep's result; its failures are one DesignError each (:func:`sweep_errors`).
    """
    from .montecarlo_chunks import check_resume
    check_scheduler(scheduler)
    check_resume(out, resume)
    with sweep_errors(out, scheduler):
        if not out:
            return direct()
        try:
            pending = streamed()
        except FileExistsError as e:
            raise DesignError("<cli>", "--out", out, f"a new folder or --resume ({e})") from None
        return pending.result(progress=progress)
