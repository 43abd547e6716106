"""Paper 003 as an instance of the general path: designs/antiskid-cruise-dry-generic.toml
writes the adhesion plant (003 eqs 6, 9, 13 with the virtual input of eq 27) as text
equations; its ``synthesize delay-bound`` output must equal the special path's
(designs/antiskid-cruise-dry.toml) to every printed digit, same eps list."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from workbench.cli import main

ROOT = Path(__file__).resolve().parents[1]
GENERIC = str(ROOT / "designs" / "antiskid-cruise-dry-generic.toml")
SPECIAL = str(ROOT / "designs" / "antiskid-cruise-dry.toml")


@pytest.fixture(scope="module")
def outputs():
    import contextlib
    import io
    res = {}
    for name, path in (("generic", GENERIC), ("special", SPECIAL)):
        for fmt in ("text", "json"):
            buf = io.StringIO()
            with contextlib.redirect_stdout(buf):
                code = main(["synthesize", "delay-bound", path] + (["--json"] if fmt == "json"
                                                                    else []))
            res[name, fmt] = (code, buf.getvalue())
    return res


def test_same_eps_list():
    from workbench.design import load_design
    g, s = load_design(GENERIC), load_design(SPECIAL)
    assert g.spec.synthesis.eps == s.spec.sweep.eps


def test_same_linearisation_to_rounding():
    from workbench.design import load_design
    from workbench.papers.p003 import antiskid_cruise
    from workbench.kinds.delay_feedback.run import nominal_point
    _, _, op, A, B = nominal_point(load_design(GENERIC).spec)
    _, lam, _, lin = antiskid_cruise.operating_point(load_design(SPECIAL).spec)
    assert op.x[1] == pytest.approx(lam, rel=1e-13)
    np.testing.assert_allclose(A, lin.A, rtol=1e-13, atol=0)
    np.testing.assert_array_equal(B, lin.B)


def test_printed_table_equal_digit_for_digit(outputs):
    (cg, g), (cs, s) = outputs["generic", "text"], outputs["special", "text"]
    assert cg == cs == 0
    # the first line names the design and its operating point; the table and notes follow
    assert g.splitlines()[1:] == s.splitlines()[1:]
    assert len(g.splitlines()) >= 8


def test_json_rows_agree(outputs):
    """The unrounded JSON floats carry solver noise (~1e-11 relative) beyond
    the printed digits: gains, statuses and solve counts are equal, the bounds
    agree far below the printed precision."""
    (_, g), (_, s) = outputs["generic", "json"], outputs["special", "json"]
    rg, rs = json.loads(g)["rows"], json.loads(s)["rows"]
    assert len(rg) == len(rs) == 5
    for a, b in zip(rg, rs):
        for k in ("eps", "K", "exact_margin", "status", "solves"):
            assert a[k] == b[k], k
        for k in ("h_certified", "h_refuted", "h_gain", "h_design"):
            assert a[k] == pytest.approx(b[k], rel=1e-8), k
