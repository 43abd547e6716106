"""The gain of a study, printed or synthesised (:mod:`workbench.features.gain_choice`),
on a toy loop that names no paper: a double integrator x'' = u."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.gain_choice import GainChoice, chosen_gain, read_gain_choice
from workbench.reader import Reader

TOY = SimpleNamespace(A=np.array([[0.0, 1.0], [0.0, 0.0]]), B=np.array([[0.0], [1.0]]))


def _table(**over):
    data = {"gain": "synthesis", "eps": 0.5, "K_table": [-1.0, -2.0], "K_source": "toy"} | over
    return Reader("toy.toml", {"controller": data}).table("controller")


def test_read_gain_choice_reads_and_rejects():
    assert read_gain_choice(_table(), 2) == GainChoice("synthesis", 0.5, (-1.0, -2.0), "toy")
    with pytest.raises(DesignError, match=r"controller.K_table.*2 gain entries \[k1, k2\]"):
        read_gain_choice(_table(K_table=[-1.0, -2.0, 3.0]), 2)
    with pytest.raises(DesignError, match="controller.gain"):
        read_gain_choice(_table(gain="tuned"), 2)
    with pytest.raises(DesignError, match="controller.eps"):
        read_gain_choice(_table(eps=0.0), 2)


def test_table_gain_needs_no_linearisation():
    def never():
        raise AssertionError("a table gain must not linearise")
    assert chosen_gain(GainChoice("table", 0.5, (-1.0, -2.0), "toy"), never, "toy-gain",
                       ("toy",), "synthesised") == ((-1.0, -2.0), "toy", None)


def test_synthesised_gain_is_certified_stabilising_and_computed_once():
    from workbench.margins import delay_margin_eig
    from workbench.memo import clear
    clear()
    calls = []

    def lin():
        calls.append(1)
        return TOY
    choice = GainChoice("synthesis", 0.5, (-1.0, -2.0), "toy")
    K, how, h = chosen_gain(choice, lin, "toy-gain", ("double integrator", 0.5), "synthesised")
    assert how == "synthesised" and h > 0
    Ad = TOY.B @ np.atleast_2d(np.asarray(K, float))
    assert np.max(np.linalg.eigvals(TOY.A + Ad).real) < 0           # stable without delay
    assert delay_margin_eig(TOY.A, Ad).h >= h                        # the bound is sound
    again = chosen_gain(choice, lin, "toy-gain", ("double integrator", 0.5), "synthesised")
    assert again == (K, how, h) and len(calls) == 1                  # synthesised once
    clear()
