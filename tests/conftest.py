from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT / "tests" / "data"


@pytest.fixture(autouse=True)
def _repo_cwd(monkeypatch):
    """Run every test from the repository root (designs/ and reports/ are relative)."""
    monkeypatch.chdir(ROOT)


def pytest_addoption(parser):
    parser.addoption("--regen-golden", action="store_true",
                     help="rewrite golden files instead of comparing with them")


# A timeline for CI logs: with WORKBENCH_TEST_TIMELINE=1 (set by .ci/run) the
# first start of each test file is written to stderr with the seconds since the
# session began, so a run cut short by a time limit still shows where the time went.
_TIMELINE = {"t0": 0.0, "seen": set()}


def pytest_sessionstart(session):
    import time
    _TIMELINE["t0"] = time.monotonic()


def pytest_runtest_logstart(nodeid, location):
    import os
    import sys
    import time
    path = nodeid.split("::")[0]
    if not os.environ.get("WORKBENCH_TEST_TIMELINE") or path in _TIMELINE["seen"]:
        return
    _TIMELINE["seen"].add(path)
    sys.stderr.write(f"\n[{time.monotonic() - _TIMELINE['t0']:7.1f} s] {path}\n")
    sys.stderr.flush()
