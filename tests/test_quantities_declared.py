"""Quantities declared once (issue 35, item 3): names, values and units all
expand one table, so they cannot drift apart."""
from __future__ import annotations

from types import SimpleNamespace

from workbench.features.quantities import Declared, Group, names, units, values

SPEC = SimpleNamespace(states=("v", "s"), basin=None)
TABLE = (
    Declared("gain", "1", lambda r: r.gain),
    Declared("peak.{k}", "{unit}", lambda r, k, unit: r.peak.get(k),
             over=lambda spec: [{"k": k, "unit": "m/s" if k == "v" else "m"}
                                for k in spec.states]),
    Group(lambda spec: {"basin.c"}, lambda r: {"basin.c": r.c},
          present=lambda spec: spec.basin is not None),
)


def test_names_values_and_units_expand_the_same_table():
    res = SimpleNamespace(gain=2.5, peak={"v": 0.1}, c=3.0)
    assert names(TABLE, SPEC) == {"gain", "peak.v", "peak.s"}
    q = values(TABLE, SPEC, res)
    assert q == {"gain": 2.5, "peak.v": 0.1, "peak.s": None}     # None: not determined
    assert set(q) == names(TABLE, SPEC)
    assert units(TABLE, SPEC) == {"gain": "1", "peak.v": "m/s", "peak.s": "m"}


def test_a_feature_group_counts_only_when_the_design_has_it():
    spec = SimpleNamespace(states=(), basin=object())
    res = SimpleNamespace(gain=1.0, peak={}, c=3.0)
    assert names(TABLE, spec) == {"gain", "basin.c"}
    assert values(TABLE, spec, res) == {"gain": 1.0, "basin.c": 3.0}
    assert units(TABLE, spec)["basin.c"] == "?"                 # the group declares no unit


def test_a_declared_study_expands_its_table():
    """features.quantities.DeclaredQuantities on a toy study: its quantity
    methods expand the class's TABLE against the spec the result holds."""
    from workbench.features.quantities import DeclaredQuantities

    class Toy(DeclaredQuantities):
        TABLE = TABLE
    res = SimpleNamespace(gain=2.5, peak={"s": 4.0}, c=3.0, spec=SPEC)
    assert Toy().quantity_names(SPEC) == {"gain", "peak.v", "peak.s"}
    assert Toy().quantities(res) == {"gain": 2.5, "peak.v": None, "peak.s": 4.0}


def test_every_delay_feedback_quantity_has_a_unit():
    from workbench.design import load_design
    from workbench.kinds.delay_feedback import STUDY
    d = load_design("tests/data/train-brake-lag-robust.toml")
    got = STUDY.quantity_units(d.spec)
    assert set(got) == STUDY.quantity_names(d.spec)
    assert got["exact_margin"] == "s" and got["synthesis.h_gain"] == "s"
    assert all(u != "?" for n, u in got.items() if not n.startswith(("basin.", "implementation.",
                                                                        "requirements.")))


def test_determined_and_a_part_that_did_not_run():
    """features.quantities.Part on a toy study: a part the design has but that
    did not run (None) leaves each of its names not determined (None: the
    claim INCONCLUSIVE, workbench.claims.check_claim); a part the design does not have
    declares no name. Declared and Group entries of a part read the same way."""
    from workbench.claims import Claim, check_claim
    from workbench.features.quantities import DeclaredQuantities, Part, determined
    from workbench.outcome import Verdict
    assert determined(float("nan")) is None and determined(None) is None
    assert determined(0.0) == 0.0 and determined("yes") == "yes"
    table = (Declared("gain", "1", lambda r: determined(r.gain)),
             Part((Declared("mc.mean", "m", lambda mc: mc.mean),
                   Group(lambda spec: {"mc.runs"}, lambda mc: {"mc.runs": mc.n})),
                  lambda spec: spec.mc, lambda r: r.mc))

    class Toy(DeclaredQuantities):
        TABLE = table

    spec = SimpleNamespace(mc=True)
    ran = SimpleNamespace(spec=spec, gain=float("nan"), mc=SimpleNamespace(n=7, mean=0.5))
    assert Toy().quantities(ran) == {"gain": None, "mc.mean": 0.5, "mc.runs": 7}
    skipped = Toy().quantities(SimpleNamespace(spec=spec, gain=1.0, mc=None))
    assert skipped == {"gain": 1.0, "mc.mean": None, "mc.runs": None}
    claim = Claim("c1", "mean", "mc.mean", "<=", 1.0, 0.0, None, "none", "toy", False, "pass", "")
    assert check_claim(claim, skipped["mc.mean"]).verdict is Verdict.INCONCLUSIVE
    assert check_claim(claim, 0.5).verdict is Verdict.PASS
    assert Toy().quantity_names(spec) == {"gain", "mc.mean", "mc.runs"}
    assert Toy().quantity_units(spec) == {"gain": "1", "mc.mean": "m", "mc.runs": "?"}
    without = SimpleNamespace(mc=False)
    assert Toy().quantity_names(without) == {"gain"} == set(Toy().quantity_units(without))
    assert Toy().quantities(SimpleNamespace(spec=without, gain=1.0, mc=None)) == {"gain": 1.0}
