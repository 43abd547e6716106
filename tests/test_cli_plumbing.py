"""The shared plumbing of ``simulate`` / ``sweep`` (:mod:`workbench.features.cli_plumbing`)
on toys that name no paper: a linear delayed loop's SimResult, toy sweeps."""
from __future__ import annotations

import errno

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.cli_plumbing import (check_sweep_flags, pick_case, pick_named,
                                             run_sweep, save_plot, sweep_errors, timed,
                                             trajectory_csv, write_output)
from workbench.sim.batch import SchedulerUnreachable
from workbench.sim.delay import simulate_linear_dde


def test_pick_case():
    assert pick_case(["a", "b"], None) == "a"
    assert pick_case(["a", "b"], "b") == "b"
    with pytest.raises(DesignError, match="--case = 'c'; expected one of a, b"):
        pick_case(["a", "b"], "c")


def test_pick_named_and_timed():
    from types import SimpleNamespace
    items = (SimpleNamespace(name="a", x=1), SimpleNamespace(name="b", x=2))
    assert pick_named(items, None).x == 1 and pick_named(items, "b").x == 2
    with pytest.raises(DesignError, match="--case = 'c'; expected one of a, b"):
        pick_named(items, "c")
    out, wall = timed(lambda: sum(range(1000)))
    assert out == 499500 and wall >= 0.0


def test_trajectory_csv_of_a_linear_run_reads_back():
    r = simulate_linear_dde([[-1.0, 0.0], [0.0, -2.0]], [[0.0, 0.0], [0.0, -0.5]], 0.1,
                            [1.0, 2.0], 0.5, 0.05)
    text = trajectory_csv(r)
    head, *rows = text.splitlines()
    assert head == "t_s,x0,x1"                      # no inputs, unnamed states
    back = np.array([[float(v) for v in row.split(",")] for row in rows])
    np.testing.assert_allclose(back[:, 0], r.t, rtol=1e-8)
    np.testing.assert_allclose(back[:, 1:].T, r.x, rtol=1e-8)


def test_write_output_and_save_plot(tmp_path, capsys):
    write_output(str(tmp_path / "toy.csv"), "t_s,x0\n0,1\n")
    assert (tmp_path / "toy.csv").read_text() == "t_s,x0\n0,1\n"
    assert capsys.readouterr().out == f"wrote {tmp_path / 'toy.csv'}\n"
    save_plot(str(tmp_path / "toy.png"), "a toy line",
              lambda fig: fig.add_subplot(111).plot([0, 1], [1, 0]), (3.0, 2.0))
    assert (tmp_path / "toy.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_sweep_flags():
    check_sweep_flags(1, None)
    with pytest.raises(DesignError, match="--samples"):
        check_sweep_flags(0, None)
    with pytest.raises(DesignError, match="--workers"):
        check_sweep_flags(3, 0)
    check_sweep_flags(1, None, "numpy")
    with pytest.raises(DesignError, match="--kernel = 'fortran'; expected compiled or numpy"):
        check_sweep_flags(1, None, "fortran")


def test_compiled_kernel_flag_needs_numba(monkeypatch):
    import workbench.sim.kernel_path as kp
    monkeypatch.setattr(kp, "compiled_available", lambda: False)
    with pytest.raises(DesignError, match="numba is not installed"):
        check_sweep_flags(1, None, "compiled")


def test_sweep_errors_name_the_flag():
    with pytest.raises(DesignError, match="--scheduler = 'tcp://x'"):
        with sweep_errors(None, "tcp://x"):
            raise SchedulerUnreachable("nobody there")
    with pytest.raises(DesignError, match="--out = 'dir'.*No space"):
        with sweep_errors("dir", None):
            raise OSError(errno.ENOSPC, "No space left on device")
    with pytest.raises(OSError):                  # without --out: not a flag's problem
        with sweep_errors(None, None):
            raise OSError(errno.ENOSPC, "No space left on device")
    with pytest.raises(ValueError):
        with sweep_errors("dir", None):
            raise ValueError("a bug")


class _Pending:
    """A toy streamed sweep: its result is the sum of the runs."""

    def __init__(self, runs):
        self.runs = runs

    def result(self, progress):
        return sum(self.runs), progress


def test_run_sweep_in_memory_streamed_and_its_errors():
    flags = dict(resume=False, scheduler=None, progress=True)
    direct, streamed = lambda: (6, None), lambda: _Pending([1, 2, 3])
    assert run_sweep(direct, streamed, out=None, **flags) == (6, None)
    assert run_sweep(direct, streamed, out="dir", **flags) == (6, True)

    def taken():
        raise FileExistsError("dir holds another sweep")
    with pytest.raises(DesignError, match="--out = 'dir'; expected a new folder or --resume"):
        run_sweep(direct, taken, out="dir", **flags)
    with pytest.raises(DesignError, match="--resume"):
        run_sweep(direct, streamed, out=None, **{**flags, "resume": True})

    def unreachable():
        raise SchedulerUnreachable("nobody there")
    with pytest.raises(DesignError, match="--scheduler = 'local'"):
        run_sweep(unreachable, streamed, out=None, **{**flags, "scheduler": "local"})
