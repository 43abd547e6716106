"""Files (issue 32, item 3): names, paths, atomic and set-wise replacement,
pool workers that die with their parent, errors that name their cause."""
import multiprocessing as mp
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from workbench.cli import main
from workbench.errors import DesignError
from workbench.report.files import (atomic_write, check_name, inside, replace_set,
                                    _journal, _roll_forward)

ROOT = Path(__file__).resolve().parents[1]
DESIGN = ROOT / "designs" / "antiskid-cruise-dry.toml"


def test_a_design_named_dotdot_exits_2_and_writes_nothing(tmp_path, capsys):
    """A file ``...toml`` (stem ``..``) with ``name = ".."``: report would write
    its figures one level above reports/."""
    work = tmp_path / "w"
    work.mkdir()
    text = DESIGN.read_text().replace('name = "antiskid-cruise-dry"', 'name = ".."')
    (work / "...toml").write_text(text)
    before = sorted(tmp_path.rglob("*"))
    assert main(["report", str(work / "...toml"), "--out", str(work / "reports")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "design.name = '..'" in err, err
    assert "file-name-safe" in err and "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == before


@pytest.mark.parametrize("bad", ["..", ".", "a/b", "a\\b", "", ".hidden", "x" * 200, "a\0b"])
def test_unsafe_names_are_refused(bad):
    with pytest.raises(DesignError, match="no path separator"):
        check_name(bad)


def test_paths_outside_the_folder_are_refused(tmp_path):
    with pytest.raises(DesignError, match="a path inside"):
        atomic_write(tmp_path / "out" / ".." / "escape.md", "x", folder=tmp_path / "out")
    assert not (tmp_path / "escape.md").exists()
    assert inside(tmp_path, tmp_path / "a" / "b") == tmp_path / "a" / "b"


def _writer(path, tag, n, errors):
    try:
        for i in range(n):
            atomic_write(Path(path), f"{tag}:{i}\n" * 2000)
    except BaseException as exc:    # noqa: BLE001 - the test reports any failure
        errors.put(f"{tag}: {type(exc).__name__}: {exc}")


def test_two_concurrent_writers_never_fail(tmp_path):
    """The fixed ``<path>.tmp`` made 3-6 of 40 writes of each writer fail."""
    path = tmp_path / "r.md"
    errors = mp.get_context("fork").Queue()
    procs = [mp.get_context("fork").Process(target=_writer, args=(path, t, 40, errors))
             for t in "ab"]
    for p in procs:
        p.start()
    for p in procs:
        p.join(60)
    assert [p.exitcode for p in procs] == [0, 0]
    assert errors.empty(), errors.get()
    lines = set(path.read_text().splitlines())
    assert lines in ({"a:39"}, {"b:39"})                     # whole, one writer's last
    assert [p.name for p in tmp_path.iterdir()] == ["r.md"]  # no temporary left
    assert oct(path.stat().st_mode & 0o777) != oct(0o600)    # not mkstemp's private mode


def test_a_report_is_replaced_as_a_set(tmp_path):
    out = tmp_path / "reports"
    replace_set(out, "d", "old\n", {"a.png": b"A0", "b.png": b"B0"})
    assert (out / "d.md").read_text() == "old\n" and sorted(os.listdir(out / "d")) == \
        ["a.png", "b.png"]
    replace_set(out, "d", "new\n", {"a.png": b"A1"})
    assert (out / "d.md").read_text() == "new\n"
    assert os.listdir(out / "d") == ["a.png"] and (out / "d" / "a.png").read_bytes() == b"A1"
    assert sorted(os.listdir(out)) == ["d", "d.md"]           # no stage, journal or old set


def test_a_killed_set_write_is_rolled_forward_or_left_old(tmp_path):
    out = tmp_path / "reports"
    replace_set(out, "d", "old\n", {"a.png": b"A0"})
    # killed before the journal: the old set stays, the stage is dropped later
    stage = out / ".d.new-killed"
    (stage / "d").mkdir(parents=True)
    (stage / "d" / "a.png").write_bytes(b"half")
    assert (out / "d.md").read_text() == "old\n"
    os.utime(stage, (time.time() - 3600, time.time() - 3600))
    # killed after the journal, with the old folder already moved away: rolled forward
    stage2 = out / ".d.new-journaled"
    (stage2 / "d").mkdir(parents=True)
    (stage2 / "d" / "a.png").write_bytes(b"A1")
    (stage2 / "d.md").write_text("new\n")
    _journal(out, "d").write_text(stage2.name)
    _roll_forward(out, "d")
    assert (out / "d.md").read_text() == "new\n" and (out / "d" / "a.png").read_bytes() == b"A1"
    assert sorted(os.listdir(out)) == ["d", "d.md"]


_PARENT = textwrap.dedent("""
    import sys, time
    from workbench.sim.batch import PendingBatch

    def collect(outs, s, w):
        return outs

    if __name__ == "__main__":
        b = PendingBatch(time.sleep, [60.0, 60.0], collect, workers=2, pool=True)
        time.sleep(1.5)
        print(" ".join(str(p) for p in b._pool._processes), flush=True)
        time.sleep(120)
""")


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split(") ")[1][0] != "Z"
    except FileNotFoundError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="prctl is Linux's")
def test_pool_workers_die_with_their_parent(tmp_path):
    """A SIGKILL of the parent (a killed sweep) leaves no pool worker alive."""
    script = tmp_path / "parent.py"
    script.write_text(_PARENT)
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        pids = [int(p) for p in proc.stdout.readline().split()]
        assert len(pids) == 2 and all(_alive(p) for p in pids)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    deadline = time.time() + 10
    while any(_alive(p) for p in pids) and time.time() < deadline:
        time.sleep(0.1)
    assert not any(_alive(p) for p in pids)


def test_a_chunk_write_failure_names_the_folder_not_the_scheduler(tmp_path, monkeypatch,
                                                                    capsys):
    """Under any scheduler, an OSError writing a chunk is an --out problem."""
    from workbench.papers.p003 import antiskid_run

    class Refused:
        def result(self, progress=False):    # a chunk's file cannot be written
            raise OSError(28, "No space left on device")
    # the name the sweep command calls (imported into antiskid_run)
    monkeypatch.setattr(antiskid_run, "start_sweep", lambda *a, **k: Refused())
    code = main(["sweep", str(ROOT / "designs/antiskid-run-dry.toml"), "--samples", "2",
                 "--seed", "1", "--workers", "1", "--kernel", "numpy",
                 "--out", str(tmp_path / "chunks")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "--out" in err and "No space left" in err and "--scheduler" not in err
