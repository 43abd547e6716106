"""Paper 000's station stops as a ``stop-accuracy`` configuration (issue 35,
item 2): designs/stop-accuracy-000-line5.toml, with the named modules
``smarc``, ``predictor`` and ``terminal`` (workbench/kinds/stop_accuracy/modules.py),
gives the stop errors of designs/stopping-line5.toml (the same kind with paper 000's
``[analysis]`` module) bit for bit, and
its new tables reject bad input in one line (exit 2)."""
from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds.stop_accuracy.run import run

ROOT = Path(__file__).resolve().parent.parent
LINE5 = ROOT / "designs" / "stop-accuracy-000-line5.toml"
#: stopping-line5's paper name -> the configuration's controller (the same in both files).
SHARED = {"pid": "pid", "pid-damped": "pid_damped", "smc": "smc", "smarc": "smarc",
          "pid-comp": "pid_comp", "smc-comp": "smc_comp", "smarc-comp": "smarc_comp",
          "smarc-comp-nogain": "smarc_comp_nogain"}


def test_line5_configuration_is_stopping_line5():
    """Every controller of stopping-line5's nominal row and Monte Carlo, on
    the nominal plant and on 3 draws of its [montecarlo], stops where
    stopping-line5's (a stop-accuracy design with paper 000's [analysis]
    module) stops, to the last bit (all 200 draws are equal too:
    reports/stop-accuracy-000-line5.md prints stopping-line5's rates). The
    PID with feed-forward and the SMC of eq 22 are expressions here, SMARC
    and the compensation named modules; stopping-line5 adds SMARC with sgn
    and the nominal ablation. Checks that the two files (constants, factor
    order, modules, start, clip range) configure the same stops."""
    from workbench.kinds.stop_accuracy.run import (compile_laws, montecarlo_draws,
                                                   simulate_cases)
    from workbench.papers.p000.station_stopping_spec import VARIANTS

    def stops(spec, names, N=3):
        # one batch: draw 0 at the nominal factors (x * 1.0 == x: the nominal plant), then N
        drawn = montecarlo_draws(spec, dataclasses.replace(spec.montecarlo, samples=N))
        draws = {f.name: np.concatenate([[f.nominal], drawn[f.name]]) for f in spec.factors
                 if f.name in drawn}
        (speed,) = spec.speeds_kmh
        ctl = [c.name for c in spec.controllers]
        cases = [(speed, ctl.index(c), None, spec.distance) for c in names]
        tr, D = simulate_cases(spec, compile_laws(spec), spec.dt, cases, draws)
        return (tr.x_stop - D).reshape(len(cases), N + 1)

    spec = load_design(LINE5).spec
    l5 = load_design(ROOT / "designs" / "stopping-line5.toml").spec
    assert l5.analysis == "p000.station_stopping" and spec.analysis is None
    assert [VARIANTS[k][0] for k in SHARED] == list(SHARED.values())
    mine, theirs = stops(spec, list(SHARED.values())), stops(l5, list(SHARED.values()))
    (speed,) = spec.speeds_kmh
    assert f"v{speed:g}" == "v79.9992" and spec.distance == l5.distance == 1544.0
    assert mine.tolist() == theirs.tolist()
    names = list(SHARED.values())
    assert mine[names.index("smarc"), 0] > 0.1 > abs(mine[names.index("smarc_comp"), 0])
    res = run(dataclasses.replace(spec, montecarlo=None, controllers=spec.controllers[3:4],
                                  sections=None))
    assert res.nominal[speed, "smarc"] == mine[names.index("smarc"), 0]


def test_line5_sections_are_stopping_line5_repeats():
    """The per-section repeats (Tables 3-4) of the two files agree repeat by
    repeat, to the last bit (2 sections x 2 repeats; the whole 7 x 10 table:
    reports/stop-accuracy-000-line5.md prints stopping-line5's 99.3, 149 and
    28.7 cm), and stopping-line5's paper rows are the kind's statistics."""
    from workbench.kinds.stop_accuracy.run import compile_laws, run_sections
    from workbench.papers.p000.station_stopping_run import run_station_stops

    def small(spec):
        rp = dataclasses.replace(spec.sections, sections=spec.sections.sections[:2], count=2)
        return dataclasses.replace(spec, sections=rp)

    spec = small(load_design(LINE5).spec)
    mine = run_sections(spec, compile_laws(spec), spec.dt)
    l5 = small(load_design(ROOT / "designs" / "stopping-line5.toml").spec)
    l5 = dataclasses.replace(l5, montecarlo=dataclasses.replace(l5.montecarlo, samples=2))
    ref = run_station_stops(l5).stats
    assert spec.sections.controllers == ("pid", "smc", "smarc") and len(mine) == 2 * 3
    for (i, c), got in mine.items():
        want = ref[c, i]
        assert got.errors == want.errors, (i, c)
        assert (got.mean_abs, got.mean, got.var, got.max_abs) == (
            want.mean_abs, want.mean, want.var, want.max_abs)
        assert got.jerk_mean == pytest.approx(want.jerk_mean, rel=1e-12)
        assert got.run_time == want.run_time


def _bad(tmp_path, old: str, new: str) -> Path:
    text = LINE5.read_text(encoding="utf-8")
    assert old in text, old
    p = tmp_path / "stop-accuracy-000-line5.toml"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return p


BAD = [
    ('lam    = { value = 0.05,  unit = "s^2/m^2"', 'lam    = { value = 0.05,  unit = "1/s"',
     "s^2/m^2"),
    ('th_max = { value = 1.6', 'th_max = { value = 0.9', "theta_min < 1 < theta_max"),
    ('name = "smarc"\n', 'name = "smarc"\nlaw = "a_d"\n', "without law"),
    ('[target]\n', '[target]\nspeeds_kmh = [80.0]\n', "no speeds with [reference]"),
    ('model = "ato-trapezoid"', 'model = "s-curve"', "ato-trapezoid"),
    ('law = "-a_d"', 'law = "-a_d*x_d"', "m / s ** 2"),                  # unit of a law
    ('gain_bounds = [0.5, 1.5]', 'gain_bounds = [1.2, 1.5]', "lo <= 1 <= hi"),
    ('compensation = { predictor = true, terminal = true }',
     'compensation = { predictor = "yes", terminal = true }', "predictor"),
    ('air_gain   = [0.9, 1.1]', 'wind = [0.9, 1.1]', "a factor of [disturbances]"),
    ('delay      = [0.8, 1.2]', 'delay      = [1.2, 0.8]', "lo <= hi"),
    ('lag        = [0.8, 1.2]', 'lag        = [0.0, 1.2]', "above 0"),
    ('controllers = ["pid", "smc", "smarc"]', 'controllers = ["pid", "pid"]', "each once"),
    ('count = 10', 'count = 1', "repeats per section"),
    ('count = 10', 'count = 2000', "at most 20000 runs"),
    ('length = { value = 1544.0, unit = "m"', 'length = { value = 1544.0, unit = "km"', '"m"'),
    ('[repeats]\n', '[repeat]\n', "repeats.count"),
]


@pytest.mark.parametrize("old,new,word", BAD)
def test_bad_module_input_exit_2(tmp_path, capsys, old, new, word):
    assert main(["verify", str(_bad(tmp_path, old, new))]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_modules_need_their_tables(tmp_path, capsys):
    """A predictor without [compensation], SMARC without [reference]."""
    text = LINE5.read_text(encoding="utf-8")
    start = text.index("[compensation]\n")
    p = tmp_path / LINE5.name
    p.write_text(text[:start] + text[text.index("# The factors"):], encoding="utf-8")
    assert main(["verify", str(p)]) == 2
    assert "a [compensation] table" in capsys.readouterr().err
    synth = ROOT / "designs" / "stop-accuracy-synthetic.toml"
    p = tmp_path / synth.name
    p.write_text(synth.read_text(encoding="utf-8").replace(
        "[disturbances]", '[[controllers]]\nname = "adaptive"\nsmarc = { c = "k_v" }\n\n'
        "[disturbances]"), encoding="utf-8")
    assert main(["verify", str(p)]) == 2
    assert "a [reference] for SMARC to track" in capsys.readouterr().err


@pytest.mark.parametrize("name,old,new,word", [
    ("stopping-line5", 'module = "p000.station_stopping"', 'module = "p000.no_such_module"',
     "ANALYSIS"),
    ("stopping-line5", 'module = "p000.station_stopping"', 'module = "os.path"', "pNNN.name"),
    ("stopping-line5", 'name = "smarc_terminal"', 'name = "smarc_term"',
     "missing: smarc_terminal"),
    ("stopping-line5", 'zeta_min = { value = 0.7,', 'zeta_min = { value = 0.0,', "(0, 1]"),
    ("stopping-line5", '[[published]]\nsection = 1\n', '[[published]]\nsection = 9\n',
     "published[0].section"),
    ("closed-loop-brake-004", 'name = "open"\n', 'name = "held"\n',
     "the controllers open, ato_open"),
    ("closed-loop-brake-004", '[retuning]\n', '[retune]\n', "retuning"),
    ("closed-loop-brake-004", 'gradient_permille = 15.0 #', 'gradient_permille = -15.0 #',
     "worked.gradient_permille"),
    ("closed-loop-brake-004", 'friction = [0.8, 1.0, 1.2]', 'friction = [0.8, 1.0, 0.0]',
     "grid.friction"),
])
def test_bad_analysis_input_exit_2(tmp_path, capsys, name, old, new, word):
    """The kind's [analysis] module and what the paper modules (p000, p004) check
    of their designs: one line, exit 2."""
    src = ROOT / "designs" / f"{name}.toml"
    text = src.read_text(encoding="utf-8")
    assert old in text, old
    p = tmp_path / src.name
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err
    assert word in err and "Traceback" not in err and len(err.strip().splitlines()) == 1
