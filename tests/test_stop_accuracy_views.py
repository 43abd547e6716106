"""General pieces of the stop-accuracy kind that paper analyses share, on its
synthetic design (no paper): the nominal stops tracking a ``[reference]``
with their oscillation counts
(:func:`workbench.kinds.stop_accuracy.tracked_stops.tracked_stops`) and a
result wrapping the kind's run that names the kind's quantities its own way
(:mod:`workbench.kinds.stop_accuracy.kind_view`)."""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest

from workbench.design import load_design
from workbench.features.quantities import Declared, values
from workbench.kinds.stop_accuracy.kind_view import KindView, kind_quantity, per_speed
from workbench.kinds.stop_accuracy.loop_damping import sign_changes
from workbench.kinds.stop_accuracy.modules import Reference
from workbench.kinds.stop_accuracy.run import compile_laws, run
from workbench.kinds.stop_accuracy.tracked_stops import tracked_stops

SYNTH = Path(__file__).resolve().parent.parent / "designs" / "stop-accuracy-synthetic.toml"


@pytest.fixture(scope="module")
def spec():
    return replace(load_design(SYNTH).spec, montecarlo=None, convergence=False)


def test_tracked_stops_follow_the_reference_and_count_sign_changes(spec):
    tracked = replace(spec, reference=Reference(60 / 3.6, 0.5, 0.6944))
    laws = compile_laws(tracked)
    both = tracked_stops(tracked, laws, ["held", "profile"], 60.0, 200.0, track_share=0.8,
                         deadband=0.05)
    assert list(both) == ["held", "profile"]
    alone = tracked_stops(tracked, laws, ["profile"], 60.0, 200.0, track_share=0.8,
                          deadband=0.05)["profile"]
    st = both["profile"]
    assert st.error == alone.error                      # a run does not depend on its batch
    assert st.v[0] == pytest.approx(st.v_d[0])          # the run starts where the target brakes
    assert st.dx[0] == pytest.approx(-st.v_d[0] ** 2 / (2 * 0.6944), rel=1e-6)
    stopped = np.flatnonzero(st.v == 0.0)[0]
    assert st.dx[stopped] == pytest.approx(st.error, abs=1e-6)
    plan = tracked.reference.braking(200.0, st.t)[2]
    err = (st.v - st.v_d)[st.t < 0.8 * plan]
    assert st.sign_changes == sign_changes(err, 0.05)
    assert tracked_stops(tracked, laws, ["profile"], 60.0, 200.0, track_share=0.8,
                         deadband=1e3)["profile"].sign_changes == 0   # all inside the dead band


@dataclass(frozen=True)
class Renamed(KindView):
    kind: object


def test_kind_view_names_the_kinds_quantities_its_own_way(spec):
    res = Renamed(run(spec))
    assert res.spec is spec and res.distance == res.kind.distance
    assert res.tolerance == spec.tolerance
    table = (Declared("{b}.steady.abs_m", "m", kind_quantity("{b}.held.nominal_m", abs),
                      over=per_speed()),
             Declared("{b}.{m}.nominal_m", "m", kind_quantity("{b}.{c}.nominal_m"),
                      over=per_speed({"m": "a", "c": "held"}, {"m": "b", "c": "profile"})))
    q = values(table, spec, res)
    assert list(q) == ["v60.steady.abs_m", "v60.a.nominal_m", "v60.b.nominal_m"]
    assert q["v60.steady.abs_m"] == abs(res.kind.nominal[60.0, "held"])
    assert q["v60.b.nominal_m"] == res.kind_values["v60.profile.nominal_m"]
    assert kind_quantity("x")(type("R", (), {"kind_values": {"x": None}})()) is None
