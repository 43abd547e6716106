"""The task order of `workbench check --jobs N` (workbench/checkrun.py, issue 36):
slow kinds first, but one compiled-kernel study among the first N tasks."""
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
