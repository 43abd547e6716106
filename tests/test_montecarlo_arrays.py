"""The general Monte Carlo pieces of issue 35 on a toy system (no paper):
the array sweep driver (in memory and streamed, resumable), the per-run
draws from (seed, run index) and the per-run curve peaks."""
from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp

from workbench.errors import ModelError
from workbench.features.curve_peaks import peaks, slope_function
from workbench.features.montecarlo_arrays import (ArrayRuns, chunk_arrays, concat_chunks,
                                                  draws_of, inputs_digest, start_array_sweep)
from workbench.features.montecarlo_draws import draw_runs, hold_steps, stream_keys
from workbench.features.montecarlo_stats import OK, RunsResult

RANGES = {"a": (0.5, 2.0), "x0": (1.0, 3.0)}
SEED, N = 11, 23


def toy_chunk(payload: dict) -> dict:
    """Runs i0 <= i < i1 of a toy sweep: x' = -a x by explicit Euler to t = 1
    (a, x0 drawn); raw: x(1) and the first time x <= 1 (NaN: never)."""
    i0, i1, dt = payload["i0"], payload["i1"], payload["dt"]
    d = draw_runs(i1, SEED, RANGES, i0)
    x, t_below = d["x0"].copy(), np.full(i1 - i0, math.nan)
    for k in range(round(1.0 / dt)):
        x = x - dt * d["a"] * x
        t_below = np.where(np.isnan(t_below) & (x <= 1.0), (k + 1) * dt, t_below)
    return chunk_arrays(i0, i1, d, {"x_end": x, "t_below": t_below})


class ToyResult(RunsResult):
    SUMMARY = ("x_end",)
    OUTCOMES = ("above_one", OK)


def toy_result(cols: dict, seconds: float, workers: int) -> ToyResult:
    return ToyResult(draws_of(cols), {"x_end": cols["raw.x_end"].tolist()},
                     {"above_one": np.isnan(cols["raw.t_below"]).tolist()}, seconds, workers)


def start(**kw):
    return start_array_sweep(toy_chunk, lambda i0, i1: {"i0": i0, "i1": i1, "dt": 0.01}, N,
                             toy_result, workers=1, **kw)


def test_the_sweep_does_not_depend_on_its_chunks():
    whole = start(chunk=N).result(False)
    cut = start(chunk=5).result(False)
    assert whole.samples == cut.samples and whole.metrics == cut.metrics
    assert whole.violations == cut.violations and whole.n == N
    # the draws are those of one seeded draw of all runs
    assert whole.samples == {k: v.tolist() for k, v in draw_runs(N, SEED, RANGES).items()}
    # x(1) ~ x0 exp(-a): the outcome counts come from montecarlo_stats
    x = np.array(whole.samples["x0"]) * (1 - 0.01 * np.array(whole.samples["a"])) ** 100
    np.testing.assert_allclose(whole.metrics["x_end"], x, rtol=1e-12)
    (name, k, n, p, lo, hi), _ = whole.outcome_rates()
    assert name == "above_one" and n == N and k == int(np.sum(x > 1.0)) and lo <= p <= hi


def test_streamed_sweep_equals_in_memory_and_resumes(tmp_path):
    out = tmp_path / "toy"
    mem = start(chunk=6).result(False)
    man = lambda ch: {"samples": N, "chunk": ch, "seed": SEED,          # noqa: E731
                      "inputs_sha256": inputs_digest({"ranges": RANGES})}
    got = start(chunk=6, out=out, manifest=man).result(False)
    assert got.metrics == mem.metrics and got.samples == mem.samples
    files = sorted(out.glob("chunk-*.npz"))
    assert len(files) == 4
    files[2].unlink()
    with pytest.raises(FileExistsError, match="already holds a sweep"):
        start(chunk=6, out=out, manifest=man)
    again = start(chunk=6, out=out, manifest=man, resume=True,
                  select=lambda k: not k.startswith("draw.")).result(False)
    assert again.metrics == mem.metrics and again.samples == {}
    other = lambda ch: {**man(ch), "seed": SEED + 1}                      # noqa: E731
    with pytest.raises(FileExistsError, match="another sweep"):
        start(chunk=6, out=out, manifest=other, resume=True)


def toy_per_run(raw: dict, scale: np.ndarray, level: float) -> tuple[dict, dict]:
    """The toy's runs from its raw fields, its own column and a context value."""
    return {"x_end": raw["x_end"] * scale}, {"above_one": raw["x_end"] > level}


def toy_scaled(payload: dict) -> dict:
    """:func:`toy_chunk` with an own column ``scale`` (2 for every run)."""
    arrays = toy_chunk(payload)
    return {**arrays, "scale": np.full(len(arrays["index"]), 2.0)}


def test_array_runs_make_the_result_in_memory_and_from_the_files(tmp_path):
    runs = ArrayRuns(toy_per_run, ("x_end",), ("scale",), ToyResult)
    assert runs.select("raw.x_end") and runs.select("scale") and runs.select("draw.a")
    assert not runs.select("raw.t_below") and not runs.select("index")
    payload = lambda i0, i1: {"i0": i0, "i1": i1, "dt": 0.01}       # noqa: E731
    man = lambda ch: {"samples": N, "chunk": ch, "level": 1.5}      # noqa: E731
    mem = start_array_sweep(toy_scaled, payload, N, lambda c, s, w: runs.result_of(c, s, w, 1.5),
                            workers=1, chunk=7).result(False)
    plain = start(chunk=N).result(False)
    assert mem.samples == plain.samples and mem.n == N and mem.workers == 1
    assert mem.metrics["x_end"] == [2 * x for x in plain.metrics["x_end"]]
    assert mem.violations["above_one"] == [x > 1.5 for x in plain.metrics["x_end"]]
    start_array_sweep(toy_scaled, payload, N, lambda c, s, w: None, workers=1, chunk=7,
                      out=tmp_path, manifest=man).result(False)
    back = runs.load(tmp_path, lambda manifest: (manifest["level"],))
    assert (back.samples, back.metrics, back.violations) == (mem.samples, mem.metrics,
                                                             mem.violations)
    assert math.isnan(back.seconds) and back.workers == 0
    # the same sweep started by the runs themselves, in memory and streamed
    again = runs.start(toy_scaled, payload, N, (1.5,), workers=1, chunk=7).result(False)
    assert (again.samples, again.metrics, again.violations) == (mem.samples, mem.metrics,
                                                                mem.violations)
    streamed = runs.start(toy_scaled, payload, N, (1.5,), workers=1, chunk=7,
                          out=tmp_path / "again", manifest=man).result(False)
    assert (streamed.metrics, streamed.violations) == (mem.metrics, mem.violations)


def test_array_helpers():
    a = chunk_arrays(3, 5, {"p": [1.0, 2.0]}, {"m": [0, 1]}, extra=np.zeros(2))
    assert sorted(a) == ["draw.p", "extra", "index", "raw.m"]
    assert a["raw.m"].dtype == float and a["index"].tolist() == [3, 4]
    b = chunk_arrays(5, 6, {"p": [3.0]}, {"m": [2]}, extra=np.ones(1))
    assert draws_of(concat_chunks([a, b])) == {"p": [1.0, 2.0, 3.0]}
    assert inputs_digest({"b": 1, "a": (1, 2)}) == inputs_digest({"a": [1, 2], "b": 1})
    assert inputs_digest({"a": 1}) != inputs_digest({"a": 2})


def test_draws_depend_on_seed_and_run_only():
    streams = {"period": (4, (2.0, 5.0)), "phase": (5, (0.0, 1.0))}
    whole = draw_runs(40, 3, RANGES, streams=streams)
    tail = draw_runs(40, 3, RANGES, start=17, streams=streams)
    for k in whole:
        np.testing.assert_array_equal(whole[k][17:], tail[k])
    # the stream draws leave the rows of the ranges unchanged
    plain = draw_runs(40, 3, RANGES)
    for k in RANGES:
        np.testing.assert_array_equal(plain[k], whole[k])
    assert 2.0 <= whole["period"].min() and whole["period"].max() < 5.0
    assert 0.0 <= whole["phase"].min() and whole["phase"].max() < 1.0
    assert len(set(whole["period"].tolist())) == 40
    keys = stream_keys(3, {"v": 1, "w": 2}, [5, 6, 7])
    assert keys["v"][1:] == stream_keys(3, {"v": 1}, [6, 7])["v"]
    assert len(set(keys["v"]) | set(keys["w"])) == 6
    assert all(isinstance(k, int) for k in keys["w"])


def test_hold_steps():
    assert hold_steps(0.01, 0.005) == 2 and hold_steps(0.01, 0.01) == 1
    with pytest.raises(ValueError, match="divides"):
        hold_steps(0.01, 0.003)


def test_curve_peaks_of_a_toy_family():
    x, a, b = sp.symbols("x a b", positive=True)
    slope = slope_function(b * x * sp.exp(-a * x), x, (a, b))    # peak at x = 1 / a
    av = np.array([0.5, 1.0, 4.0])
    np.testing.assert_allclose(peaks(slope, [av, np.ones(3)], 1e-9, 10.0), 1 / av, rtol=1e-12)
    with pytest.raises(ModelError, match="run 0: toy without a peak"):
        peaks(slope, [[0.05], [1.0]], 1e-9, 10.0, "toy")


def _claim(cid, quantity, compare, value):
    from workbench.claims import Claim
    return Claim(cid, f"claim {cid}", quantity, compare, value, 0.0, None, "round", "workbench",
                 False, "pass", "", "minor", "workbench")


def test_masked_metrics_are_not_compared():
    from workbench.features.convergence import compare_steps
    c = {"y": [1.0, 2.0, 3.0], "bad": [False, True, False]}
    f = {"y": [1.0, 9.0, 3.5], "bad": [False, True, True]}
    _, _, agree = compare_steps(c, f, 0.01, {}, ("y",), ("bad",))
    assert agree["y"] == (True, False, False)
    cm, fm, agree = compare_steps(c, f, 0.01, {}, ("y",), ("bad",),
                                  masked={"y": np.array(c["bad"]) | np.array(f["bad"])})
    assert agree["y"] == (True, True, True) and math.isnan(cm["y"][2]) and math.isnan(fm["y"][1])
    assert agree["bad"] == (True, True, False) and cm["y"][0] == 1.0


def test_claimed_members_and_unstepped_levels():
    from workbench.claims import ClaimResult, Verdict
    from workbench.features.refinement import claimed_members, unstepped_levels
    claims = [_claim("a", "runs[fast].converged", "==", "yes"),
              _claim("b", "runs[slow].peak", "<=", 1.0),
              _claim("c", "runs[x].converged.no", "==", 1)]
    assert claimed_members(claims, r"runs\[([^\]]+)\]\.converged") == {"fast"}
    lv = unstepped_levels(ClaimResult(claims[1], 0.1234567, Verdict.PASS), "no step")
    assert lv.values == ("0.123457",) * 3 and lv.parameter == "no step"


def test_share_findings_of_a_toy_sweep_over_three_levels():
    """A share finding of a toy sweep (N = 10 runs at dt, the first 4 at dt/2
    and dt/4): the unrefined runs bound the count, the levels decide it."""
    from types import SimpleNamespace

    from workbench.claims import ClaimResult, Verdict
    from workbench.features.montecarlo_halving import sweep_share_levels
    whole = [False] * 9 + [True]
    check = SimpleNamespace(dt=0.1, fine={"grew": (False,) * 4})
    quarter = []

    def at_quarter():
        quarter.append(1)
        return {"grew": (False,) * 4}

    def levels(quantity, value, chk=check):
        r = ClaimResult(_claim("s", quantity, "<=", value), 0.1, Verdict.PASS)
        return sweep_share_levels(r, lambda k: whole, chk, {"toy.fraction.grew": "grew"},
                                  at_quarter, "toy")

    lv = levels("toy.fraction.grew", 0.9)    # at most 7 of 10 at dt/2: holds at every level
    assert lv.decides == ("holds",) * 3 and lv.parameter == "toy.dt" and quarter == [1]
    assert lv.values[1] == "0 of the first 4, so 0-6 of 10 grew: holds"
    assert levels("toy.fraction.grew", 0.2).decides == ("holds", "undecided", "undecided")
    assert levels("toy.halving.fraction_agree", 1.0).reason.startswith("a comparison of two")
    assert levels("toy.fraction.grew", 0.2, None).reason.endswith(
        "step check of its Monte Carlo runs")


def test_draws_from_declared_distributions():
    from workbench.features.montecarlo import Distribution
    from workbench.sim.batch import uniform_draws
    norm = Distribution("normal", 1.0, 0.04, 0.85, 1.15, "toy")
    got = draw_runs(50, 7, {"a": (0.5, 2.0), "m": norm, "g": Distribution(
        "uniform", -3.0, 3.0, -3.0, 3.0, "toy")}, start=10)
    ref = uniform_draws(50, 7, {"a": (0.5, 2.0), "m": (0.0, 1.0), "g": (-3.0, 3.0)}, 10)
    np.testing.assert_array_equal(got["a"], ref["a"])      # bit for bit as uniform_draws
    np.testing.assert_array_equal(got["g"], ref["g"])
    np.testing.assert_array_equal(got["m"], norm.ppf(ref["m"]))
    assert 0.85 <= got["m"].min() and got["m"].max() <= 1.15
