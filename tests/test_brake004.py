"""Paper 004: worked numbers, fuzzy controller, axle-speed faults, error grid."""
from dataclasses import replace

import numpy as np
import pytest

from workbench.controllers.fuzzy import FuzzyIncrement, memberships
from workbench.design import load_design
from workbench.papers.p004.closed_loop_brake import compute_worked, run_grid

DESIGN = "designs/closed-loop-brake-004.toml"


@pytest.fixture(scope="module")
def spec():
    return load_design(DESIGN).spec


def test_worked_numbers_match_print_at_printed_digits(spec):
    w = compute_worked(spec.paper.worked)
    assert round(w["d1"], 3) == 96.466            # 004 section 1.3.3, case 1
    assert round(w["a2"], 3) == 0.703             # case 2 deceleration
    assert round(w["d2"], 2) == 137.22            # case 2 distance
    assert round(w["share[30permille,1]"], 2) == 29.39   # 004 section 1.3.2
    assert round(w["share[15permille,0.7]"], 2) == 21.00
    # the printed difference 40.754 m is the difference of the rounded distances
    assert round(137.22 - 96.466, 3) == 40.754 and round(w["delta"], 3) != 40.754


def test_fuzzy_memberships_partition_and_rule_table_is_odd():
    x = np.linspace(-1.5, 1.5, 31)
    assert np.allclose(memberships(x).sum(axis=-1), 1.0)
    f = FuzzyIncrement(0.3, 0.5, 0.05)
    assert f.increment(0.0, 0.0) == pytest.approx(0.0)
    assert f.increment(0.2, 0.1) == pytest.approx(-f.increment(-0.2, -0.1))
    assert f.increment(1.0, 1.0) == pytest.approx(0.05)     # saturates at du_scale
    assert f.increment(0.1, 0.0) > 0


@pytest.fixture(scope="module")
def res50(spec):
    corners = {"force_error": (0.0, 0.15), "gradient": (0.0, 30.0), "friction": (1.0,)}
    small = replace(spec, speeds_kmh=(50.0,), grid=tuple((k, corners[k]) for k, _ in spec.grid))
    return run_grid(small)


def _corner(res, mode, fe, gr):
    """Stop error (m) of ``mode`` (analogue channel) at the grid corner (fe, gr, friction 1)."""
    return res.grid(50.0, mode)[res.corners().index((fe, gr, 1.0))]


def test_max_of_four_axles_masks_up_to_three_bad_sensors(res50):
    healthy = res50.stop(50.0)
    assert healthy == _corner(res50, "closed", 0.0, 0.0)    # the nominal run is the corner's
    for f in ("1 sliding", "3 failed", "2 sliding + 1 failed"):
        assert res50.stop(50.0, fault=f) == pytest.approx(healthy, abs=1e-12)


def test_all_four_bad_falls_back_to_ato_open_loop(res50):
    ato = res50.stop(50.0, "ato-open")
    assert res50.stop(50.0, fault="all 4 failed") == pytest.approx(ato, abs=1e-12)
    assert res50.stop(50.0, fault="all 4 sliding") == pytest.approx(ato, abs=1e-12)


def test_open_loop_single_command_is_exact_only_at_the_nominal_corner(res50):
    nominal = _corner(res50, "open", 0.0, 0.0)
    assert abs(nominal) < 1e-6                       # D is its stopping distance
    assert abs(_corner(res50, "open", 0.15, 0.0)) > 5.0


def test_closed_loop_beats_open_loop_off_nominal(res50):
    for fe, gr in ((0.15, 0.0), (0.0, 30.0), (0.15, 30.0)):
        closed = _corner(res50, "closed", fe, gr)
        opened = _corner(res50, "open", fe, gr)
        assert abs(closed) < abs(opened) / 5
