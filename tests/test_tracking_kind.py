"""The general ``tracking`` kind (issue 35): a user's design (PID only, no
``[[plant_readings]]``, no ``[analysis]``) runs; bad tables exit 2 naming
file, key and value; the kind's runs are the old paper-002 code's bit for bit."""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from workbench.controllers.mfac import MFAC, MFACGains
from workbench.controllers.pid import BatchPID
from workbench.design import load_design
from workbench.errors import DesignError
from workbench.kinds import REGISTRY
from workbench.kinds.tracking import run as R
from workbench.kinds.tracking.spec import quantity_names
from workbench.profiles import build_profile
from workbench.sim.tracking import objectives, simulate_tracking

SYNTH = Path("designs/tracking-synthetic.toml")
P002 = Path("designs/ato-mfac-pid-002.toml")
FIELDS = ("t", "v", "s", "a", "u", "target", "stop_time", "stop_pos", "traction_work")


@pytest.fixture(scope="module")
def synth():
    design = load_design(SYNTH)
    return design, REGISTRY["tracking"].run(design)


def test_synthetic_design_runs_pid_only(synth):
    design, res = synth
    (r,) = res.readings
    assert design.kind == "tracking" and r.reading.name == "nominal"
    assert r.reading.controllers == ("pid",) and r.mfac is None and r.ppd is None
    q = REGISTRY["tracking"].quantities(res)
    assert set(q) == quantity_names(design.spec)        # declared = computed
    assert not any(".mfac" in k or "verdict" in k for k in q)
    # the chosen point stops, is reproducible, and keeps the peak-jerk limit
    tun = r.pid
    assert tun.reproducible[tun.chosen] and np.isfinite(tun.cost[tun.chosen])
    assert q["reading[nominal].pid.peak_jerk"] <= design.spec.peak_jerk.value
    assert len(tun.cost) == 27 and len(r.line) == 1


def _bad(tmp_path, old, new, src=SYNTH):
    text = src.read_text()
    assert old in text
    p = tmp_path / src.name
    p.write_text(text.replace(old, new, 1))
    return p


@pytest.mark.parametrize("old, new, key", [
    ("kp = [0.5, 1.0, 2.0]", "kp = [-0.5, 1.0, 2.0]", "pid.kp"),
    ("kd = [0.0, 0.3, 1.0]", "kd = [0.0, 0.3, 1.0]\nkq = [1.0]", "pid.kq"),
    ("[pid]", "[pidd]", "pid"),
    ('model = "delay-lag-002"', 'model = "first-order-002"', "train.model"),
    ('[requirements]', '[analysis]\nmodule = "p002.nothing"\n\n[requirements]',
     "analysis.module"),
])
def test_bad_tables_name_file_key_value(tmp_path, old, new, key):
    with pytest.raises(DesignError) as exc:
        load_design(_bad(tmp_path, old, new))
    assert exc.value.key == key


def test_bad_value_exits_2_with_one_line(tmp_path):
    p = _bad(tmp_path, "ki = [0.1, 0.3, 0.6]", 'ki = [0.1, "x"]')
    out = subprocess.run([sys.executable, "-m", "workbench", "verify", str(p)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 2
    err = out.stderr.strip()
    assert "\n" not in err and "Traceback" not in err
    assert str(p) in err and "pid.ki" in err and "x" in err


def _old_compare(spec, reading, sec, mg, pg):
    """The paper-002 code before the kind (``ato_tracking_run._compare`` of
    integ c8311bf), verbatim but for the names: MFAC row 0, PID row 1."""
    prof = build_profile(spec.profile_spec(sec), dt=spec.Ts)
    g = MFACGains(**{k: np.asarray(mg[k], float) for k in R.MFAC_KEYS}, epsilon=reading.epsilon)
    mfac = MFAC(g, 1, u_min=reading.train.u_min, u_max=reading.train.u_max)
    pid = BatchPID(*(np.asarray(pg[k], float) for k in R.PID_KEYS), 1, dt=spec.Ts,
                   u_min=reading.train.u_min, u_max=reading.train.u_max)
    ctl = lambda k, y, yn: np.concatenate([mfac.step(y[:1], yn[:1]), pid.step(yn[1:] - y[1:])])
    brake_start = float(prof.t[np.argmax(prof.a < 0)])
    both = simulate_tracking(reading.train, sec.route, prof.speed_at, ctl, 2, Ts=spec.Ts,
                             dt=spec.dt, horizon=sec.run_time + 60.0, brake_start=brake_start)
    return both.rows(slice(0, 1)), both.rows(slice(1, 2))


def _same(a, b):
    for f in FIELDS:
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)


def test_kind_runs_equal_the_old_code_bit_for_bit():
    """Paper 002's design on its shortest line section (980 m), both controllers
    at one grid point: the kind's batch is the old code's, and a PID-only
    reading's run is the PID row of it (rows of a batch are independent)."""
    spec = load_design(P002).spec
    reading = spec.readings[0]
    sec = min(spec.line, key=lambda s: s.route.distance)
    mg = {k: reading.mfac_grid[k][1] for k in R.MFAC_KEYS}
    pg = {k: reading.pid_grid[k][1] for k in R.PID_KEYS}
    cmp, _ = R._compare(spec, reading, sec, {"mfac": mg, "pid": pg})
    old_m, old_p = _old_compare(spec, reading, sec, mg, pg)
    _same(cmp.mfac, old_m)
    _same(cmp.pid, old_p)
    d, T = sec.route.distance, sec.run_time
    np.testing.assert_array_equal(cmp.pid_q.matrix(), objectives(old_p, d, T).matrix())
    from dataclasses import replace
    alone, _ = R._compare(spec, replace(reading, mfac_grid=None, epsilon=None), sec,
                          {"pid": pg})
    assert alone.mfac is None
    K = min(alone.pid.t.size, old_p.t.size)
    for f in ("v", "s", "a", "u"):
        np.testing.assert_array_equal(getattr(alone.pid, f)[:, :K], getattr(old_p, f)[:, :K])
    assert alone.pid.stop_time == old_p.stop_time


def test_simulate_prints_the_chosen_point_and_writes_its_trajectory(synth, tmp_path, capsys):
    from workbench.kinds import capabilities
    design, res = synth
    out = tmp_path / "run.csv"
    assert capabilities.run(design, "simulate", case=None, as_json=True, csv=str(out),
                            dt=None, plot=None) == 0
    import json
    got = json.loads(capsys.readouterr().out)
    r = res.readings[0]
    assert got["gains"] == {"PID": r.pid.chosen_params()}
    assert got["metrics"]["pid.stop_error"] == r.main.value("PID", "stop_error")
    lines = out.read_text().splitlines()
    assert lines[0] == "t,target,v_pid,s_pid,a_pid,u_pid"
    v = np.array([float(x.split(",")[2]) for x in lines[1:]])
    np.testing.assert_array_equal(v, r.main.pid.v[0])      # repr floats read back bit for bit


def test_general_report_without_an_analysis_module(synth):
    from workbench.kinds import renderer
    design, res = synth
    assert design.spec.analysis_module is None
    out = renderer("tracking")(design, res)
    heads = [s.splitlines()[0] for s in out.sections]
    assert heads == ["## Problem", "## Tuning per reading and controller",
                     "## Chosen points on the main pair", "## Line"]
    assert {f.name for f in out.figures} == {"pareto-nominal", "tracking", "jerk", "line"}
    assert "MFAC" not in "".join(out.sections)
    assert "| `nominal` | PID | 27 | 0 |" in out.sections[1]


def test_render_tables_on_a_pid_only_design(synth):
    """The tables a paper's report reuses (kinds/tracking/render_tables) work
    on a non-paper design with one controller: no MFAC column, winner row,
    front dominance, PPD, reset or sensitivity rows."""
    from workbench.kinds.tracking import render_tables as T
    design, res = synth
    (r,) = res.readings
    (row,) = T.tuning_rows(res)
    assert row[:4] == ["`nominal`", "27", "0", str(int(r.pid.front.sum()))]
    assert len(row) == 5 and row[4].startswith("kp = ")
    (cmp,) = T.compare_rows(res)                      # one controller: no winner row
    assert cmp[1] == "PID" and len(cmp) == 2 + 5 + 1
    (best,) = T.best_rows(res)
    assert len(best) == 5 and not any(" / " in x for x in best)
    assert T.dominated_rows(res) == [] and T.ppd_rows(res) == [] and T.reset_rows(res) == []
    assert T.sensitivity_rows(res, ("kp",), {}) == []
    (line,) = T.line_rows(res)
    assert line[1] == r.line[0].section.name and len(line) == 4 + 4
    text = T.comfort_section(design.spec, res)
    assert "| `nominal` | PID |" in text and "| yes |" in text and "MFAC" not in text
    assert T.pct(0.5) == "50 %" and T.pct(None) == "—" and T.span([]) == "—"
    assert T.span([0.25, 0.5, 0.1]) == "10 % … 50 %"


def test_headed_tables_on_a_pid_only_design(synth):
    """The headed tables of kinds/tracking/render_tables on a non-paper design
    with one controller: headings name its controller, no MFAC column; the
    MFAC-only tables have a heading and no row."""
    from types import SimpleNamespace

    from workbench.kinds.tracking import render_tables as T
    design, res = synth
    (r,) = res.readings
    head = T.tuning_table(res).splitlines()[0]
    assert "PID runs" in head and "PID chosen" in head and "MFAC" not in head
    assert T.tuning_table(res).splitlines()[1].count("|") == 6
    assert "| cost |" in T.compare_table(res).splitlines()[0]
    assert len(T.best_table(res).splitlines()) == 3
    assert len(T.ppd_table(res).splitlines()) == 2 and len(T.reset_table(res).splitlines()) == 2
    assert T.sensitivity_table(res, ("kp", "ki"), {"kp": "k_p", "ki": "k_i"}).startswith(
        "| reading | k_p | k_i | most sensitive |")
    assert r.line[0].section.name in T.line_table(res)
    assert T.readings_table(design.spec).count("`nominal`") == 1
    from workbench.features.reproducible import NUDGE, RTOL
    from workbench.report.markdown import fmt
    assert f"+{fmt(NUDGE)} and −{fmt(NUDGE)}" in T.reproducible_text()
    assert f"more than {fmt(RTOL)} (relative)" in T.reproducible_text()
    assert T.dominated_text().startswith("Weight-free comparison of the fronts")
    assert T.ppd_text().startswith("Each reading, at the chosen MFAC run:")
    assert T.edges_text(r) == ("" if not r.pid.edges else "PID in " + ", ".join(r.pid.edges))
    assert T.end_error_text(SimpleNamespace(s=[0.0, 10.0], spec=SimpleNamespace(
        distance=10.0 + 1e-12))) == "below 1 nm"
    assert T.end_error_text(SimpleNamespace(s=[9.99], spec=SimpleNamespace(distance=10.0))) \
        == "0.01 m"
    assert T.roots_text([complex(1e-12, 1.0), complex(1e-12, -1.0)]) == "0 ± 1 j"
    assert T.roots_text([complex(0.5, 0.0), complex(-0.25, 0.0)]) == "0.5 and -0.25"
    tun = SimpleNamespace(stops=np.array([-1, 0, 1, -1]),
                          reproducible=np.array([1, 1, 1, 0], bool),
                          reset_rate=np.array([0.2, 0.3, 0.4, 0.9]))
    assert T.admissible_text(tun, 0.5) == (
        "Of its 3 reproducible MFAC runs, 1-2 stop within 0.5 m (1 with a stop error within "
        "its band of the limit: undecided); their reset rates span 20 % … 20 %")
    tun.stops = np.array([1, 1, 1, 1])
    assert T.admissible_text(tun, 0.5) == "None of its 3 reproducible MFAC runs stops within 0.5 m"


def test_profile_text_of_a_toy_profile():
    """render_general.profile_text (the general report and paper 002's profile
    section) on a toy profile."""
    from types import SimpleNamespace

    from workbench.kinds.tracking.render_general import profile_text
    spec = SimpleNamespace(profile={"accel": 0.8, "brake": 0.75, "jerk": 0.5})
    assert profile_text(spec) == "acceleration 0.8 m/s², braking 0.75 m/s², jerk 0.5 m/s³"
