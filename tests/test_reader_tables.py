"""Reader.quantities and Reader.strings (workbench/reader.py) on toy tables
that name no paper: values in the units' order, bounds, unknown keys and
choices named in the message."""
from __future__ import annotations

import pytest

from workbench.errors import DesignError
from workbench.reader import Quantity, Reader

UNITS = {"k": "N/m", "m": "kg"}


def _q(value, unit):
    return {"value": value, "unit": unit, "source": "toy"}


def test_quantities_read_every_unit_and_finish():
    t = Reader("toy.toml", {"m": _q(2.0, "kg"), "k": _q(5.0, "N/m")}, "plant")
    q = t.quantities(UNITS, positive=True)
    assert list(q) == ["k", "m"] and q["m"] == Quantity(2.0, "kg", "toy")
    with pytest.raises(DesignError, match="plant.m.value"):
        Reader("toy.toml", {"m": _q(-2.0, "kg"), "k": _q(5.0, "N/m")}, "plant").quantities(
            UNITS, positive=True)
    with pytest.raises(DesignError, match="plant.extra"):      # finished: no other key
        Reader("toy.toml", {"m": _q(2.0, "kg"), "k": _q(5.0, "N/m"), "extra": 1},
               "plant").quantities(UNITS)
    with pytest.raises(DesignError, match="plant.k"):
        Reader("toy.toml", {"m": _q(2.0, "kg")}, "plant").quantities(UNITS)


@pytest.mark.parametrize("bad", [[], ["a", "z"], "a", [1]])
def test_strings_are_a_non_empty_list_of_choices(bad):
    t = Reader("toy.toml", {"modes": ["b", "a"], "bad": bad}, "op")
    assert t.strings("modes", ("a", "b")) == ("b", "a")
    with pytest.raises(DesignError, match="op.bad") as exc:
        t.strings("bad", ("a", "b"))
    assert "among 'a', 'b'" in str(exc.value)
