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


# `make test` starts the test session while `workbench check` still runs (issue
# 36): pytest-xdist's workers import and collect the test files meanwhile (about
# 10 CPU s each, on the core the check's last tasks leave idle), and the session
# runs its first test only once the check has left every study result in the run
# folder (WORKBENCH_STUDY_CACHE): the file named by WORKBENCH_TESTS_AFTER exists.
AFTER_ENV = "WORKBENCH_TESTS_AFTER"


def wait_for(flag: str | None, poll: float = 0.2) -> None:
    """Return once the file ``flag`` exists (at once when ``flag`` is empty)."""
    import os
    import time
    while flag and not os.path.exists(flag):
        time.sleep(poll)


@pytest.hookimpl(tryfirst=True)
def pytest_runtestloop(session):
    """Hold the first test until the check is done (see :data:`AFTER_ENV`):
    the xdist controller hands out no test before, a plain session runs none."""
    import os
    wait_for(os.environ.get(AFTER_ENV))


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


# The order in which pytest-xdist hands out the test files (issue 36): with
# `--dist loadscope --no-loadscope-reorder` (pyproject addopts) a worker takes
# the next file in collection order when it runs out of work. Longest files
# first (tests/file_costs.txt, measured): the last file handed out is then a
# short one, and no worker idles for long at the end while the other finishes
# a long module. Tests keep their order inside a file (module fixtures).
# Only on xdist workers: a plain `pytest` run keeps the file order.
COSTS = ROOT / "tests" / "file_costs.txt"


def file_costs(path: Path = COSTS) -> dict[str, float]:
    """{test file (as in a node id): seconds} from ``tests/file_costs.txt``."""
    costs = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.strip() and not line.startswith("#"):
            seconds, name = line.split()
            costs[name] = float(seconds)
    return costs


def longest_files_first(nodeids: list[str], costs: dict[str, float]) -> list[int]:
    """The positions of ``nodeids`` reordered: files by decreasing cost (an
    unlisted file: cost 0), ties in their first-seen order, each file's tests
    in their own order."""
    first: dict[str, int] = {}
    files = [n.split("::")[0] for n in nodeids]
    for i, f in enumerate(files):
        first.setdefault(f, i)
    return sorted(range(len(nodeids)), key=lambda i: (-costs.get(files[i], 0.0),
                                                      first[files[i]], i))


def pytest_collection_modifyitems(session, config, items):
    if not hasattr(config, "workerinput"):
        return
    order = longest_files_first([it.nodeid for it in items], file_costs())
    items[:] = [items[i] for i in order]
