"""Paper 000's station stops as a ``stop-accuracy`` configuration (issue 35,
item 2): designs/stop-accuracy-000-line5.toml, with the named modules
``smarc``, ``predictor`` and ``terminal`` (workbench/kinds/stop_accuracy/modules.py),
gives the stop errors of designs/stopping-line5.toml's study bit for bit, and
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
#: stopping-line5's variant -> the configuration's controller.
SHARED = {"pid": "pid", "pid-damped": "pid_damped", "smc": "smc", "smarc": "smarc",
          "pid-comp": "pid_comp", "smc-comp": "smc_comp", "smarc-comp": "smarc_comp",
          "smarc-comp-nogain": "smarc_comp_nogain"}


def test_line5_configuration_is_stopping_line5():
    """Every controller of stopping-line5's nominal row and Monte Carlo, on
    the nominal plant and on 3 draws of its [montecarlo], stops where the
    paper study's stops, to the last bit (all 200 draws are equal too:
    reports/stop-accuracy-000-line5.md prints stopping-line5's rates). The
    PID with feed-forward and the SMC of eq 22 are expressions here, SMARC
    and the compensation named modules. The study runs its laws through the
    kind too (``station_stopping_run.kind_spec``), so this checks that the
    design file (constants, factor order, modules, start, clip range)
    configures what the study runs."""
    from workbench.papers.p000.station_stopping_run import _runset, _concat, simulate_runs
    from workbench.features.montecarlo import draw
    from workbench.papers.p000.station_stopping_spec import MC_FACTORS, NOMINAL
    from workbench.kinds.stop_accuracy.run import (compile_laws, montecarlo_draws,
                                                   simulate_cases)
    spec = load_design(LINE5).spec
    N = 3
    # one batch: draw 0 at the nominal factors (x * 1.0 == x: the nominal plant), then N draws
    drawn = montecarlo_draws(spec, dataclasses.replace(spec.montecarlo, samples=N))
    draws = {f.name: np.concatenate([[f.nominal], drawn[f.name]]) for f in spec.factors
             if f.name in drawn}
    (speed,) = spec.speeds_kmh
    cases = [(speed, i, None, spec.distance) for i in range(len(spec.controllers))]
    tr, D = simulate_cases(spec, compile_laws(spec), spec.dt, cases, draws)
    mine = (tr.x_stop - D).reshape(len(cases), N + 1)
    names = [c.name for c in spec.controllers]
    l5 = load_design(ROOT / "designs" / "stopping-line5.toml").spec
    l5 = dataclasses.replace(l5, montecarlo=dataclasses.replace(l5.montecarlo, samples=N))
    L = l5.sections[0].length
    d = draw(l5.montecarlo, tuple(MC_FACTORS), NOMINAL)
    nom = list(SHARED)
    rs = _concat(_runset(nom, "nom", [0] * len(nom), [0] * len(nom), [L] * len(nom), {}),
                 *(_runset([v] * N, "mc", [0] * N, np.arange(N), [L] * N, d) for v in nom))
    tr = simulate_runs(l5, rs)[0]
    err = tr.x_stop - rs["length"]
    assert f"v{speed:g}" == "v79.9992" and spec.distance == L and list(SHARED.values()) == names
    for v, c in SHARED.items():
        got = mine[names.index(c)]
        nominal = err[(rs["kind"] == "nom") & (rs["variant"] == v)]
        assert got[0] == nominal[0], c
        mc = err[(rs["kind"] == "mc") & (rs["variant"] == v)]
        assert got[1:].tolist() == mc.tolist(), c
    assert mine[names.index("smarc"), 0] > 0.1 > abs(mine[names.index("smarc_comp"), 0])
    res = run(dataclasses.replace(spec, montecarlo=None, controllers=spec.controllers[3:4],
                                  sections=None))
    assert res.nominal[speed, "smarc"] == mine[names.index("smarc"), 0]


def test_line5_sections_are_stopping_line5_repeats():
    """The kind's [[sections]] and [repeats] give stopping-line5's per-section
    repeats (Tables 3-4) repeat by repeat, to the last bit (2 sections x 2
    repeats; the whole 7 x 10 table: reports/stop-accuracy-000-line5.md
    prints stopping-line5's 99.3, 149 and 28.7 cm). The error statistics are
    the same arithmetic on the same errors (equal); the jerk is averaged over
    each batch's records, whose length depends on the batch (to 1e-12)."""
    from workbench.kinds.stop_accuracy.run import run_sections
    from workbench.kinds.stop_accuracy.run import compile_laws
    from workbench.papers.p000.station_stopping_run import run_station_stops
    spec = load_design(LINE5).spec
    rp = dataclasses.replace(spec.sections, sections=spec.sections.sections[:2], count=2)
    spec = dataclasses.replace(spec, sections=rp)
    mine = run_sections(spec, compile_laws(spec), spec.dt)
    l5 = load_design(ROOT / "designs" / "stopping-line5.toml").spec
    l5 = dataclasses.replace(l5, sections=l5.sections[:2], repeats=2)
    ref = run_station_stops(l5, extras=False).stats
    assert rp.controllers == ("pid", "smc", "smarc") and len(mine) == 2 * 3
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
