"""CLI exit codes, bad input, claims and verdicts, reports and their freshness."""
import json
from pathlib import Path

import pytest

from workbench.claims import Verdict, check_claim
from workbench.cli import main
from workbench.design import load_design

DATA = Path("tests/data")
GOLDEN = Path("tests/golden")
BAD = sorted(DATA.glob("bad-*.toml"))


def test_enough_malformed_designs():
    assert len(BAD) >= 10


@pytest.mark.parametrize("path", BAD, ids=lambda p: p.stem)
def test_malformed_design_exits_2_with_one_message(path, capsys):
    first = path.read_text().splitlines()[0]
    key = first.split("error about ")[1].strip()
    assert main(["synthesize", "delay-bound", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "Traceback" not in err
    assert str(path) in err and key in err and "expected" in err
    assert main(["verify", str(path)]) == 2


def test_bad_arguments_exit_2(capsys):
    assert main(["synthesize", "delay-bound"]) == 2
    assert main(["frobnicate"]) == 2
    assert main(["synthesize", "delay-bound", "designs/antiskid-cruise-dry.toml",
                 "--eps", "-1"]) == 2
    assert "--eps" in capsys.readouterr().err
    assert main(["verify", "no/such/design.toml"]) == 2


def test_synthesize_json(capsys):
    code = main(["synthesize", "delay-bound", "designs/antiskid-cruise-dry.toml",
                 "--eps", "0.35", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert code == 0
    assert out["design"] == "antiskid-cruise-dry"
    (row,) = out["rows"]
    assert set(row) >= {"eps", "h_certified", "h_refuted", "K", "exact_margin", "status",
                        "solves", "seconds"}
    assert row["exact_margin"] == "inf" and row["status"] == "certified"
    assert 0.0433 <= row["h_certified"] < 0.0434


def test_synthesize_table(capsys):
    assert main(["synthesize", "delay-bound", "designs/antiskid-cruise-dry.toml",
                 "--eps", "0.35", "0.25"]) == 0
    out = capsys.readouterr().out
    assert "h_certified" in out and "h* (eig)" in out and "∞" in out


def test_verify_passing_and_failing(capsys):
    assert main(["verify", str(DATA / "small-cruise.toml")]) == 0
    capsys.readouterr()
    assert main(["verify", str(DATA / "failing-claim.toml")]) == 1
    out = capsys.readouterr().out
    assert "h-0.35" in out and "FAIL" in out
    assert main(["verify", "--json", str(DATA / "failing-claim.toml")]) == 1
    data = json.loads(capsys.readouterr().out)
    bad = [c for c in data["designs"][0]["claims"] if not c["ok"]]
    assert [c["id"] for c in bad] == ["h-0.35"]


def _claim(**kw):
    d = load_design(DATA / "small-cruise.toml")
    from dataclasses import replace
    return replace(d.claims[0], **kw)


def test_claim_semantics():
    c = _claim(compare="==", value=0.0433, digits=4, rounding="truncate")
    assert check_claim(c, 0.043399).verdict is Verdict.PASS
    assert check_claim(c, 0.04340).verdict is Verdict.FAIL
    assert check_claim(c, None).verdict is Verdict.INCONCLUSIVE
    assert not check_claim(c, None).ok
    assert check_claim(_claim(compare="==", value=0.0433, digits=4, rounding="truncate",
                              allow_inconclusive=True), None).ok
    c = _claim(compare="within", value=1.0, tolerance=0.1, digits=None)
    assert check_claim(c, 1.09).verdict is Verdict.PASS
    assert check_claim(c, 1.11).verdict is Verdict.FAIL
    c = _claim(compare="==", value=float("inf"), digits=None)
    assert check_claim(c, float("inf")).verdict is Verdict.PASS
    assert check_claim(c, 1e9).verdict is Verdict.FAIL
    xf = _claim(compare=">=", value=1.0, digits=None, expect="fail", reason="r")
    assert check_claim(xf, 0.5).ok and not check_claim(xf, 2.0).ok


@pytest.fixture(scope="module")
def small_report(tmp_path_factory):
    """A folder holding ``workbench report tests/data/small-cruise.toml``, written
    once for the tests of this file that read it or copy it (the tests that
    write into a report folder work on their own copy)."""
    out = tmp_path_factory.mktemp("small-report")
    import os
    cwd = os.getcwd()
    os.chdir(Path(__file__).resolve().parents[1])      # DATA is relative to the root
    try:
        assert main(["report", str(DATA / "small-cruise.toml"), "--out", str(out)]) == 0
    finally:
        os.chdir(cwd)
    return out


def _copy_report(src, dst):
    import shutil
    shutil.copytree(src, dst, dirs_exist_ok=True)


def test_golden_report(tmp_path, request, small_report):
    """The report of a small design, byte for byte (regenerate with --regen-golden)."""
    src = DATA / "small-cruise.toml"
    md = (small_report / "small-cruise.md").read_text()
    assert (small_report / "small-cruise" / "delay-bound-vs-eps.png").is_file()
    golden = GOLDEN / "small-cruise.md"
    if request.config.getoption("--regen-golden"):
        GOLDEN.mkdir(exist_ok=True)
        golden.write_text(md)
    # the commit line is the one line that changes with every commit (issue 33, item 6)
    from workbench.report.writer import _sans_commit
    assert _sans_commit(md) == _sans_commit(golden.read_text())
    # same inputs, same bytes
    assert main(["report", str(src), "--out", str(tmp_path / "again")]) == 0
    assert (tmp_path / "again" / "small-cruise.md").read_text() == md


def test_report_check_detects_stale_and_missing(tmp_path, capsys, small_report):
    """A fresh report passes ``--check``; an edited Markdown, a figure one byte
    longer and a missing figure each fail it (exit 1)."""
    src = str(DATA / "small-cruise.toml")
    _copy_report(small_report, tmp_path)               # the fresh report (`report --out`)
    assert main(["report", src, "--out", str(tmp_path), "--check"]) == 0
    md = tmp_path / "small-cruise.md"
    md.write_text(md.read_text() + "edited\n")
    assert main(["report", src, "--out", str(tmp_path), "--check"]) == 1
    _copy_report(small_report, tmp_path)               # fresh again
    png = tmp_path / "small-cruise" / "delay-bound-vs-eps.png"
    png.write_bytes(png.read_bytes() + b"\0")      # a figure is compared byte for byte
    assert main(["report", src, "--out", str(tmp_path), "--check"]) == 1
    assert "stale figure" in capsys.readouterr().out
    png.unlink()
    assert main(["report", src, "--out", str(tmp_path), "--check"]) == 1
    assert "missing figure" in capsys.readouterr().out


def test_report_is_markdown_with_math_tables_and_relative_images(small_report):
    md = (small_report / "small-cruise.md").read_text()
    assert "$$\n" in md and "| :---" in md or "| ---:" in md
    assert "](small-cruise/delay-bound-vs-eps.png)" in md
    for section in ("## Problem", "## Model", "## Operating point", "## Certified delay bounds",
                    "## Claims", "## Provenance"):
        assert section in md
