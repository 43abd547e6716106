"""The reduced Monte Carlo sample of an antiskid-run design: seeded, the same
summary whatever the worker count, byte-identical Markdown, quantities for
claims, bad [montecarlo] keys rejected (short horizons: the full sample runs
in `workbench verify`)."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from workbench.cli import main
from workbench.design import load_design
from workbench.features.quantities import names, values
from workbench.papers.p003 import antiskid_run as R
from workbench.papers.p003.antiskid_montecarlo import (QUANTITIES, VIOLATIONS, draw_samples,
                                                       start_sweep, sweep)
from workbench.papers.p003.antiskid_montecarlo_render import WORDS
from workbench.papers.p003.antiskid_run_render import _montecarlo_section

DRY = Path("designs/antiskid-run-dry.toml")


def _short(tmp_path, samples=6, chunk=3, workers=2) -> Path:
    """The dry design cut to its first 10 s (braking from 9.5 s), with a
    small reduced sample."""
    text = DRY.read_text()
    text = text.replace('value = 300.0,  unit = "s"', 'value = 9.5,  unit = "s"')
    text = text.replace("value = 420.0,", "value = 10.0,")
    for key, val in (("samples", samples), ("chunk", chunk), ("workers", workers),
                     ("halving_samples", min(2, samples))):
        old = next(ln for ln in text.splitlines() if ln.startswith(f"{key} = "))
        text = text.replace(old, f"{key} = {val}", 1)
    path = tmp_path / "antiskid-run-dry.toml"
    path.write_text(text)
    return path


def test_draws_are_prefix_stable():
    ms = load_design(DRY).spec.montecarlo
    a, b = draw_samples(5, 3, ms), draw_samples(50, 3, ms)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k][:5])
        assert np.all((a[k] >= min(b[k])) & (a[k] <= max(b[k])))
    assert not np.array_equal(draw_samples(5, 4, ms)["h"], a["h"])


def test_same_seed_same_summary_any_worker_count(tmp_path):
    d = load_design(_short(tmp_path))
    pool_of_1 = start_sweep(d, 6, 5, workers=1, chunk=3, pool=True)   # as the study runs it
    in_process = sweep(d, 6, seed=5, workers=1, chunk=3, progress=False)   # meanwhile
    runs = (in_process, pool_of_1.result(), sweep(d, 6, seed=5, workers=2, chunk=3,
                                                  progress=False))
    for r in runs[1:]:
        np.testing.assert_equal(r.metrics, in_process.metrics)    # bit for bit (NaN = NaN)
        np.testing.assert_equal(r.statistics(), in_process.statistics())
        assert WORDS.tables(r, 3) == WORDS.tables(in_process, 3)
    assert np.isfinite(in_process.metrics["lam_max_over_opt"]).all()


def test_study_quantities_and_identical_markdown(tmp_path):
    d = load_design(_short(tmp_path, samples=4, chunk=4, workers=1))
    spec = d.spec
    declared = names(QUANTITIES, spec)
    assert declared <= R.STUDY.quantity_names(spec)
    # the study's Monte Carlo part only (the cases are covered elsewhere)
    res = [sweep(d, 4, spec.montecarlo.seed, workers=w, chunk=2, progress=False)
           for w in (1, 2)]
    q = values(QUANTITIES, spec, SimpleNamespace(montecarlo=res[0]))
    assert set(q) == declared and q["montecarlo.samples"] == 4
    stats = {k.removeprefix("montecarlo."): v for k, v in q.items()}
    t_c = np.asarray(res[0].metrics["t_cruise"])
    assert stats["t_cruise.n_finite"] == np.isfinite(t_c).sum()
    if np.isfinite(t_c).any():
        assert stats["t_cruise.median"] == np.median(t_c[np.isfinite(t_c)])
    assert stats["fraction.not_stopped"] == 1.0       # braking from 9.5 s, run ends at 10 s
    assert 0.0 <= stats["fraction.diverged"] <= 1.0
    md = [_montecarlo_section(d, r) for r in res]
    assert md[0] == md[1]
    assert "## Monte Carlo robustness" in md[0] and "montecarlo-histograms.png" in md[0]
    for label in VIOLATIONS.values():
        assert label.replace("|", "\\|") in md[0]


@pytest.mark.parametrize("line, key", [("samples = 0", "montecarlo.samples"),
                                       ("samples = 6.5", "montecarlo.samples"),
                                       ("workers = 0", "montecarlo.workers"),
                                       ("chunk = -1", "montecarlo.chunk"),
                                       ("halving_samples = 7", "montecarlo.halving_samples")])
def test_bad_montecarlo_keys_are_exit_2(tmp_path, capsys, line, key):
    path = _short(tmp_path)
    name = line.split(" = ")[0]
    text = path.read_text()
    old = next(ln for ln in text.splitlines() if ln.startswith(f"{name} = "))
    path.write_text(text.replace(old, line, 1))
    assert main(["verify", str(path)]) == 2
    assert key in capsys.readouterr().err
