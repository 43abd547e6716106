"""General design-table readers (:mod:`workbench.features.spec_readers`) on
toy tables that name no paper."""
from __future__ import annotations

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.spec_readers import (event_time, read_range, read_step_tolerances,
                                             sourced_range)
from workbench.reader import Reader


def test_read_range_checks_order_and_bounds():
    t = Reader("toy.toml", {"gain": [0.5, 2.0], "down": [2.0, 1.0], "neg": [-1.0, 1.0],
                            "three": [1.0, 2.0, 3.0]}, "toy")
    assert tuple(read_range(t, "gain", positive=True, hi=5.0)) == (0.5, 2.0)
    with pytest.raises(DesignError, match="low <= high"):
        read_range(t, "down")
    with pytest.raises(DesignError, match="low <= high"):
        read_range(t, "three")
    with pytest.raises(DesignError, match=r"allowed values \(\{'positive': True\}\)"):
        read_range(t, "neg", positive=True)
    with pytest.raises(DesignError, match="allowed values"):
        read_range(t, "gain", lo=1.0)


def test_sourced_range_reads_range_unit_and_source():
    t = Reader("toy.toml", {"band": {"span": [1.0, 3.0], "unit": "m", "source": "toy",
                                     "step": 0.5}}, "toy")
    lo_hi, source, sub = sourced_range(t, "band", "span", "m", positive=True)
    assert tuple(lo_hi) == (1.0, 3.0) and source == "toy"
    assert sub.number("step", positive=True) == 0.5      # the caller reads the rest
    sub.finish()
    bad = Reader("toy.toml", {"band": {"span": [1.0, 3.0], "unit": "km", "source": "toy"}},
                 "toy")
    with pytest.raises(DesignError, match="band.unit"):
        sourced_range(bad, "band", "span", "m")


def test_event_time_absorbs_last_bit_moves():
    t = 300.0
    moved = np.nextafter(np.nextafter(np.nextafter(t, 1e9), 1e9), 1e9)
    assert moved != t and event_time(float(moved)) == t == event_time(t)
    assert event_time(12.345) == 12.345


def test_step_tolerances_per_metric():
    t = Reader("toy.toml", {"convergence_rtol": 1e-3, "convergence_atol": {"peak": 0.1}},
               "numerics")
    assert read_step_tolerances(t, ("peak", "final")) == (1e-3, {"peak": 0.1})
    bad = Reader("toy.toml", {"convergence_rtol": 1e-3, "convergence_atol": {"nope": 0.1}},
                 "numerics")
    with pytest.raises(DesignError, match="a metric name: peak, final"):
        read_step_tolerances(bad, ("peak", "final"))
    big = Reader("toy.toml", {"convergence_rtol": 0.5, "convergence_atol": {}}, "numerics")
    with pytest.raises(DesignError, match="convergence_rtol"):
        read_step_tolerances(big, ("peak",))


def test_keyed_numbers_takes_only_known_keys_within_bounds():
    from workbench.features.spec_readers import keyed_numbers
    t = Reader("toy.toml", {"x": 1.5, "y": -2.0}, "scenario.target")
    assert keyed_numbers(t, ("x", "y", "z"), "a state: x, y, z", lo=-10.0) == {"x": 1.5, "y": -2.0}
    bad = Reader("toy.toml", {"w": 1.0}, "scenario.target")
    with pytest.raises(DesignError, match="a state: x, y"):
        keyed_numbers(bad, ("x", "y"), "a state: x, y")
    low = Reader("toy.toml", {"x": -1.0}, "scenario.target")
    with pytest.raises(DesignError, match="scenario.target.x"):
        keyed_numbers(low, ("x",), "a state", positive=True)


def test_named_tables_need_one_table_and_distinct_matching_names():
    import re
    from workbench.features.spec_readers import named_tables
    ok = Reader("toy.toml", {"modes": [{"name": "a", "k": 1.0}, {"name": "b", "k": 2.0}]}, "")
    got = named_tables(ok, "modes", re.compile(r"[a-z]+$"))
    assert [n for _, n in got] == ["a", "b"] and got[1][0].number("k") == 2.0
    with pytest.raises(DesignError, match=r"at least one \[\[modes\]\]"):
        named_tables(Reader("toy.toml", {"modes": []}, ""), "modes")
    twice = Reader("toy.toml", {"modes": [{"name": "a"}, {"name": "a"}]}, "")
    with pytest.raises(DesignError, match=r"modes\[1\].name.*used once"):
        named_tables(twice, "modes")
    with pytest.raises(DesignError, match="letters, digits"):
        named_tables(Reader("toy.toml", {"modes": [{"name": "a-b"}]}, ""), "modes",
                     re.compile(r"\w+$"))
