"""Streaming sweep (issue 17, item 3): one .npz file per chunk, written as
chunks finish; --resume re-runs only the missing chunks; the summaries read
back from the files equal the in-memory sweep's, bit for bit."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.features.montecarlo_chunks import chunk_file
from workbench.papers.p003 import antiskid_montecarlo as S
from workbench.papers.p003.antiskid_montecarlo import sweep
from workbench.sim.batch import uniform_draws

N, CHUNK = 24, 8


@pytest.fixture(scope="module")
def short():
    d = load_design("designs/antiskid-run-dry.toml")
    sp = d.spec
    spec = dataclasses.replace(
        sp, scenario={**sp.scenario, "t_brake": 6.0, "t_end": 12.0},
        montecarlo=dataclasses.replace(sp.montecarlo, v0=(64.0, 68.0)))
    return dataclasses.replace(d, spec=spec)


@pytest.fixture(scope="module")
def in_memory(short):
    return sweep(short, N, 5, workers=1, chunk=CHUNK, progress=False)


def assert_identical(a, b) -> None:
    for part in ("samples", "metrics", "violations"):
        x, y = getattr(a, part), getattr(b, part)
        assert x.keys() == y.keys()
        for k in x:
            np.testing.assert_array_equal(np.asarray(x[k]), np.asarray(y[k]), err_msg=f"{part}.{k}")


def test_a_chunk_draws_its_own_samples():
    r = {"a": (0.0, 1.0), "b": (2.0, 5.0)}
    whole, tail = uniform_draws(100, 9, r), uniform_draws(100, 9, r, start=37)
    for k in r:
        np.testing.assert_array_equal(whole[k][37:], tail[k])
    with pytest.raises(ValueError, match="start = 101"):
        uniform_draws(100, 9, r, start=101)


@pytest.mark.slow
def test_stream_resume_and_refusals(short, in_memory, tmp_path, monkeypatch):
    out = tmp_path / "run"
    res = S.start_sweep(short, N, 5, out=out, workers=1, chunk=CHUNK).result()
    files = sorted(out.glob("chunk-*.npz"))
    assert [f.name for f in files] == [chunk_file(out, i, i + CHUNK).name
                                       for i in range(0, N, CHUNK)]
    assert_identical(res, in_memory)
    assert_identical(S.load_sweep(out), in_memory)

    # an interrupted sweep: one chunk missing; resume runs that chunk only
    files[1].unlink()
    with pytest.raises(FileNotFoundError, match="1 of 3 chunks not written"):
        S.load_sweep(out)
    with pytest.raises(FileExistsError, match="already holds a sweep"):
        S.start_sweep(short, N, 5, out=out, workers=1, chunk=CHUNK)
    with pytest.raises(FileExistsError, match="another sweep"):
        S.start_sweep(short, N, 6, out=out, resume=True, workers=1, chunk=CHUNK)
    ran = []
    worker = S.range_worker
    monkeypatch.setattr(S, "range_worker", lambda p: ran.append(p["i0"]) or worker(p))
    res = S.start_sweep(short, N, 5, out=out, resume=True, workers=1, chunk=CHUNK).result()
    assert ran == [CHUNK]
    assert_identical(res, in_memory)
    # every chunk written: nothing runs, the summaries come from the files (pool or not)
    for workers in (1, 2):
        res = S.start_sweep(short, N, 5, out=out, resume=True, workers=workers,
                                chunk=CHUNK).result()
        assert ran == [CHUNK]
        assert_identical(res, in_memory)


def test_cli_resume_needs_out(capsys):
    code = main(["sweep", "designs/antiskid-run-dry.toml", "--samples", "2", "--seed", "1",
                 "--resume"])
    err = capsys.readouterr().err
    assert code == 2 and "--resume = True; expected with --out DIR" in err


def test_default_chunk_is_bounded():
    """A large sweep is cut into chunks of at most MAX_CHUNK runs (streaming,
    resume and progress at a fine grain); a small one into DEFAULT_CHUNKS."""
    from workbench.features.montecarlo_chunks import DEFAULT_CHUNKS, MAX_CHUNK, default_chunk
    assert default_chunk(1) == 1
    assert default_chunk(64) == 64 // DEFAULT_CHUNKS
    assert default_chunk(10**6) == MAX_CHUNK
    assert all(1 <= default_chunk(n) <= MAX_CHUNK for n in range(1, 5000, 37))
