"""Lazy study loading (a design error answers without the solvers) and the
once-per-process study results that `workbench check` shares between verify
and the report check."""
from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np

from workbench import kinds, memo
from workbench.design import load_design

DATA = Path("tests/data")
HEAVY = ("cvxpy", "control", "matplotlib", "sympy", "scipy.optimize")


def test_registry_names_each_study_by_its_kind():
    assert sorted(kinds.REGISTRY) == sorted(kinds.STUDIES)
    for kind in kinds.REGISTRY:
        assert kinds.REGISTRY[kind].kind == kind


def test_a_design_error_imports_no_solver():
    """Exit 2 with the same one-line message, and none of the heavy
    libraries imported on the way (they load when a design runs)."""
    code = ("import sys; from workbench.cli import main; rc = main(['verify', sys.argv[1]]); "
            f"print(rc, [m for m in {HEAVY!r} if m in sys.modules])")
    out = subprocess.run([sys.executable, "-c", code, str(DATA / "bad-negative-mass.toml")],
                         capture_output=True, text=True, check=True)
    assert out.stdout.split("\n")[0] == "2 []"
    assert out.stderr.strip() == ("error: tests/data/bad-negative-mass.toml: plant.m.value = "
                                  "-5.0; expected a positive number (kg)")


def test_spec_key_is_exact():
    k = memo.spec_key
    assert k({"a": 0.1, "b": (1, 2)}) == k({"b": (1, 2), "a": 0.1})
    assert k(0.1) != k(0.1 + 2**-56)                    # floats by value, not by repr digits
    x = np.array([0.123456789012345])
    assert k(x) != k(x + 1e-15)                          # arrays by bytes, not by repr
    assert k(1) != k(1.0) and k(True) != k(1)
    assert k(object()) is None                           # unknown: never shared


def test_run_study_once_per_equal_spec():
    d = load_design(DATA / "small-cruise.toml")
    calls = []

    def run(design, started=None):
        calls.append(design.spec)
        return object()

    memo.clear()
    try:
        a = memo.run_study(d, run)
        assert memo.run_study(load_design(DATA / "small-cruise.toml"), run) is a
        other = dataclasses.replace(d, spec=dataclasses.replace(
            d.spec, sweep=dataclasses.replace(d.spec.sweep, eps=(0.5,))))
        assert memo.run_study(other, run) is not a
        assert len(calls) == 2
        assert [t.design for t in memo.study_times()] == ["small-cruise", "small-cruise"]
    finally:
        memo.clear()


def test_study_times_count_the_run_and_the_pool_apart():
    """A study with nothing to start is timed from its run; one whose pool
    started early also gets the wall time since that start."""
    import time
    from types import SimpleNamespace

    from workbench import memo

    class Study:
        def __init__(self, handle):
            self.handle = handle

        def start(self, design):
            return self.handle

    quiet = SimpleNamespace(kind="quiet", spec=("q",), name="quiet")
    pooled = SimpleNamespace(kind="pooled", spec=("p",), name="pooled")
    registry = {"quiet": Study(None), "pooled": Study(())}   # (): no pools to cancel
    memo.clear()
    try:
        memo.start_studies([quiet, pooled], registry)
        time.sleep(0.2)                       # the other designs' work, in between
        memo.run_study(quiet, lambda d: 1)
        memo.run_study(pooled, lambda d, started=None: started)
        t = {x.design: x for x in memo.study_times()}
        assert t["quiet"].since_start is None and t["quiet"].wall < 0.1
        assert t["pooled"].wall < 0.1 and t["pooled"].since_start >= 0.2
    finally:
        memo.clear()


def _double(design):
    _double.calls += 1
    return {"name": design.name, "calls": _double.calls}


_double.calls = 0


def test_run_folder_shares_results_between_processes(tmp_path, monkeypatch):
    """With WORKBENCH_STUDY_CACHE set, a result computed by one process is
    read by the next one of the run (here: the memo cleared in between)."""
    from workbench.design import load_design
    monkeypatch.setenv(memo.CACHE_ENV, str(tmp_path))
    d = load_design(DATA / "small-cruise.toml")
    memo.clear()
    try:
        first = memo.run_study(d, _double)
        assert len(list(tmp_path.glob("*.pickle"))) == 1
        memo.clear()                                   # "another process"
        assert memo.run_study(d, _double) == first and _double.calls == 1
        memo.clear()
        assert memo.run_study(d, lambda x: "fresh") == "fresh"   # no stable name: not shared
        monkeypatch.delenv(memo.CACHE_ENV)
        memo.clear()
        memo.run_study(d, _double)                     # no run folder: computed again
        assert _double.calls == 2
    finally:
        memo.clear()


def test_computed_once_per_process_and_per_run(tmp_path, monkeypatch):
    """The findings' refinement (verify.py) is computed once per run: kept in
    the process, and read back from the run folder by the next process."""
    calls = []
    compute = lambda: calls.append(1) or {"levels": (1.0, 0.5)}   # noqa: E731
    memo.clear()
    try:
        assert memo.computed_once("refine", ("k", 1), compute) == {"levels": (1.0, 0.5)}
        assert memo.computed_once("refine", ("k", 1), compute) is not None and len(calls) == 1
        memo.computed_once("refine", ("k", 2), compute)          # another key: computed
        assert len(calls) == 2
        monkeypatch.setenv(memo.CACHE_ENV, str(tmp_path))
        memo.clear()
        memo.computed_once("refine", ("k", 1), compute)          # folder empty: computed
        memo.clear()                                              # "another process"
        assert memo.computed_once("refine", ("k", 1), compute) == {"levels": (1.0, 0.5)}
        assert len(calls) == 3
    finally:
        memo.clear()


def test_perturbed_moves_physical_values_only():
    from workbench.design import perturbed
    data = {"parameters": {"m": {"value": 1.0, "unit": "kg"}, "n": {"value": 3, "unit": "-"}},
            "settings": {"dt": 0.001}, "list": [{"value": -2.5, "unit": "m"}]}
    up = perturbed(data, 3)
    assert up["parameters"]["m"]["value"] == 1.0 + 3 * 2.0 ** -52
    assert up["parameters"]["n"]["value"] == 3 and up["settings"]["dt"] == 0.001
    assert up["list"][0]["value"] == math.nextafter(math.nextafter(math.nextafter(
        -2.5, math.inf), math.inf), math.inf)
    assert perturbed(data, -1)["parameters"]["m"]["value"] == math.nextafter(1.0, 0.0)
