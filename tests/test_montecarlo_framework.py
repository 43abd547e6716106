"""The general Monte Carlo framework (issue 35) on a toy system that is no
paper's: seeded draws of declared distributions
(:mod:`workbench.features.montecarlo`), chunked and resumable chunk files run
in-process or in a process pool (:mod:`workbench.features.montecarlo_chunks`)
and the statistics of the runs with Wilson intervals
(:mod:`workbench.features.montecarlo_stats`). The toy: exponential decay
x' = -a x from x(0) = x0, exact solution, the rate ``a`` and ``x0`` drawn."""
from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import pytest

from workbench.features.montecarlo import (Distribution, MonteCarloSpec, draw, drawn_factors,
                                           wilson_interval)
from workbench.features.montecarlo_chunks import (Chunk, FolderTaken, Group, chunk_ranges,
                                                  default_chunk, read_npz, run_chunks,
                                                  start_chunks, write_npz)
from workbench.features.montecarlo_stats import (OK, RunsResult, finite_span, quantity_names,
                                                 summary_row)

N, T = 37, 2.0
SPEC = MonteCarloSpec(N, 11, {
    "a": Distribution("uniform", -0.5, 2.0, -0.5, 2.0, "toy"),
    "x0": Distribution("normal", 1.0, 0.1, 0.5, 1.5, "toy")})
ORDER = ("a", "b", "x0")


class Decay(RunsResult):
    SUMMARY: ClassVar[tuple] = ("x_end",)
    OUTCOMES: ClassVar[tuple] = ("grew", OK)


def decay_chunk(payload: dict) -> dict:
    """The toy's per-chunk run function (module level: picklable for a pool)."""
    a, x0 = np.asarray(payload["a"]), np.asarray(payload["x0"])
    x_end = x0 * np.exp(-a * T)
    return {"x_end": np.where(a == 0.0, np.nan, x_end), "grew": x_end > x0}


def test_draws_of_declared_factors_only():
    full = draw(SPEC, ORDER, {"b": 3.0})
    only = drawn_factors(SPEC, ORDER)
    assert list(only) == ["a", "x0"] and np.all(full["b"] == 3.0)
    for k in only:
        np.testing.assert_array_equal(only[k], full[k])
    assert np.all((only["x0"] >= 0.5) & (only["x0"] <= 1.5))


def test_chunks_resume_and_pool_agree(tmp_path):
    d = drawn_factors(SPEC, ORDER)
    ranges = chunk_ranges(N, default_chunk(N))
    assert ranges[0] == (0, 10) and ranges[-1] == (30, 37) and len(ranges) == 4

    def chunks(folder):
        return [Chunk(folder / f"c{i0}.npz", {k: v[i0:i1] for k, v in d.items()}, i1 - i0)
                for i0, i1 in ranges]

    def sweep(folder, resume=False, workers=1):
        """The sweep's runs read back from every chunk file; ``ran``: the
        chunks run by this call (the files ``collect`` receives)."""
        def collect(paths, seconds, n_workers):
            ran[:] = paths
            return read_npz([c.path for c in chunks(folder)], lambda k: True)
        return start_chunks(folder, {"toy": 1}, chunks(folder), decay_chunk, write_npz,
                            collect, resume=resume, workers=workers,
                            pool=workers > 1).result()

    ran = []

    whole = decay_chunk(d)
    got = sweep(tmp_path / "one")
    for k in whole:
        np.testing.assert_array_equal(got[k], whole[k])
    (tmp_path / "one" / "c10.npz").unlink()
    with pytest.raises(FolderTaken, match="already holds a sweep") as e:
        sweep(tmp_path / "one")
    assert not e.value.other
    with pytest.raises(FolderTaken, match="another sweep") as e:
        start_chunks(tmp_path / "one", {"toy": 2}, [], decay_chunk, write_npz, None,
                     resume=True)
    assert e.value.other
    again = sweep(tmp_path / "one", resume=True, workers=2)      # the missing chunk, in a pool
    assert ran == [tmp_path / "one" / "c10.npz"]
    pooled = sweep(tmp_path / "two", workers=2)
    for k in whole:
        np.testing.assert_array_equal(again[k], whole[k])
        np.testing.assert_array_equal(pooled[k], whole[k])


def test_csv_chunks_read_back_bit_for_bit(tmp_path):
    d = drawn_factors(MonteCarloSpec(120, 3, SPEC.distributions), ORDER)
    calls = []

    def compute(g, part):
        calls.append(len(part["a"]))
        m = decay_chunk(part)
        return {"x_end": m["x_end"]}, ["grew" if x else "decayed" for x in m["grew"]]

    got = run_chunks(tmp_path / "out", {"toy": 1}, [Group("decay", d)], compute, False)
    assert calls == [50, 50, 20]
    np.testing.assert_array_equal(got["decay"].metrics["x_end"], decay_chunk(d)["x_end"])
    again = run_chunks(tmp_path / "out", {"toy": 1}, [Group("decay", d)], compute, True)
    assert calls == [50, 50, 20] and again["decay"].reasons == got["decay"].reasons


def test_statistics_of_the_runs():
    d = drawn_factors(SPEC, ORDER)
    m = decay_chunk(d)
    res = Decay({k: v.tolist() for k, v in d.items()}, {"x_end": m["x_end"].tolist()},
                {"grew": m["grew"].tolist()}, math.nan, 1)
    grew = int(m["grew"].sum())
    assert 0 < grew < N and res.n == N
    rates = dict((o, rest) for o, *rest in res.outcome_rates())
    assert rates["grew"] == list(wilson_interval(grew, N))
    assert rates[OK] == list(wilson_interval(N - grew, N))
    q = res.quantities("toy")
    assert set(q) == quantity_names("toy", Decay.SUMMARY, res.violations, Decay.OUTCOMES)
    assert q["toy.x_end.max"] == float(np.max(m["x_end"])) and q["toy.samples"] == N
    assert q["toy.fraction.grew"] == grew / N
    assert summary_row("x", [math.nan]) == ["x", 0, None, None, None, None]
    assert finite_span([math.nan, 2.0, -1.0]) == (-1.0, 2.0)
    assert finite_span([math.nan]) == (None, None)
