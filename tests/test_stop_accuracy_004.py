"""Paper 004's closed loop as a ``stop-accuracy`` configuration
(designs/stop-accuracy-004-closed.toml, the named module ``deceleration_loop``):
its stop errors equal those of designs/closed-loop-brake-004.toml (the same kind
with paper 004's ``[analysis]`` module, its report read from the kind's run)
draw by draw, corner by corner and fault by fault, bit for bit; bad module
input exits 2 in one line."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds.stop_accuracy.decel_loop import axle_speeds
from workbench.kinds.stop_accuracy.run import run, stopping_points

ROOT = Path(__file__).resolve().parent.parent
CLOSED = ROOT / "designs" / "stop-accuracy-004-closed.toml"
P004 = ROOT / "designs" / "closed-loop-brake-004.toml"
#: the kind's fault name -> closed-loop-brake-004's
FAULT_NAMES = {"sliding_1": "1 sliding", "failed_3": "3 failed",
               "sliding_2_failed_1": "2 sliding + 1 failed", "failed_4": "all 4 failed",
               "sliding_4": "all 4 sliding", "high_1": "1 reading high", "stuck_1": "1 stuck"}
CORNERS = {"force_error": (0.0, 0.15), "gradient": (-30.0, 0.0), "friction": (1.0, 1.2)}


@pytest.fixture(scope="module")
def both():
    """The kind's run and the study's, on 4 Monte Carlo draws and a 2 x 2 x 2
    grid from 50 km/h."""
    from workbench.papers.p004.closed_loop_brake import run_grid
    from workbench.papers.p004.closed_loop_brake_run import run_montecarlo
    spec = load_design(CLOSED).spec
    spec = dataclasses.replace(spec, speeds_kmh=(50.0,), convergence=False,
                               montecarlo=dataclasses.replace(spec.montecarlo, samples=4),
                               grid=tuple((k, CORNERS[k]) for k, _ in spec.grid))
    p4 = load_design(P004).spec
    p4 = dataclasses.replace(p4, speeds_kmh=(50.0,),
                             grid=tuple((k, CORNERS[k]) for k, _ in p4.grid),
                             montecarlo=dataclasses.replace(p4.montecarlo, samples=4))
    D = stopping_points(p4)[50.0]
    return run(spec), run_grid(p4, montecarlo=False), run_montecarlo(p4, {50.0: D}), D


def test_closed_loop_reproduces_closed_loop_brake_bit_for_bit(both):
    res, grid, mc, D = both
    assert res.distance[50.0] == D
    for name, channel in (("closed", "analogue"), ("closed_3bit", "3bit")):
        assert res.grid[50.0, name] == grid.grid(50.0, "closed", channel)   # corner by corner
    from workbench.kinds.stop_accuracy.quantities import feasible
    assert feasible(res, 50.0) == feasible(grid.kind, 50.0)      # [grid] feasible_with
    assert 0 < sum(feasible(res, 50.0)) < len(grid.corners())
    ref = mc[50.0, "closed"]
    np.testing.assert_array_equal(res.mc[50.0, "closed"].errors, ref.errors)   # draw by draw
    for ours, theirs in FAULT_NAMES.items():
        assert res.faults[50.0, "closed", ours] == grid.stop(50.0, fault=theirs)
    assert res.faults[50.0, "closed", "electric_loss"] == grid.stop(50.0, fault="electric_loss")
    # the nominal run is the grid's nominal corner, which the study's report printed
    assert res.nominal[50.0, "closed"] == grid.stop(50.0) == res.grid[50.0, "closed"][
        grid.corners().index((0.0, 0.0, 1.0))]


def test_fallback_and_masking(both):
    res = both[0]
    q = {f: res.faults[50.0, "closed", f] for f in FAULT_NAMES}
    # max of four axles: up to three bad sensors change nothing
    for f in ("sliding_1", "failed_3", "sliding_2_failed_1"):
        assert q[f] == res.nominal[50.0, "closed"]
    # every axle detected bad: the loop is off, both cases are the law alone
    assert q["failed_4"] == q["sliding_4"] != res.nominal[50.0, "closed"]
    assert q["stuck_1"] < -10.0          # undetected: the loop winds up to full service


def test_axle_speeds_per_state():
    st = np.array([list("oshzf")])
    got = axle_speeds(st, np.array([10.0]), np.array([20.0]), 0.2, 1.1)
    assert got.tolist() == [[10.0, 8.0, 11.0, 20.0, 0.0]]


LOOP = 'kp = "kp", ki = "ki"'
BAD = [
    (LOOP, 'kp = "kq", ki = "ki"', "kq"),                                   # not a constant
    (LOOP, 'kp = "ki", ki = "ki"', "deceleration_loop.kp"),                 # 1/s, not 1
    (LOOP, 'kp = "kp", ki = "kp"', "deceleration_loop.ki"),                 # 1, not 1/s
    ('axles = "sooo"', 'axles = "soo"', "axle states"),
    ('axles = "sooo"', 'axles = "sooq"', "axle states"),
    ('slide      = { value = 0.2,', 'slide      = { value = 1.5,', "slide_ratio"),
    ('levels = 7', 'levels = 2.5', "levels"),
    ('levels = 7', 'levels = 0', "levels"),
    ('feasible_with = "full_service"', 'feasible_with = "full"', "feasible_with"),
    ('axles = 4 }\n\n[[controllers]]', 'axles = 4 }\npid = { error = "d_go", kp = "kp", '
     'ki = "kp", kd = "kp" }\n\n[[controllers]]', "no pid"),
]


@pytest.mark.parametrize("old,new,word", BAD)
def test_bad_module_input_exit_2(tmp_path, capsys, old, new, word):
    text = CLOSED.read_text()
    assert old in text, old
    p = tmp_path / CLOSED.name
    p.write_text(text.replace(old, new, 1))
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_axles_need_a_loop(tmp_path, capsys):
    text = (ROOT / "designs" / "stop-accuracy-004-ato.toml").read_text()
    p = tmp_path / "stop-accuracy-004-ato.toml"
    p.write_text(text.replace('parameters = { v_ho = 1000.0 }',
                              'parameters = { v_ho = 1000.0 }\naxles = "oooo"', 1))
    assert main(["verify", str(p)]) == 2
    assert "no controller has a deceleration_loop" in capsys.readouterr().err

