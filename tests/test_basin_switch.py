"""The general switch checks (workbench.features.basin_switch) on a toy switched
run (no paper): phase 1 drives z' = 1 from z0 for t_s seconds, then the law of
phase 2 takes over with the loop z' = -z + z^3, whose basin is |z| < 1."""
import math
from types import SimpleNamespace

import sympy as sp

from workbench.features import basin_points as BP
from workbench.features.basin_loop import modal_problem
from workbench.features.basin_scalar import scalar_verdict
from workbench.features.basin_switch import (switch_quantities, switch_quantity_names,
                                             switch_states)
from workbench.features.basin_trajectory import limit_event
from workbench.outcome import Outcome

Z = sp.symbols("z", real=True)
G = -Z + Z**3


def _case(name, z0, t_s):
    """A toy case: its state where phase 2 takes over (nan: it never switched)."""
    return SimpleNamespace(name=name, z_switch=z0 + t_s)


CASES = [_case("near", 0.1, 0.4), _case("far", 0.2, 1.3), _case("never", 0.0, math.nan)]
LABELS = [c.name for c in CASES]


def _make(p, xs):
    return modal_problem([G], (Z,), (0.0,), [[-1.0]], [p], names=("z",), points=xs,
                         domain=((-3.0,), (3.0,)), c_search=math.inf)


def _judge(x):
    """Best verdict and fate of phase 2's loop from the switch state x."""
    fn = sp.lambdify((Z,), [G], "math")
    v = BP.point_in_basin((1.0,), _make, x, fn, 20.0, events=[limit_event(0, 3.0)])
    return v.outcome, v.fate


def test_switch_states_leave_out_cases_that_never_switched():
    pts = switch_states(CASES, lambda c: (c.name, (c.z_switch,)))
    assert pts == [("near", (0.5,)), ("far", (1.5,))]
    assert all(type(v) is float for _, x in pts for v in x)


def test_switch_verdicts_and_quantities_of_a_toy_switched_run():
    pts = switch_states(CASES, lambda c: (c.name, (c.z_switch,)))
    judged = {"phase2": [(lab, *_judge(x)) for lab, x in pts]}
    # the frozen one-state verdict agrees on both switch states
    assert [scalar_verdict(G, Z, x[0], -3.0, 3.0, name="z").outcome for _, x in pts] == [
        Outcome.CERTIFIED, Outcome.REFUTED]
    q = switch_quantities(LABELS, judged)
    assert set(q) == switch_quantity_names(LABELS, ("phase2",))
    assert q["switch.phase2[near].in_basin"] == "CERTIFIED"
    assert q["switch.phase2[near].fate"] == "converges"
    assert (q["switch.phase2[far].in_basin"], q["switch.phase2[far].fate"]) == (
        "REFUTED", "diverges")
    assert q["switch.phase2[never].in_basin"] is None and q["switch.phase2[never].fate"] is None


def test_switch_quantities_of_two_switches_and_none_judged():
    q = switch_quantities(["a", "b"], {"s1": [("a", Outcome.INCONCLUSIVE, "undecided")],
                                       "s2": []})
    assert q["switch.s1[a].in_basin"] == "INCONCLUSIVE" and q["switch.s1[b].fate"] is None
    assert all(q[f"switch.s2[{c}].{f}"] is None for c in "ab" for f in ("in_basin", "fate"))
    assert len(q) == len(switch_quantity_names(["a", "b"], ("s1", "s2"))) == 8


def test_gain_sweep_quantities_of_a_toy_sweep():
    """z = 0.5 of z' = -g0 z + g1 z^3 is certified iff g1 < 4 g0 (g0 = 1 kept)."""
    def judge(gain):
        f = [-sp.Float(gain[0]) * Z + sp.Float(gain[1]) * Z**3]

        def make(p, xs):
            return modal_problem(f, (Z,), (0.0,), [[-gain[0]]], [p], names=("z",), points=xs,
                                 domain=((-3.0,), (3.0,)), c_search=math.inf)
        fn = sp.lambdify((Z,), f, "math")
        return BP.point_in_basin((1.0, 2.0), make, (0.5,), fn, 20.0,
                                 events=[limit_event(0, 3.0)])
    sw = BP.sweep_gain_entry(judge, (0.5,), (1.0, 0.0), 1, [0.5, 2.0, 8.0], bisect=2,
                             compare=[("ok", (1.0, 1.0)), ("bad", (1.0, 9.0))])
    q = BP.gain_sweep_quantities(sw, "g1")
    assert set(q) == BP.gain_sweep_quantity_names("g1")
    assert 2.0 <= q["basin.g1_safe_max"] < 4.0 < q["basin.g1_unsafe_min"] <= 8.0
    assert q["basin.compared_certified"] == 1
    none = BP.GainSweep((0.5,), (1.0, 0.0), 1, sw.rows, (), None, 0.5, False)
    assert BP.gain_sweep_quantities(none, "g1") == {
        "basin.g1_safe_max": None, "basin.g1_unsafe_min": None, "basin.compared_certified": 0}
