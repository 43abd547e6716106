"""The general ``[tight]`` comparison (workbench/features/tight_compare.py) on
a loop of no paper: Fridman & Shaked 2002 (IEEE TAC 47(11)), Example,
A = [[0, 0], [0, 1]], B = [1; 1], an open loop with an unstable pole."""
import math

import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.published_rows import Published
from workbench.features.tight_compare import (TIGHT_QUANTITIES, load_tight, run_tight,
                                              tight_quantities)
from workbench.features.tight_compare_render import tight_section
from workbench.reader import Reader
from workbench.synthesis import SynthesisSettings, synthesize_delay_bound

A, B = np.array([[0.0, 0.0], [0.0, 1.0]]), np.array([[1.0], [1.0]])
EPS = (1.0,)
ST = SynthesisSettings(rel_tol=1e-3, h_max=10.0)


def _table(data):
    return Reader("toy.toml", data)


def test_load_tight_defaults_and_bad_input():
    assert load_tight(_table({}), EPS) is None
    t = load_tight(_table({"tight": {"h_max": 5.0, "grid": [0.1, 1.0, 10.0]}}), EPS)
    assert (t.h_max, t.grid, t.order, t.reference_eps) == (5.0, (0.1, 1.0, 10.0), 2, 1.0)
    assert load_tight(_table({"tight": {"enable": False}}), EPS) is None
    with pytest.raises(DesignError, match="increasing order"):
        load_tight(_table({"tight": {"grid": [1.0, 0.1]}}), EPS)
    with pytest.raises(DesignError, match="one of synthesis.eps"):
        load_tight(_table({"tight": {"reference_eps": 0.5}}), EPS)


@pytest.fixture(scope="module")
def comparison():
    rows = synthesize_delay_bound(A, B, EPS, ST)
    ts = load_tight(_table({"tight": {"h_max": 5.0, "grid": [0.1, 1.0, 10.0]}}), EPS)
    pub = Published(1.0, 0.1, tuple(rows[0].K), "a printed toy row")
    return rows, run_tight(A, B, ts, ST, rows, (pub,))


def test_tight_gain_is_sound_and_no_worse_than_the_sweep(comparison):
    rows, t = comparison
    assert t.reference is rows[0] and not t.open_loop_hurwitz
    s = t.synthesis
    assert s.K is not None and 0 < s.h_certified <= 5.0
    # soundness: no certified delay exceeds the exact margin of the same gain
    assert t.check.h_certified <= t.check.exact.h * (1 + 1e-3)
    assert t.reference_check.h_certified <= t.reference_check.exact.h * (1 + 1e-3)
    # the printed row is the sweep's own gain here: the same analysis bound
    assert t.published_check.h_certified == pytest.approx(t.reference_check.h_certified)
    q = tight_quantities(t)
    assert set(q) == {f"tight.{k}" for k in TIGHT_QUANTITIES}
    assert q["tight.K1"] == float(s.K.ravel()[0]) and q["tight.at_cap"] in ("yes", "no")
    assert q["tight.ratio_to_reference"] == pytest.approx(s.h_certified / rows[0].h_certified)
    assert math.isfinite(q["tight.exact_margin"])


def test_tight_section_names_the_reference_row(comparison):
    _, t = comparison
    text = tight_section(t, A, B, "ours: the toy sweep")
    assert text.startswith("## Tight synthesis beyond the paper")
    assert "ours: the toy sweep" in text and "a printed toy row" in text
    assert "A is already Hurwitz" not in text
