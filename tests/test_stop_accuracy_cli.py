"""``workbench simulate`` and ``workbench sweep`` of a ``stop-accuracy`` design
(issue 35, items 1 and 3): the case's stop equals the study's, the sweep's
stop errors equal the study's Monte Carlo for the same draws, chunked
``--out`` files equal the one-batch sweep and a resumed sweep rewrites the
same bytes; bad input is one line, exit 2."""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from workbench.cli import main
from workbench.design import load_design
from workbench.kinds.stop_accuracy.run import run

ROOT = Path(__file__).resolve().parent.parent
SYNTH = ROOT / "designs" / "stop-accuracy-synthetic.toml"


def test_simulate_is_the_studys_stop(tmp_path, capsys):
    spec = load_design(SYNTH).spec
    res = run(dataclasses.replace(spec, montecarlo=None, convergence=False,
                                  controllers=spec.controllers[1:2]))
    out = tmp_path / "run.csv"
    assert main(["simulate", str(SYNTH), "--case", "v60.profile", "--json",
                 "--csv", str(out)]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["metrics"]["stop_error_m"] == res.nominal[60.0, "profile"]
    assert got["metrics"]["distance_m"] == 200.0
    rows = out.read_text(encoding="utf-8").splitlines()
    assert rows[0] == "t,x,v,a,command" and rows[1].startswith("0.0,0.0,16.66666")
    assert main(["simulate", str(SYNTH), "--case", "v60.profile.fault[electric_loss]",
                 "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["metrics"]["stop_error_m"] == res.faults[60.0, "profile", "electric_loss"]
    assert main(["simulate", str(SYNTH), "--case", "v50.profile"]) == 2
    assert "--case" in capsys.readouterr().err
    assert main(["simulate", str(SYNTH), "--dt", "0.03"]) == 2      # 0.1 s not a multiple
    assert "--dt = 0.03" in capsys.readouterr().err


def test_sweep_is_the_studys_montecarlo_chunked_and_resumable(tmp_path, capsys):
    spec = load_design(SYNTH).spec
    mc = dataclasses.replace(spec.montecarlo, samples=60, seed=4)
    res = run(dataclasses.replace(spec, montecarlo=mc, convergence=False, faults=()))
    args = ["sweep", str(SYNTH), "--samples", "60", "--seed", "4", "--json"]
    assert main(args) == 0
    whole = json.loads(capsys.readouterr().out)
    assert list(whole["cases"]) == ["v60.held", "v60.profile", "v60.profile_pid"]
    for name, c in whole["cases"].items():
        st = res.mc[60.0, name.split(".")[1]]
        assert (c["within"], c["n"], c["p95_abs_m"], c["mean_m"]) == (st.k, st.n, st.p95,
                                                                      st.mean)
    one = args + ["--case", "v60.profile"]
    folder = tmp_path / "out"
    assert main(one + ["--out", str(folder)]) == 0
    assert json.loads(capsys.readouterr().out)["cases"] == {
        "v60.profile": whole["cases"]["v60.profile"]}
    chunks = sorted(folder.glob("*.csv"))
    assert [c.name for c in chunks] == ["v60.profile-chunk-0000.csv",
                                        "v60.profile-chunk-0001.csv"]
    head = chunks[0].read_text(encoding="utf-8").splitlines()
    assert head[0] == "delay,mass_ratio,gradient,error_m" and len(head) == 51
    kept = chunks[1].read_text(encoding="utf-8")
    chunks[1].unlink()
    assert main(one + ["--out", str(folder)]) == 2                 # not empty, no --resume
    capsys.readouterr()
    assert main(one + ["--out", str(folder), "--resume"]) == 0
    assert chunks[1].read_text(encoding="utf-8") == kept
    assert json.loads(capsys.readouterr().out)["cases"]["v60.profile"] == \
        whole["cases"]["v60.profile"]
    assert main(["sweep", str(SYNTH), "--samples", "60", "--seed", "5", "--case",
                 "v60.profile", "--out", str(folder), "--resume"]) == 2
    assert "sweep.json" in capsys.readouterr().err
    assert main(["sweep", str(SYNTH), "--samples", "60", "--seed", "4", "--resume"]) == 2
    assert main(["sweep", str(SYNTH), "--samples", "60", "--seed", "4", "--case",
                 "v60.profile.fault[speed_high]"]) == 2
    assert "--case" in capsys.readouterr().err
