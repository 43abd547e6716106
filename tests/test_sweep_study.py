"""The general eps-sweep study (workbench/features/sweep_study.py and its
rendering) on a loop of no paper: x'' = x - x' + u, A = [[0, 1], [1, -1]],
B = [0; 1] (open loop unstable), with a made-up printed row, a ``[tight]``
table and two foreign gains, held by a study of its own as ``.sweep``."""
from types import SimpleNamespace

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.quantities import names, values
from workbench.features.sweep_study import (ROW_FIELDS, load_sweep, row_value, run_sweep,
                                            sweep_quantities)
from workbench.reader import Reader

A, B = np.array([[0.0, 1.0], [1.0, -1.0]]), np.array([[0.0], [1.0]])
DATA = {
    "synthesis": {"eps": [0.5, 1.0], "rel_tol": 1e-3, "h_max": 10.0,
                  "published": [{"eps": 0.5, "h_m": 0.1, "K": [-3.0, -2.0],
                                 "source": "a made-up printed row"}]},
    "tight": {"h_max": 5.0, "grid": [0.1, 1.0, 10.0], "reference_eps": 0.5},
    "other_gains": [{"name": "stabilising", "K": [-3.0, -2.0], "source": "test"},
                    {"name": "zero", "K": [0.0, 0.0], "source": "test: the open loop"}],
}


def _spec(data):
    root = Reader("toy.toml", data)
    return SimpleNamespace(sweep=load_sweep(root, root.table("synthesis")))


@pytest.fixture(scope="module")
def toy():
    spec = _spec(DATA)
    return spec, SimpleNamespace(sweep=run_sweep(A, B, spec.sweep))


def test_load_sweep_reads_every_table_and_rejects_bad_input():
    s = _spec(DATA).sweep
    assert s.eps == (0.5, 1.0) and s.settings.h_max == 10.0 and s.compare_published
    assert [p.K for p in s.published] == [(-3.0, -2.0)]
    assert s.tight.reference_eps == 0.5 and [g.name for g in s.other_gains] == ["stabilising",
                                                                                "zero"]
    with pytest.raises(DesignError, match="distinct eps"):
        _spec({"synthesis": {"eps": [0.5, 0.5]}})
    with pytest.raises(DesignError, match="unknown|not a key|expected"):
        _spec({"synthesis": {"eps": [0.5], "typo": 1}})


def test_declared_names_are_exactly_the_computed_values(toy):
    spec, res = toy
    table = sweep_quantities()
    q = values(table, spec, res)
    assert set(q) == names(table, spec)
    assert {f"synthesis.rows[eps=0.5].{f}" for f in ROW_FIELDS} <= set(q)
    assert {"tight.h_certified", "published[eps=0.5].h_paper_K",
            "other_gains[zero].abscissa", "synthesis.best.h_certified"} <= set(q)
    # with K = [-3, -2] the loop at h = 0 is s^2 + 3 s + 2 = (s + 1)(s + 2)
    assert q["other_gains[stabilising].abscissa"] == pytest.approx(-1.0, rel=1e-12)
    assert q["other_gains[zero].stable"] == "no"
    best = max(res.sweep.rows, key=lambda r: r.h_certified)
    assert q["synthesis.best.h_certified"] == best.h_certified > 0
    row = res.sweep.rows[0]
    assert q["synthesis.rows[eps=0.5].K1"] == row.K[0] and row_value(row, "status") == \
        q["synthesis.rows[eps=0.5].status"]


def test_without_comparisons_only_the_sweep_is_declared():
    spec = _spec({"synthesis": {"eps": [1.0], "rel_tol": 1e-3, "h_max": 10.0}})
    got = names(sweep_quantities(), spec)
    assert not any(n.startswith(("tight.", "published", "other_gains")) for n in got)
    assert "synthesis.rows[eps=1].h_certified" in got


def test_sections_render_each_comparison(toy):
    from workbench.features.sweep_study_render import sweep_sections
    spec, res = toy
    sections, figs = sweep_sections(res.sweep, spec.sweep.settings, A, B, heading="Sweep",
                                    reference="ours", where="the toy loop", law="u = K x",
                                    title="toy")
    text = "\n".join(sections)
    for heading in ("## Sweep", "## Comparison with the printed table",
                    "## Gains designed elsewhere, on this loop", "## Figures"):
        assert heading in text
    assert {"delay-bound-vs-eps", "loop"} <= {f.name for f in figs}


def test_loop_sweep_command_prints_the_sweep_of_a_study_that_owns_its_loop(monkeypatch,
                                                                          capsys):
    """``synthesize delay-bound`` of a kind with ``loop(design)`` and a spec's
    ``.sweep`` (workbench.kinds.delay_feedback.cli.loop_sweep_command)."""
    from workbench import kinds
    from workbench.kinds.delay_feedback.cli import loop_sweep_command
    study = SimpleNamespace(loop=lambda design: (A, B, "toy loop header"))
    monkeypatch.setattr(kinds, "REGISTRY", {"toy-loop": study})
    design = SimpleNamespace(kind="toy-loop", name="toy", spec=_spec(
        {"synthesis": {"eps": [1.0], "rel_tol": 1e-3, "h_max": 10.0}}))
    assert loop_sweep_command(design, eps=[0.5]) == 0
    out = capsys.readouterr().out
    assert out.startswith("toy loop header\n") and "| 0.5 |" in out
