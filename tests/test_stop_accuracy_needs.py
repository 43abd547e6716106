"""What an [analysis] module needs of a stop-accuracy design
(:mod:`workbench.kinds.stop_accuracy.needs`), on the general synthetic design:
nothing missing passes, every missing part is named, the failure is one
design error on ``analysis.module``."""
from __future__ import annotations

from pathlib import Path

import pytest

from workbench.design import load_design
from workbench.errors import DesignError
from workbench.kinds.stop_accuracy.needs import missing, require
from workbench.reader import Reader

SYNTH = Path(__file__).resolve().parent.parent / "designs" / "stop-accuracy-synthetic.toml"


@pytest.fixture(scope="module")
def spec():
    return load_design(SYNTH).spec


def test_a_design_with_every_part_misses_nothing(spec):
    assert missing(spec, controllers=("held", "profile_pid"), pids=("profile_pid",),
                   faults=("speed_high", "electric_loss"), constants=("k_v",),
                   tables=("montecarlo",)) == []


def test_every_missing_part_is_named(spec):
    got = missing(spec, controllers=("held", "adaptive"), pids=("held",), loops=("profile",),
                  grid=("gradient",), feasible_with="held", faults=("stuck",),
                  constants=("k_v", "t_x"), tables=("reference", "sections", "command"))
    assert got == ["adaptive", "deceleration_loop in profile", "pid in held", "[grid] of gradient",
                   "feasible_with = held", "fault stuck", "constant t_x", "[reference]",
                   "[[sections]]", "[target] command"]


def test_require_fails_on_analysis_module_in_one_line(spec):
    root = Reader(str(SYNTH), {})
    require(root, spec, "p999.toy", controllers=("held",))           # nothing missing
    with pytest.raises(DesignError) as e:
        require(root, spec, "p999.toy", controllers=("held", "adaptive"), constants=("t_x",))
    text = str(e.value)
    assert "analysis.module" in text and "the controllers held, adaptive" in text
    assert "(missing: adaptive, constant t_x)" in text and "\n" not in text.strip()
