"""Lazy study loading (a design error answers without the solvers) and the
once-per-process study results that `workbench check` shares between verify
and the report check."""
from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np

from workbench import memo, studies
from workbench.design import load_design

DATA = Path("tests/data")
HEAVY = ("cvxpy", "control", "matplotlib", "sympy", "scipy.optimize")


def test_registry_names_each_study_by_its_kind():
    assert sorted(studies.REGISTRY) == sorted(studies.STUDIES)
    for kind in studies.REGISTRY:
        assert studies.REGISTRY[kind].kind == kind


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
        other = dataclasses.replace(d, spec=dataclasses.replace(d.spec, eps=(0.5,)))
        assert memo.run_study(other, run) is not a
        assert len(calls) == 2
        assert [t.design for t in memo.study_times()] == ["small-cruise", "small-cruise"]
    finally:
        memo.clear()
