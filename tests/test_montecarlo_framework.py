"""The general Monte Carlo framework (issue 35) on a toy system that is no
paper's: seeded draws of declared distributions
(:mod:`workbench.features.montecarlo`), chunked and resumable chunk files run
in-process or in a process pool (:mod:`workbench.features.montecarlo_chunks`)
and the statistics of the runs with Wilson intervals
(:mod:`workbench.features.montecarlo_stats`), the streaming driver (one
``.npz`` per range of runs, resume, read back), the step-halving check of a
sweep's first runs (:mod:`workbench.features.montecarlo_halving`) and the
tables (:mod:`workbench.features.montecarlo_render`). The toy: exponential
decay x' = -a x from x(0) = x0, exact solution (or explicit Euler at a step
for the halving check), the rate ``a`` and ``x0`` drawn."""
from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace
from typing import ClassVar

import numpy as np
import pytest

from workbench.features.montecarlo import (Distribution, MonteCarloSpec, draw, drawn_factors,
                                           wilson_interval)
from workbench.features.convergence import compare_steps
from workbench.features.montecarlo_chunks import (Chunk, FolderTaken, Group, chunk_file,
                                                  chunk_ranges, default_chunk, read_npz,
                                                  read_streamed, run_chunks, run_groups,
                                                  start_batches,
                                                  start_chunks, start_streaming, write_npz)
from workbench.features.montecarlo_halving import (Compared, HalvingCheck, halving_quantities,
                                                   start_halving)
from workbench.features.montecarlo_render import (DRAWS_TEXT, draw_outcome_scatter,
                                                  halving_section, halving_tables,
                                                  montecarlo_figures, rates_text,
                                                  summary_tables, SweepWords)
from workbench.features.montecarlo_stats import (OK, STATISTICS, RunsResult, finite_span,
                                                 runs_quantities, summary_row)
from workbench.features.quantities import Part, names, values

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


def test_one_path_in_memory_or_through_chunk_files(tmp_path):
    """run_groups: one batch per group held in memory, or the CSV chunk files
    (and their resume) when given a folder; the same runs either way."""
    d = drawn_factors(MonteCarloSpec(70, 5, SPEC.distributions), ORDER)
    calls = []

    def compute(g, part):
        calls.append((g.name, len(part["a"])))
        m = decay_chunk(part)
        return {"x_end": m["x_end"] * (2.0 if g.name == "twice" else 1.0)}, \
            (["grew" if x else "decayed" for x in m["grew"]] if g.name == "once" else None)

    groups = [Group("once", d), Group("twice", d)]
    mem = run_groups(groups, compute)
    assert calls == [("once", 70), ("twice", 70)] and mem["twice"].reasons == []
    files = run_groups(groups, compute, tmp_path / "out", {"toy": 2})
    assert calls[2:] == [("once", 50), ("once", 20), ("twice", 50), ("twice", 20)]
    for g in ("once", "twice"):
        np.testing.assert_array_equal(files[g].metrics["x_end"], mem[g].metrics["x_end"])
        assert files[g].reasons == mem[g].reasons
    assert run_groups(groups, compute, tmp_path / "out", {"toy": 2}, resume=True
                      )["once"].reasons == mem["once"].reasons and len(calls) == 6


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
    # the toy's quantities declared once (a result holding the runs as ``.mc``)
    table = (Part(runs_quantities("toy", Decay.SUMMARY, res.violations, Decay.OUTCOMES),
                  lambda spec: spec == "with mc", lambda r: r.mc),)
    q = values(table, "with mc", SimpleNamespace(mc=res))
    assert set(q) == names(table, "with mc") == {"toy.samples", "toy.fraction.grew"} | {
        f"toy.x_end.{s}" for s in STATISTICS} | {f"toy.wilson.{o}.{b}" for o in ("grew", OK)
                                                 for b in ("lo", "hi")}
    assert q["toy.x_end.max"] == float(np.max(m["x_end"])) and q["toy.samples"] == N
    assert q["toy.fraction.grew"] == grew / N
    # the sweep did not run: every name not determined; the design has none: no name
    assert values(table, "with mc", SimpleNamespace(mc=None)) == dict.fromkeys(q)
    assert names(table, "without") == set() and values(table, "without", None) == {}

    class Counted(Decay):                 # the statistics are computed once per result
        calls = 0

        def summary_rows(self):
            type(self).calls += 1
            return super().summary_rows()
    once = Counted(res.samples, res.metrics, res.violations, math.nan, 1)
    q_once = values(table, "with mc", SimpleNamespace(mc=once))
    assert set(q_once) == set(q) and q_once["toy.x_end.max"] == q["toy.x_end.max"]
    assert Counted.calls == 1
    once.statistics()["toy"] = 0.0        # a copy: the memo is not changed by its reader
    assert "toy" not in once.statistics() and Counted.calls == 1
    assert names(table, "no mc") == set() and values(table, "no mc", None) == {}
    assert set(values(table, "with mc", SimpleNamespace(mc=None)).values()) == {None}
    assert summary_row("x", [math.nan]) == ["x", 0, None, None, None, None]
    assert finite_span([math.nan, 2.0, -1.0]) == (-1.0, 2.0)
    assert finite_span([math.nan]) == (None, None)


def decay_range(payload: dict) -> dict:
    """Runs ``i0 <= i < i1`` of the toy sweep, drawn by the worker itself
    (the streaming driver's run function)."""
    i0, i1 = payload["i0"], payload["i1"]
    d = {k: v[i0:i1] for k, v in drawn_factors(SPEC, ORDER).items()}
    return {"index": np.arange(i0, i1), **{f"draw.{k}": v for k, v in d.items()},
            **decay_chunk(d)}


@pytest.mark.parametrize("workers", [1, 2])
def test_batches_in_memory_agree_with_one_batch(workers):
    d, compiled = drawn_factors(SPEC, ORDER), []

    def collect(outs, seconds, n_workers):
        return {k: np.concatenate([o[k] for o in outs]) for k in outs[0]}, n_workers

    got, n_workers = start_batches(decay_chunk, lambda i0, i1: {k: v[i0:i1] for k, v in d.items()},
                                   N, 10, collect, workers=workers, pool=workers > 1,
                                   before_pool=lambda: compiled.append(1)).result()
    assert n_workers == workers and compiled == [1] * (workers > 1)
    for k, v in decay_chunk(d).items():
        np.testing.assert_array_equal(got[k], v)


def test_streaming_driver_writes_resumes_and_reads_back(tmp_path):
    out, man = tmp_path / "s", {"toy": 1, "samples": N, "chunk": 10}
    payload = lambda i0, i1: {"i0": i0, "i1": i1}      # noqa: E731
    compiled = []

    def go(resume=False, workers=1):
        return start_streaming(out, man, payload, decay_range,
                               lambda s, w: read_streamed(out, lambda k: True)[1],
                               resume=resume, workers=workers,
                               before_pool=lambda: compiled.append(1)).result()

    whole = decay_range({"i0": 0, "i1": N})
    got = go()
    assert sorted(p.name for p in out.glob("chunk-*.npz")) == [
        chunk_file(out, i0, i1).name for i0, i1 in chunk_ranges(N, 10)]
    for k in whole:
        np.testing.assert_array_equal(got[k], whole[k])
    chunk_file(out, 10, 20).unlink()
    chunk_file(out, 20, 30).unlink()
    with pytest.raises(FileNotFoundError, match="2 of 4 chunks not written"):
        read_streamed(out, lambda k: True)
    with pytest.raises(FolderTaken, match="already holds a sweep"):
        go()
    again = go(resume=True, workers=2)      # the two missing chunks, in a pool
    assert compiled == [1]
    for k in whole:
        np.testing.assert_array_equal(again[k], whole[k])
    assert read_streamed(out, lambda k: k == "x_end")[0] == man


def euler_chunk(payload: dict) -> dict:
    """The toy by explicit Euler at ``payload["dt"]`` up to T: x_end and
    whether x grew (a batch run function of the halving check)."""
    a, x = np.asarray(payload["a"]), np.asarray(payload["x0"], float).copy()
    for _ in range(round(T / payload["dt"])):
        x = x - payload["dt"] * a * x
    return {"x_end": x, "grew": x > np.asarray(payload["x0"])}


class EulerRuns(RunsResult):
    SUMMARY: ClassVar[tuple] = ("x_end",)
    OUTCOMES: ClassVar[tuple] = ("grew", OK)


@pytest.mark.parametrize("rtol", [0.3, 1e-6])
def test_halving_check_of_a_toy_sweep(rtol):
    d, n, dt = drawn_factors(SPEC, ORDER), 12, 0.1
    first = {k: v[:n] for k, v in d.items()}

    def step_values(metrics, viol):
        return {"x_end": np.asarray(metrics["x_end"], float),
                "grew": np.asarray(viol["grew"], bool)}

    def runs_of(o):
        return {"x_end": o["x_end"]}, {"grew": o["grew"]}

    def start(coarse):
        return start_halving(euler_chunk, lambda step: {**first, "dt": step}, runs_of,
                             step_values, Compared(("x_end",), ("grew",)), dt, n, rtol=rtol,
                             atol={}, case="toy", seed=SPEC.seed, draws=first, coarse=coarse,
                             pool=False)

    hc = start(True).result()
    assert hc.n == n and hc.coarse["x_end"] == tuple(euler_chunk({**first, "dt": dt})["x_end"])
    assert hc.fine["x_end"] == tuple(euler_chunk({**first, "dt": dt / 2})["x_end"])
    # Euler at dt and dt / 2 differ by up to ~22 % (a = 2): within 30 %, never within 1e-6
    assert sum(hc.run_agree) == (n if rtol == 0.3 else 0)
    sweep = euler_chunk({**d, "dt": dt})
    res = EulerRuns({k: v.tolist() for k, v in d.items()}, {"x_end": sweep["x_end"].tolist()},
                    {"grew": sweep["grew"].tolist()}, math.nan, 1)
    assert start(False).result()(res) == hc       # the dt side taken from the sweep
    with pytest.raises(ValueError, match="the sweep has 3 runs"):
        start(False).result()(EulerRuns({}, {"x_end": [1.0] * 3}, {"grew": [False] * 3},
                                        math.nan, 1))
    assert hc.atol == {"x_end": 0.0} and hc.case == "toy" and hc.seed == SPEC.seed
    with pytest.raises(ValueError, match="need at least 1"):
        start_halving(euler_chunk, lambda step: {}, runs_of, step_values,
                      Compared(("x_end",), ()), dt, 0, rtol=rtol, atol={}, case="toy",
                      seed=SPEC.seed, draws={})
    assert hc.draws == {k: tuple(v.tolist()) for k, v in first.items()}
    cv, fv, agree = compare_steps({k: hc.coarse[k] for k in ("x_end", "grew")},
                                  {k: hc.fine[k] for k in ("x_end", "grew")}, rtol,
                                  {"x_end": 0.0}, ("x_end",), ("grew",))
    assert (cv, fv, agree) == (hc.coarse, hc.fine, hc.agree)
    table = halving_quantities("toy.halving")
    assert values(table, None, hc) == hc.quantities("toy.halving") == {
        "toy.halving.runs": n, "toy.halving.agree": sum(hc.run_agree),
        "toy.halving.fraction_agree": sum(hc.run_agree) / n}
    # a study's mask: a masked metric is NaN at both steps, so it agrees
    masked = Compared(("x_end",), ("grew",), lambda c, f: {"x_end": [True] * n}).compare(
        hc.coarse, hc.fine, rtol, {"x_end": 0.0})
    assert all(math.isnan(x) for x in masked[0]["x_end"]) and all(masked[2]["x_end"])
    text = halving_tables(hc, ("x_end",), ("grew",), (("a", "rate a"),))
    assert text.count("| `x_end` |") == 1 + (0 if rtol == 0.3 else n)
    assert text.endswith(" none.") == (rtol == 0.3)
    assert "| outcome | runs" in summary_tables(res, 3, {"grew": "grew", OK: "ok"})
    md = halving_section(hc, ("x_end",), ("grew",), (("a", "rate a"),), N,
                         " (the toy's note)", "; nothing left out")
    assert md.startswith(f"The first {n} of the sweep's {N} runs (seed {SPEC.seed}, case `toy`")
    assert "at dt / 2 (the toy's note). " in md and "do not; nothing left out. " in md
    assert f"**{sum(hc.run_agree)} of {n} runs agree" in md and md.endswith(text)
    assert f"between k and k + {N - n} of the {N} runs" in md        # the refinement it covers
    assert "Refinement" not in halving_section(hc, ("x_end",), ("grew",), (), None)
    words = SweepWords({}, {}, halving_metrics=("x_end",), halving_outcomes=("grew",),
                       draws=(("a", "rate a"),), batch_note=" (the toy's note)",
                       not_compared="; nothing left out")
    assert words.halving(hc, N) == md                  # the study's words as one table
    sec = dataclasses.replace(words, outcomes={"grew": "grew", OK: "ok"}).section(
        res, heading="Toy", intro="", draws=[], summary_note="", halving=hc, samples=N)
    assert sec.endswith("\n\n### Step-size check of the Monte Carlo runs\n\n" + md)
    alt = dataclasses.replace(words, alternates={"a": ("x0", "x(0)", "")})
    assert alt.halving(hc, N) == halving_section(hc, ("x_end",), ("grew",), (("x0", "x(0)"),),
                                                 N, " (the toy's note)", "; nothing left out")


def test_outcome_scatter_and_report_figures_of_a_toy_sweep():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = drawn_factors(SPEC, ORDER)
    m = decay_chunk(d)
    res = Decay({k: v.tolist() for k, v in d.items()}, {"x_end": m["x_end"].tolist()},
                {"grew": m["grew"].tolist()}, math.nan, 1)
    grew = np.asarray(m["grew"])
    fig = plt.figure()
    draw_outcome_scatter(fig, res.samples, (("a", "x0", "rate a", "x(0)"),),
                         (("grew", grew, "tab:red", "x"), ("decayed", ~grew, "tab:blue", "o"),
                          ("never", np.zeros(N, bool), "k", "s")), N,
                         ("grew", np.asarray(m["x_end"]), "x at T"))
    (ax,) = [a for a in fig.axes if a.get_label() != "<colorbar>"]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [f"grew: {grew.sum()} of {N}", f"decayed: {N - grew.sum()} of {N}"]
    assert len(fig.axes) == 2 and ax.get_xlabel() == "rate a"     # the shaded group's bar
    plt.close(fig)
    figs = montecarlo_figures(res, lambda fig, r: fig.subplots(), lambda fig, r: None)
    assert [f.name for f in figs] == ["montecarlo-histograms", "montecarlo-rates",
                                      "montecarlo-outcomes"]
    for f in figs:                          # the report's text shows each figure
        assert f"({{figdir}}/{f.name}.png)" in rates_text(N) + DRAWS_TEXT
    assert f"(the {N} runs as independent trials;" in rates_text(N)
    fig = plt.figure()
    figs[1].draw(fig)                                              # the rates of the toy
    assert len(fig.axes[0].get_yticklabels()) == len(res.outcome_rates())
    plt.close(fig)


def test_sweep_words_render_a_toy_sweep():
    """SweepWords: the toy's words as one table drive the tables, the
    histograms, the step-halving text and the outcome scatter (groups from
    the flags, an alternate draw in place of another)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from workbench.features.montecarlo_render import SweepWords, draw_histograms
    d = drawn_factors(SPEC, ORDER)
    m = decay_chunk(d)
    grew = np.asarray(m["grew"])
    res = Decay({k: v.tolist() for k, v in d.items()}, {"x_end": m["x_end"].tolist()},
                {"grew": grew.tolist(), "big": (np.asarray(d["x0"]) > 1.0).tolist()},
                math.nan, 1)
    words = SweepWords(
        outcomes={"grew": "x grew", OK: "ok"}, units={"x_end": "-"},
        marks={"x_end": (1.0, "x = 1")}, halving_metrics=("x_end",),
        halving_outcomes=("grew",), draws=(("a", "rate a"), ("x0", "x(0)")),
        batch_note=" (the toy's note)", not_compared="; nothing left out",
        panels=(("a", "x0", "rate a", "x(0)"),),
        groups=(("grew, big", ("grew", "big"), (), "tab:red", "x"),
                ("grew, small", ("grew",), ("big",), "tab:orange", "x"),
                ("decayed", (), ("grew",), "tab:blue", "o")),
        shade=("decayed", "x_end", "x at T"),
        alternates={"x0": ("x_start", "x start", "start of x")})
    assert words.tables(res, 3) == summary_tables(res, 3, {"grew": "x grew", OK: "ok"})
    assert "| x grew |" in words.tables(res, 3)
    fig = plt.figure()
    words.outcome_scatter(fig, res)
    ax = fig.axes[0]
    big = np.asarray(d["x0"]) > 1.0
    counts = [int((grew & big).sum()), int((grew & ~big).sum()), int((~grew).sum())]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == [f"{lab}: {k} of {N}" for lab, k in
                      zip(("grew, big", "grew, small", "decayed"), counts) if k]
    assert ax.get_ylabel() == "x(0)" and len(fig.axes) == 2      # decayed shaded by x_end
    plt.close(fig)
    fig = plt.figure()                                # the sweep has the alternate draw
    alt = Decay({**res.samples, "x_start": res.samples["x0"]}, res.metrics, res.violations,
                math.nan, 1)
    words.outcome_scatter(fig, alt)
    assert fig.axes[0].get_ylabel() == "start of x"
    plt.close(fig)
    fig, ref = plt.figure(), plt.figure()
    words.histograms(fig, res)
    draw_histograms(ref, res, {"x_end": "-"}, {"x_end": (1.0, "x = 1")})
    assert fig.axes[0].get_xlabel() == ref.axes[0].get_xlabel() == "x_end (-)"
    assert fig.axes[0].get_legend().get_texts()[0].get_text() == "x = 1"
    plt.close(fig)
    plt.close(ref)
    md = words.section(res, heading="Toy sweep", intro="Draws:", draws=[["a", "[-0.5, 2]"]],
                       summary_note="Summary:", notes=("A note.",))
    assert md.startswith("## Toy sweep\n\nDraws:\n\n| parameter | range |")
    assert md[md.index("Summary:"):] == ("Summary:\n\n" + words.tables(res, 3) + "\n\n"
                                         + rates_text(N) + "\n\nA note.\n\n" + DRAWS_TEXT)
    assert [f.name for f in words.figures(res)] == ["montecarlo-histograms",
                                                    "montecarlo-rates", "montecarlo-outcomes"]
