"""CLI verbs by capability (issue 35, item 3), and ``simulate`` / ``sweep`` of
a ``switched-run`` design (item 1): a kind declares what it can do
(:mod:`workbench.kinds.capabilities`); a verb on a design without it says
what is missing, one line, exit 2."""
from __future__ import annotations

import ast
import csv
import dataclasses
import importlib
import inspect
import json
import math
from pathlib import Path

import numpy as np
import pytest

from workbench import kinds
from workbench.cli import main
from workbench.design import load_design
from workbench.features.montecarlo import draw
from workbench.kinds.capabilities import CAPABILITIES, NEEDS

from test_switched_run import GUARD, MC, write

ROOT = Path(__file__).resolve().parents[1]


def test_every_capability_is_a_kind_with_a_command_taking_the_design():
    for kind, verbs in CAPABILITIES.items():
        assert kind in kinds.STUDIES
        for verb, target in verbs.items():
            assert verb in NEEDS
            module, attr = target.split(":")
            fn = getattr(importlib.import_module(module), attr)
            assert next(iter(inspect.signature(fn).parameters)) == "design"


def test_cli_names_no_kind():
    """The verbs do not branch on the kind: no kind's name is a string of cli.py."""
    tree = ast.parse((ROOT / "workbench" / "cli.py").read_text(encoding="utf-8"))
    words = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant)
             and isinstance(n.value, str)}
    assert not words & set(kinds.STUDIES)


@pytest.mark.parametrize("argv, words", [
    (["simulate", "designs/delay-benchmarks.toml"],
     "design delay-benchmarks (kind delay-benchmark) has no simulate: it needs [[scenarios]]"),
    (["sweep", "designs/delay-benchmarks.toml", "--samples", "2", "--seed", "1"],
     "kinds with sweep: antiskid-run, delay-feedback, stop-accuracy, switched-run"),
    (["synthesize", "delay-bound", "designs/emu-speed-switched-run.toml"],
     "(kind switched-run) has no synthesize delay-bound"),
    (["simulate", "designs/emu-speed-switched-run.toml", "--plot", "x.png"],
     "(kind switched-run) has no simulate --plot"),
    (["sweep", "designs/emu-speed-switched-run.toml", "--samples", "2", "--seed", "1",
      "--workers", "2"], "has no sweep --workers"),
])
def test_missing_capability_is_one_line_exit_2(capsys, monkeypatch, argv, words):
    monkeypatch.chdir(ROOT)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert words in err and err.count("\n") == 1 and "Traceback" not in err


def test_switched_run_simulate_writes_the_trajectory(tmp_path, capsys):
    """x' = 1 until x >= 1 m (binary-exact steps of 1/8 s), then hold."""
    p = write(tmp_path, GUARD.replace("H", "0.25"))
    out = tmp_path / "run.csv"
    assert main(["simulate", str(p), "--csv", str(out), "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    rows = list(csv.reader(out.read_text(encoding="utf-8").splitlines()))
    assert rows[0] == ["t", "x", "u", "phase"]
    assert rows[-1][-1] == "hold" and float(rows[-1][1]) == res["metrics"]["final.x"]
    assert float(rows[-1][0]) == 2.0 and len(rows) == 2 + 16
    assert main(["simulate", str(p), "--dt", "0.1"]) == 2       # h = 0.25 s: not a multiple
    assert "--dt = 0.1" in capsys.readouterr().err
    assert main(["simulate", str(p), "--case", "nope"]) == 2


def test_switched_run_sweep_is_seeded_chunked_and_resumable(tmp_path, capsys):
    """x(1) = (1 - 0.5 g)^2 <= 0.3 exactly when g >= 2 (1 - sqrt(0.3))
    (tests/test_switched_run.py), g drawn with --samples and --seed."""
    p = write(tmp_path, MC.replace("SAMPLES", "50").replace("SEED", "7"))
    d = load_design(p)
    g = draw(dataclasses.replace(d.spec.montecarlo, samples=120, seed=3),
             tuple(d.spec.plant.parameters), d.spec.plant.values())["g"]
    want = int(np.sum(g >= 2 * (1 - math.sqrt(0.3))))
    args = ["sweep", str(p), "--samples", "120", "--seed", "3", "--json"]
    assert main(args) == 0
    whole = json.loads(capsys.readouterr().out)
    assert whole["claims"]["small"]["passes"] == want and whole["claims"]["small"]["n"] == 120
    folder = tmp_path / "out"
    assert main(args + ["--out", str(folder)]) == 0
    assert json.loads(capsys.readouterr().out) == whole
    chunks = sorted(folder.glob("s-chunk-*.csv"))
    assert [c.name for c in chunks] == ["s-chunk-0000.csv", "s-chunk-0001.csv",
                                        "s-chunk-0002.csv"]
    kept = chunks[0].read_text(encoding="utf-8")
    chunks[1].unlink()
    assert main(args + ["--out", str(folder)]) == 2              # not empty, no --resume
    capsys.readouterr()
    assert main(args + ["--out", str(folder), "--resume"]) == 0
    assert json.loads(capsys.readouterr().out) == whole
    assert chunks[1].is_file() and chunks[0].read_text(encoding="utf-8") == kept
    other = ["sweep", str(p), "--samples", "120", "--seed", "4", "--out", str(folder),
             "--resume"]
    assert main(other) == 2                                       # another sweep's folder
    assert "sweep.json" in capsys.readouterr().err
    assert main(["sweep", str(p), "--samples", "120", "--seed", "3", "--resume"]) == 2


#: A [montecarlo] table drawing the pendulum's ``a`` (the delay-feedback sweep tests).
DRAW_A = ('\n[montecarlo]\nsamples = 5\nseed = 1\n[montecarlo.distributions]\n'
          'a = { dist = "uniform", lo = 1.5, hi = 2.5, source = "test" }\n')


def test_delay_feedback_sweep_draws_the_plant(tmp_path, capsys):
    """x' = -a sin(x) + u at x = 0.5 rad, a drawn: the sweep's largest errors
    are those of its draws (the same numbers for the same seed; others for
    another), and a design without [montecarlo] has no sweep."""
    from test_delay_feedback import write as write_feedback
    scen = ('\n[[scenarios]]\nname = "kick"\nx0 = { x = 0.7 }\nt_end = 2.0\ndt = 0.02\n')
    p = write_feedback(tmp_path, extra=scen + DRAW_A)
    args = ["sweep", str(p), "--samples", "8", "--seed", "3", "--json"]
    assert main(args) == 0
    one = json.loads(capsys.readouterr().out)["quantities"]
    assert one["montecarlo.kick.runs"] == 8 and one["montecarlo.kick.diverged"] == 0
    assert 0.19 < one["montecarlo.kick.max.peak_error.x"] <= 0.2 + 1e-12
    assert main(args) == 0
    assert json.loads(capsys.readouterr().out)["quantities"] == one
    assert main(args[:-2] + ["4", "--json"]) == 0
    other = json.loads(capsys.readouterr().out)["quantities"]
    assert other["montecarlo.kick.max.final_error.x"] != one["montecarlo.kick.max.final_error.x"]
    bare = write_feedback(tmp_path, name="bare", extra=scen)
    assert main(["sweep", str(bare), "--samples", "8", "--seed", "3"]) == 2
    assert "(kind delay-feedback) has no sweep: it needs a [montecarlo] table" in \
        capsys.readouterr().err


def test_delay_feedback_sweep_is_chunked_and_resumable(tmp_path, capsys):
    """``sweep --out/--resume`` of a delay-feedback design: 120 draws in
    three chunk files per scenario, the summary equal to the one-batch
    sweep's (to 1e-12: the gain's matrix product may round differently for
    another batch width), a deleted chunk rewritten byte for byte."""
    from test_delay_feedback import write as write_feedback
    scen = ('\n[[scenarios]]\nname = "kick"\nx0 = { x = 0.7 }\nt_end = 1.0\ndt = 0.05\n')
    p = write_feedback(tmp_path, extra=scen + DRAW_A)
    args = ["sweep", str(p), "--samples", "120", "--seed", "3", "--json"]
    assert main(args) == 0
    whole = json.loads(capsys.readouterr().out)["quantities"]
    folder = tmp_path / "out"
    assert main(args + ["--out", str(folder)]) == 0
    got = json.loads(capsys.readouterr().out)["quantities"]
    assert got.keys() == whole.keys() and got["montecarlo.kick.runs"] == 120
    assert all(got[k] == pytest.approx(v, rel=1e-12, abs=0.0) for k, v in whole.items())
    chunks = sorted(folder.glob("*.csv"))
    assert [c.name for c in chunks] == [f"kick-chunk-000{k}.csv" for k in range(3)]
    assert chunks[0].read_text(encoding="utf-8").splitlines()[0].startswith("a,peak_error.x,")
    kept = chunks[2].read_text(encoding="utf-8")
    chunks[2].unlink()
    assert main(args + ["--out", str(folder)]) == 2              # not empty, no --resume
    capsys.readouterr()
    assert main(args + ["--out", str(folder), "--resume"]) == 0
    assert json.loads(capsys.readouterr().out)["quantities"] == got
    assert chunks[2].read_text(encoding="utf-8") == kept
    assert main(["sweep", str(p), "--samples", "120", "--seed", "4", "--out", str(folder),
                 "--resume"]) == 2                                # another sweep's folder
    assert "sweep.json" in capsys.readouterr().err
    assert main(["sweep", str(p), "--samples", "120", "--seed", "3", "--resume"]) == 2
