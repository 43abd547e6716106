"""The ``stop-accuracy`` kind (issue 35, items 1-2): the shared stop-error
pipeline, laws written in the design file (units checked, never evaluated),
faults, Monte Carlo, convergence, bad input (exit 2), and paper 004's ATO open
loop as a configuration that reproduces the ``closed-loop-brake`` study."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds import REGISTRY
from workbench.kinds.stop_accuracy.pipeline import Factor, apply_factors, group_statistics
from workbench.kinds.stop_accuracy.run import run, stopping_points

ROOT = Path(__file__).resolve().parent.parent
ATO = ROOT / "designs" / "stop-accuracy-004-ato.toml"
SYNTH = ROOT / "designs" / "stop-accuracy-synthetic.toml"


def _small(spec, samples=None, speeds=None, convergence=False):
    mc = spec.montecarlo
    if samples is not None:
        mc = dataclasses.replace(mc, samples=samples)
    return dataclasses.replace(spec, montecarlo=mc if samples != 0 else None,
                               speeds_kmh=speeds or spec.speeds_kmh, convergence=convergence)


def test_apply_factors_order_and_effects():
    base = {"K1": 2.0, "P1": 3.0, "T1": 0.5}
    fs = (Factor("air", "scale", ("K1",)), Factor("gain", "scale", ("K1", "P1")),
          Factor("grad", "gradient"), Factor("mass", "mass_ratio"))
    x = lambda v: np.array([v, 1.0])
    over, theta, kappa = apply_factors(base, fs, {"air": x(3.0), "gain": x(5.0),
                                                  "grad": x(-2.0), "mass": x(4.0)}, 2)
    assert over["K1"].tolist() == [2.0 * 3.0 * 5.0, 2.0] and over["P1"].tolist() == [15.0, 3.0]
    assert "T1" not in over and theta.tolist() == [-2.0, 1.0] and kappa.tolist() == [0.25, 1.0]
    over, theta, kappa = apply_factors(base, (Factor("fe", "force_error"),),
                                       {"fe": x(0.1)}, 2)
    assert over == {} and theta.tolist() == [0.0, 0.0] and kappa.tolist() == [1.1, 2.0]
    st = group_statistics([0.1, 0.5, np.nan, -0.2], ["a", "b"], 2, 0.3)
    assert (st["a"].k, st["a"].n, st["b"].k) == (1, 2, 1) and st["b"].overshoot == 0.5


def test_ato_open_reproduces_closed_loop_brake():
    """The configuration's laws, factors and stopping points give paper 004's
    ATO open-loop stop errors draw by draw, bit for bit (10 draws, 50 km/h;
    all 200 draws at both speeds are equal too, 166/200 and 164/200 within
    0.3 m, as reports/closed-loop-brake-004.md prints)."""
    from workbench.papers.p004.closed_loop_brake_run import run_montecarlo
    d = load_design(ATO)
    spec = _small(d.spec, samples=10, speeds=(50.0,))
    res = run(spec)
    p4 = load_design(ROOT / "designs" / "closed-loop-brake-004.toml").spec
    p4 = dataclasses.replace(p4, speeds_kmh=(50.0,),
                             montecarlo=dataclasses.replace(p4.montecarlo, samples=10))
    D = stopping_points(p4)[50.0]
    assert res.distance[50.0] == D
    ref = run_montecarlo(p4, {50.0: D})[50.0, "ato-open"]
    got = res.mc[50.0, "ato_open"]
    np.testing.assert_array_equal(got.errors, ref.errors)      # bit for bit
    assert (got.k, got.n) == (ref.k, ref.n)
    assert res.nominal[50.0, "open"] == pytest.approx(0.0, abs=1e-9)


TIGHT = """
[[claims]]
id = "held-tight"
description = "a tolerance below the step's error: not converged"
quantity = "v60.held.nominal_m"
compare = "within"
value = 2.936
tolerance = 0.00001
source = "test"

[[faults]]
name = "downhill"
disturbance = { gradient = -10.0 }

[grid]
gradient = [-10.0, 0.0]
"""


def test_synthetic_design_claims_and_features(tmp_path):
    from workbench.outcome import Verdict
    from workbench.verify import evaluate_design
    p = tmp_path / SYNTH.name
    p.write_text(SYNTH.read_text() + TIGHT)
    d = load_design(p)
    d = dataclasses.replace(d, spec=_small(d.spec, samples=6, convergence=True))
    ev = evaluate_design(d)
    verdict = {r.claim.id: r for r in ev.claims}
    assert verdict["held-tight"].verdict is Verdict.INCONCLUSIVE
    assert "not converged" in verdict["held-tight"].note
    assert verdict["profile-nominal"].verdict is Verdict.PASS
    study, res = REGISTRY["stop-accuracy"], ev.result
    q = study.quantities(res)
    assert set(q) == study.quantity_names(d.spec)
    # the held command does not read the speed: a sensor fault cannot move its stop
    assert q["v60.held.fault[speed_high].change_m"] == 0.0
    assert q["v60.held.fault[electric_loss].error_m"] > 10.0
    # a down-grade lengthens the held command's stop
    assert q["v60.held.fault[downhill].error_m"] > q["v60.held.nominal_m"] + 1.0
    assert abs(q["v60.profile.nominal_m"]) < 0.5
    # the grid's corners are the nominal run and the down-grade fault again
    assert res.grid[60.0, "held"] == (q["v60.held.fault[downhill].error_m"],
                                      q["v60.held.nominal_m"])
    assert q["v60.held.grid.failing_corners"] == 2.0
    assert q["v60.held.grid.max_abs_m"] == q["v60.held.fault[downhill].error_m"]
    assert res.mc[60.0, "profile"].n == 6
    assert len(res.levels) == 3 * 4 and all(len(v) == 3 for v in res.levels.values())
    assert q["v60.profile.convergence.estimate_m"] < 0.01
    # the named module pid: with zero gains it is the law alone
    zero = dataclasses.replace(d.spec, speeds_kmh=(60.0,), montecarlo=None, convergence=False,
                               faults=(), grid=(), constants=d.spec.constants | {
                                   k: dataclasses.replace(d.spec.constants[k], value=0.0)
                                   for k in ("k_v", "k_i")})
    plain = dataclasses.replace(zero, controllers=tuple(
        dataclasses.replace(c, pid=None) for c in zero.controllers))
    a, b = run(zero), run(plain)
    assert a.nominal[60.0, "profile_pid"] == b.nominal[60.0, "profile_pid"]
    assert res.nominal[60.0, "profile_pid"] != res.nominal[60.0, "profile"]
    units = study.quantity_units(d.spec)
    assert units["v60.profile.mc.p95_abs_m"] == "m" and units["v60.held.mc.p_within"] == "1"


def _design(tmp_path, text: str, old: str, new: str) -> Path:
    assert old in text, old
    p = tmp_path / "stop-accuracy-synthetic.toml"
    p.write_text(text.replace(old, new, 1))
    return p


BAD = [
    ('law = "a_ref"', 'law = "a_ref*k_v"', "brake_command, m / s ** 2; found m / s ** 3"),
    ('law = "a_ref"', 'law = "__import__(1)"', "__import__"),             # not whitelisted
    ('law = "a_ref"', 'law = "a_ref + speed"', "speed"),                  # unknown name
    ('law = "a_ref"', 'law = "a_ref*log(0)"', "real, finite"),
    ('law = "a_ref"', 'law = "a_ref*sqrt(0 - 1)"', "real, finite"),
    ('speeds_kmh = [60.0]', 'speeds_kmh = [60.0, 60.0]', "distinct"),
    ('parameters = ["T1", "T3"]', 'parameters = 3', "brake parameters"),
    ('distance = { value = 200.0, unit = "m"', 'distance = { value = 200.0, unit = "km"', '"m"'),
    ('parameters = ["T1", "T3"]', 'parameters = ["T9"]', "brake parameters"),
    ('parameters = { v_ho = 1000.0 }', 'parameters = { v_hx = 1000.0 }', "brake parameter"),
    ('dt_ctrl = 0.1', 'dt_ctrl = 0.015', "multiple"),
    ('kp = "k_v"', 'kp = "k_q"', "k_q"),                                  # not a constant
    ('ki = "k_i"', 'ki = "k_v"', "controllers[2].pid.ki"),                # gain of a wrong unit
    ('[convergence]', '[grid]\nwind = [1.0]\n\n[convergence]', "a factor of [disturbances]"),
    ('[convergence]', '[grid]\ngradient = [1.0, 1.0]\n\n[convergence]', "distinct"),
    ('[convergence]', '[grid]\nmass_ratio = [0.0, 1.0]\n\n[convergence]', "above 0"),
    ('effect = "mass_ratio"', 'effect = "force_error"', None),            # fine alone
    ('[convergence]', '[[sections]]\nname = "a"\nlength = { value = 100.0, unit = "m", '
     'source = "x" }\n\n[convergence]', "with a [reference]"),         # sections: a tracking law
]


@pytest.mark.parametrize("old,new,word", BAD)
def test_bad_input_exit_2(tmp_path, capsys, old, new, word):
    p = _design(tmp_path, SYNTH.read_text(), old, new)
    if word is None:
        load_design(p)
        return
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_mc_factor_must_be_declared(tmp_path, capsys):
    p = _design(tmp_path, SYNTH.read_text(), 'gradient   = { dist = "uniform"',
                'wind = { dist = "uniform"')
    assert main(["verify", str(p)]) == 2 and "wind" in capsys.readouterr().err


def test_distance_or_command_exactly_one(tmp_path, capsys):
    p = _design(tmp_path, SYNTH.read_text(), 'c_max =',
                'command = { value = 0.7, unit = "m/s^2", source = "x" }\nc_max =')
    assert main(["verify", str(p)]) == 2 and "exactly one" in capsys.readouterr().err


def test_monte_carlo_report_pieces_on_a_non_paper_design():
    """The Monte Carlo table pieces papers 000 and 004 share
    (kinds/stop_accuracy/render.py) on the synthetic design: every distribution
    with its factor's meaning and unit; the statistics cells; the ECDF steps."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbench.features.montecarlo import stop_statistics
    from workbench.kinds.stop_accuracy.render import (distribution_table, mc_cells, plot_ecdf,
                                                      tolerance_lines)
    spec = load_design(SYNTH).spec
    table = distribution_table(spec).splitlines()
    factor = {f.name: f for f in spec.factors}
    assert len(table) == 2 + len(spec.montecarlo.distributions)
    for k, line in zip(spec.montecarlo.distributions, table[2:]):
        assert f"`{k}`" in line and factor[k].what in line and factor[k].unit in line
    st = stop_statistics([0.1, -0.2, 0.5, 0.25], 0.3)
    assert mc_cells(st, lambda x: f"{x:.2f}")[:2] == ["3 / 4", "0.75"]
    assert mc_cells(st, lambda x: f"{x:.2f}")[4:] == ["0.16", "75"]
    fig, ax = plt.subplots()
    plot_ecdf(ax, [0.5, -0.2, 0.1], color="C0")
    tolerance_lines(ax, 0.3)
    x, y = ax.lines[0].get_data()
    assert list(x) == [-0.2, 0.1, 0.5] and y[-1] == 1.0 and len(ax.lines) == 3
    plt.close(fig)


def test_monte_carlo_section_and_panels_on_a_non_paper_design():
    """The Monte Carlo section and ECDF panels papers 000 and 004 share
    (kinds/stop_accuracy/render.py) on the synthetic design: the heading at the
    asked level with the design's tolerance, the draws and seed, one row per
    member with its key cells and statistics; one panel per group on shared
    axes, an ECDF per member scaled to the unit, the tolerance dashed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbench.features.montecarlo import stop_statistics
    from workbench.kinds.stop_accuracy.render import mc_section, plot_mc_panels
    spec = load_design(SYNTH).spec
    st = stop_statistics([0.1, -0.2, 0.5, 0.25], spec.tolerance)
    text = mc_section(spec, "###", ", a note):", [(("a", "x"), st), (("b", "y"), st)],
                      heads=("key", "group"), align="ll", unit="cm", error=lambda x: "E",
                      alt="alt")
    lines = text.splitlines()
    assert lines[0].startswith("### Monte Carlo: P(|e| ≤ ")
    assert f"{spec.montecarlo.samples} draws (seed {spec.montecarlo.seed};" in text
    assert "a note):" in text and text.endswith("![alt]({figdir}/mc-stop-errors.png)")
    rows = [ln for ln in lines if ln.startswith("| a ") or ln.startswith("| b ")]
    assert len(rows) == 2 and "| x |" in rows[0] and rows[0].count("| E ") == 2
    fig = plt.figure()
    plot_mc_panels(fig, [("one", [("a", [0.1, -0.2])]), ("two", [("a", [0.3]), ("b", [0.0])])],
                   0.3, unit="cm", scale=100)
    one, two = fig.axes
    assert [len(ax.lines) for ax in (one, two)] == [1 + 2, 2 + 2]
    assert list(one.lines[0].get_xdata()) == [-20.0, 10.0]
    assert [ln.get_xdata()[0] for ln in one.lines[1:]] == [-30.0, 30.0]
    assert two.get_shared_x_axes().joined(one, two) and one.get_ylabel() and not two.get_ylabel()
    assert two.get_xlabel() == "stop error (cm, + overshoot)"
    plt.close(fig)


def test_declared_families_on_a_non_paper_design():
    """``over`` and ``mc_family`` (kinds/stop_accuracy/quantities.py) on the
    synthetic design: a family per fixed name, and every Monte Carlo statistic
    of every member with its unit, read from the member's statistics."""
    from workbench.features.montecarlo import MC_QUANTITIES, stop_statistics
    from workbench.features.quantities import names, units, values
    from workbench.kinds.stop_accuracy.quantities import mc_family, over
    spec = load_design(SYNTH).spec
    st = {"a": stop_statistics([0.1, -0.2], 0.3), "b": stop_statistics([0.5], 0.3)}
    table = (mc_family("{c}.mc", over(("a", "b")), lambda r, c: r[c]),)
    assert names(table, spec) == {f"{c}.mc.{k}" for c in "ab" for k in MC_QUANTITIES}
    assert units(table, spec)["a.mc.p95_abs_m"] == "m"
    assert units(table, spec)["b.mc.p_within"] == "1"
    q = values(table, spec, st)
    assert q["a.mc.p_within"] == 1.0 and q["b.mc.p_within"] == 0.0
    assert q["b.mc.mean_m"] == 0.5


def test_error_colours_threshold_at_the_synthetic_tolerance():
    """``error_colours`` (kinds/stop_accuracy/render.py) at the synthetic design's
    tolerance: an |error| just inside it maps to a green, just beyond it to
    orange, beyond three tolerances to the over colour."""
    from matplotlib.colors import to_hex

    from workbench.kinds.stop_accuracy.render import error_colours
    tol = load_design(SYNTH).spec.tolerance
    cmap, norm = error_colours(tol)
    colour = lambda x: to_hex(cmap(norm(x)))
    assert colour(0.99 * tol) == "#a6d96a" and colour(0.1 * tol) == "#1a9850"
    assert colour(1.01 * tol) == "#fdae61"
    assert colour(3.5 * tol) == "#67001f"


@pytest.mark.parametrize("name", ["stopping-line5", "closed-loop-brake-004"])
def test_every_paper_quantity_has_a_unit(name):
    """Papers 000 and 004 declare their quantities once (Declared tables): every
    claimable name has a unit, ``""`` only for the words ``order`` and ``best``
    of paper 000; paper 004's worked numbers are distances, decelerations and
    shares of section 1.3."""
    d = load_design(ROOT / "designs" / f"{name}.toml")
    study = REGISTRY[d.kind]
    got = study.quantity_units(d.spec)
    assert set(got) == study.quantity_names(d.spec)
    assert all(u != "?" for u in got.values())
    assert {n for n, u in got.items() if u == ""} <= {"order", "best"}
    if name == "closed-loop-brake-004":
        assert (got["worked.d1"], got["worked.a2"], got["worked.share[15permille,1]"]) == (
            "m", "m/s^2", "%")
    assert any(u == "m" for u in got.values()) and any(u == "1" for u in got.values())


def test_constant_sweep_through_the_design_value_is_the_nominal_stop():
    """A constant swept through its design value gives the nominal stop bit for
    bit, another value another stop (the general synthetic design)."""
    from workbench.kinds.stop_accuracy.run import constant_sweep
    spec = dataclasses.replace(load_design(SYNTH).spec, montecarlo=None, convergence=False)
    res = run(spec)
    k = spec.constants["k_v"].value
    got = constant_sweep(spec, "profile", "k_v", [k, 2 * k], res.distance)
    assert list(got) == [(x, s) for s in spec.speeds_kmh for x in (k, 2 * k)]
    for s in spec.speeds_kmh:
        assert got[k, s] == res.nominal[s, "profile"]
        assert got[2 * k, s] != got[k, s]
