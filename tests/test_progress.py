"""Progress bars (issue 17, item 4): shown on a terminal, silent otherwise
(``--json``, CI, pipes); never on stdout."""
from __future__ import annotations

import io
import sys

import pytest

from workbench.sim.batch import PendingBatch
from workbench.sim.progress import progress, shown


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def _collect(outs, seconds, workers):
    return outs


def test_shown_only_on_a_terminal_and_when_enabled():
    assert shown(True, Terminal()) and not shown(False, Terminal())
    assert not shown(True, io.StringIO())


def test_batch_bar_on_a_terminal_counts_units(monkeypatch, capsys):
    term = Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    job = PendingBatch(abs, [-1, -2, -3], _collect, 1, False, sizes=[5, 5, 2], unit="run")
    assert job.result(progress=True) == [1, 2, 3]
    text = term.getvalue()
    assert "12/12" in text and "run" in text
    assert capsys.readouterr().out == ""          # stdout untouched


@pytest.mark.parametrize("enabled", [True, False])
def test_silent_when_not_a_terminal_or_disabled(monkeypatch, enabled):
    stream = io.StringIO() if enabled else Terminal()
    monkeypatch.setattr(sys, "stderr", stream)
    job = PendingBatch(abs, [-1, -2], _collect, 1, False)
    assert job.result(progress=enabled) == [1, 2]
    for _ in progress(range(3), enabled=enabled):
        pass
    assert stream.getvalue() == ""


def test_pool_results_keep_payload_order():
    job = PendingBatch(abs, [-3, -1, -2, -5], _collect, 2, True, sizes=[1, 1, 1, 1])
    assert job.result(progress=False) == [3, 1, 2, 5]
