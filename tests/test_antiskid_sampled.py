"""Sampled-data antiskid (issue 20): the laws of paper 003 at a fixed rate
with a zero-order hold, on a plant mesh independent of the rate
(:mod:`workbench.papers.p003.antiskid_sampled`)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.features import rate_sweep as RS
from workbench.papers.p003 import antiskid_sampled as S
from workbench.papers.p003.antiskid_run_spec import sampled_context
from workbench.features.mesh_replay import replay, window
from workbench.papers.p003.antiskid_sampled_check import ATOL, RTOL
from workbench.sim.wheel_slip import held_torque_rhs as plant_rhs

pytest.importorskip("numba")

DRY = Path("designs/antiskid-run-dry.toml")


@pytest.fixture(scope="module")
def ctx():
    # the printed cruise gain (no synthesis: these tests are about sampling)
    design = load_design(DRY)
    return sampled_context(design.spec, design.spec.K_table)


def _traction(ctx, rate, t0, t1, **kw):
    kw.setdefault("dt_p", 1e-4)
    kw.setdefault("predictor_step", 1e-3)
    cap = int((t1 - t0) / kw["dt_p"]) * 3 + 100
    return S.run_once(ctx, rate, 0, record=(t0, t1, cap), t_cap=t1, **kw)


def test_zoh_holds_the_torque_between_samples(ctx):
    # at 100 Hz the wheel's torque changes only where a command arrives,
    # t_k + h; between two such instants it is exactly constant while the
    # plant moves on 100 sub-steps. A law evaluated at every sub-step (the
    # continuous law, or the emulation) changes it at every sub-step.
    rate, h = 100.0, ctx.h
    _, (rec, rec_u) = _traction(ctx, rate, 0.5, 1.0)
    t, lam, u = rec[:, 0], rec[:, 2], rec[:, 3]
    changes = t[:-1][np.diff(u) != 0.0]     # rec[i, 3]: the torque over the step ending at t_i
    k = (changes - h) * rate                 # arrival instants t_k + h, k whole
    assert len(changes) >= 40
    assert np.allclose(k, np.round(k), atol=1e-6)
    # the commands themselves are sampled at t_k = k / f_c, one per sample
    assert np.allclose(rec_u[:, 0] * rate, np.round(rec_u[:, 0] * rate), atol=1e-6)
    assert len(rec_u) == pytest.approx(0.5 * rate, abs=1)
    # between two arrivals: many mesh points, one torque, a moving state
    inside = (t > changes[10]) & (t < changes[11])
    assert inside.sum() >= 90 and np.ptp(u[inside]) == 0.0 and np.ptp(lam[inside]) > 0.0
    # the emulation (law at every step of dt/2) changes the torque every step
    dt_e = 0.005
    _, (erec, _) = _traction(ctx, 1 / dt_e, 0.5, 1.0, dt_p=dt_e, emulation=True,
                             predictor_step=0.0)
    assert np.count_nonzero(np.diff(erec[:, 3])) >= 0.9 * 0.5 / dt_e


def test_quantised_commands_are_multiples_of_the_step(ctx):
    q = 8.0
    _, (_, rec_u) = _traction(ctx, 200.0, 0.2, 0.6, q=q)
    ratio = rec_u[:, 1] / q
    assert len(ratio) >= 70 and np.allclose(ratio, np.round(ratio), rtol=0, atol=1e-9)
    _, (_, free) = _traction(ctx, 200.0, 0.2, 0.6)
    assert not np.allclose(free[:, 1] / q, np.round(free[:, 1] / q), rtol=0, atol=1e-3)


def test_metrics_do_not_depend_on_the_plant_step(ctx):
    # halving the plant's sub-step moves no metric beyond the mesh tolerances
    # (and the outcome not at all); a sub-step of 5 ms, the emulation's
    # dt/2, is outside them: the bound is not vacuous
    row = lambda step: RS.rate_row(*S.model(ctx, 1e-3), 100.0, 8.0, 0.002, step)  # noqa: E731
    a, b = row(1e-4).metrics, row(5e-5).metrics
    assert a["ok"] == b["ok"]
    for key, tol in S.MESH_ATOL.items():
        assert abs(a[key] - b[key]) <= tol, key
    c = row(5e-3).metrics
    assert any(not abs(a[k] - c[k]) <= tol for k, tol in S.MESH_ATOL.items())


def test_fast_sampling_tends_to_the_emulation(ctx):
    # traction: the largest creep ratio falls with the rate toward the
    # emulation's, and at 5 kHz reproduces it within 1e-4 lambda_opt (a tenth
    # of the requirement's margin) and the time to v_d within 0.02 s
    dt_e = 0.005
    emu, _ = S.run_once(ctx, 1 / dt_e, 0, dt_p=dt_e, emulation=True)
    lo = ctx.cs.lambda_opt
    peaks = []
    for rate in (20.0, 100.0, 1000.0, 5000.0):
        out, _ = S.run_once(ctx, rate, 0, dt_p=1e-4, predictor_step=1e-3)
        peaks.append(out["lam_max"] / lo)
        last = out
    assert peaks == sorted(peaks, reverse=True)
    assert abs(peaks[-1] - emu["lam_max"] / lo) <= 1e-4
    assert abs(last["t_cruise"] - emu["t_cruise"]) <= 0.02


def test_radau_replay_agrees_and_sees_a_tampered_record(ctx):
    _, (rec, _) = _traction(ctx, 100.0, ctx.h, ctx.h + 0.05)
    (_, dl), (dv, _), pieces = replay(plant_rhs(ctx.plant), rec, RTOL, ATOL)
    assert pieces >= 4 and dl <= 1e-5 * ctx.cs.lambda_opt and dv <= 1e-4
    bad = rec.copy()
    bad[len(bad) // 2:, 2] += 1e-4        # the creep ratio moved by hand halfway
    assert replay(plant_rhs(ctx.plant), bad, RTOL, ATOL)[0][1] >= 0.9e-4


def test_the_braking_entry_sets_the_lowest_dry_rate(ctx):
    # at 20 Hz braking diverges at the braking entry (the law of eq 69 held
    # for 50 ms on the traction side); at 50 Hz the train stops
    runs, decl = S.model(ctx, 1e-3)
    lo = RS.rate_row(runs, decl, 20.0, 0.0, 0.0, 1e-4).metrics
    hi = RS.rate_row(runs, decl, 50.0, 0.0, 0.0, 1e-4).metrics
    assert lo["traction_ok"] == "yes" and lo["braking_ok"] == "no"
    assert ctx.t_brake <= lo["braking_diverged"] <= ctx.t_brake + 2.0
    assert hi["ok"] == "yes" and math.isfinite(hi["stop_distance"])


@pytest.mark.parametrize("old, new, key", [
    ("rates_hz = [5.0, 10.0,", "rates_hz = [10.0, 5.0,", "sampled.rates_hz"),
    ("rates_hz = [5.0,", "rates_hz = [-5.0,", "sampled.rates_hz[0]"),
    ('{ value = 8.0, unit = "N m"', '{ value = 8.0, unit = "N"', "sampled.quantisation.unit"),
    ("{ value = 0.002, unit", "{ value = -0.002, unit", "sampled.measurement_delay.value"),
    ("plant_step = 1e-4", "plant_step = 0.5", "sampled.plant_step"),
    ('case = "compensated"\nrates_hz', 'case = "nope"\nrates_hz', "sampled.case"),
    ("bisect = 4 ", "bisects = 4 ", "sampled.bisects"),
])
def test_bad_sampled_table_is_exit_2(tmp_path, capsys, old, new, key):
    text = DRY.read_text(encoding="utf-8")
    assert old in text
    bad = tmp_path / "antiskid-run-dry.toml"
    bad.write_text(text.replace(old, new, 1), encoding="utf-8")
    assert main(["verify", str(bad)]) == 2
    err = capsys.readouterr().err
    assert str(bad.name) in err and key in err and "expected" in err


def test_a_memoised_run_and_a_cut_record_are_those_of_separate_runs(ctx):
    """run_sampled memoises its runs: the braking run that locates the Radau
    check's windows is the grid's, the outputs of its own call; a window cut
    from a longer record (the figure's trace, or one run over both braking
    windows) holds the rows of a run recording that window alone."""
    from workbench.papers.p003.antiskid_sampled_kernel import run_once
    runs = S.model(ctx, 1e-3)[0]
    kept = runs(100.0, 1, 0.0, 0.0, 2e-4)
    assert runs(100.0, 1, 0.0, 0.0, 2e-4) is kept and runs.made == 1
    own = run_once(ctx, 100.0, 1, dt_p=2e-4, predictor_step=1e-3)[0]
    assert math.isfinite(own["t_stop"])
    assert {k: repr(v) for k, v in kept.items()} == {k: repr(v) for k, v in own.items()}
    kw = dict(dt_p=2e-4, predictor_step=1e-3)
    long = run_once(ctx, 100.0, 0, record=(0.0, 0.5, 20000), t_cap=0.5, **kw)[1][0]
    t0, t1 = ctx.h - 1e-4, ctx.h + 0.05 - 1e-4
    alone = run_once(ctx, 100.0, 0, record=(t0, t1, 2000), **kw)[1][0]
    assert len(alone) > 100 and np.array_equal(window(long, t0, t1), alone)
