"""The task order of `workbench check --jobs N` (workbench/checkrun.py, issue 36):
slow kinds first, but one compiled-kernel study among the first N tasks; and the
file that releases `make test`'s test session once every study result is there."""
from pathlib import Path
from types import SimpleNamespace

from workbench.checkrun import _task_order


def _designs():
    return [SimpleNamespace(path=str(p), name=p.stem, kind=k)
            for p, k in [(p, _kind(p)) for p in sorted(Path("designs").glob("*.toml"))]]


def _kind(p):
    import tomllib
    return tomllib.loads(p.read_text())["design"]["kind"]


def test_first_tasks_hold_one_compiled_study_and_nothing_is_lost():
    ds = _designs()
    runs = [d for d in ds if d.kind == "antiskid-run"]
    assert len(runs) >= 2
    for jobs in (1, 2, 3):
        order = _task_order(ds, jobs)
        assert sorted(d.name for d in order) == sorted(d.name for d in ds)
        assert sum(d.kind == "antiskid-run" for d in order[:jobs]) == 1
        assert order[0].kind == "antiskid-run"
    # two workers: the second starts a slow study that compiles nothing
    assert _task_order(ds, 2)[1].kind in ("delay-benchmark", "antiskid-robust", "platoon")


def test_studies_done_is_written_before_the_verdicts(tmp_path, monkeypatch):
    """``WORKBENCH_STUDIES_DONE``: the check creates the file after its pool
    (every study in the run folder) and before ``verify`` prints the verdicts."""
    import workbench.checkrun as cr
    flag = tmp_path / "studies-done"
    monkeypatch.setenv(cr.DONE_ENV, str(flag))
    monkeypatch.setattr(cr, "prefetch", lambda *a, **k: (set(), [], []))
    seen = []
    code = cr.check_parallel([], str(tmp_path / "out"), 2,
                             lambda: seen.append(flag.exists()) or 0, lambda checked, problems: 0)
    assert code == 0 and seen == [True]
