"""The order in which the xdist workers receive the test files (tests/conftest.py,
issue 36): longest measured file first, each file's tests in their own order; and
the wait for the check's end before the first test (`make test`)."""
import threading

from conftest import COSTS, file_costs, longest_files_first, wait_for


def test_files_go_out_longest_first_and_keep_their_inner_order():
    ids = ["tests/test_a.py::x", "tests/test_b.py::y", "tests/test_a.py::z",
           "tests/test_c.py::w", "tests/test_d.py::v", "tests/test_b.py::u"]
    costs = {"tests/test_b.py": 5.0, "tests/test_c.py": 9.0}
    got = [ids[i] for i in longest_files_first(ids, costs)]
    assert got == ["tests/test_c.py::w", "tests/test_b.py::y", "tests/test_b.py::u",
                   # unlisted: cost 0, in the order first seen
                   "tests/test_a.py::x", "tests/test_a.py::z", "tests/test_d.py::v"]
    assert sorted(longest_files_first(ids, {})) == list(range(len(ids)))


def test_the_committed_costs_parse(tmp_path):
    costs = file_costs()
    assert len(costs) > 20 and all(v > 0 for v in costs.values())
    assert all(k.startswith("tests/test_") and k.endswith(".py") for k in costs)
    assert file_costs(COSTS) == costs
    p = tmp_path / "costs.txt"
    p.write_text("# comment\n\n2.5 tests/test_x.py\n", encoding="utf-8")
    assert file_costs(p) == {"tests/test_x.py": 2.5}


def test_the_first_test_waits_for_the_check(tmp_path):
    """``wait_for`` returns at once without a flag file name, and otherwise not
    before the file exists (written here by a thread after a short delay)."""
    wait_for(None)
    wait_for("")
    flag = tmp_path / "check-done"
    timer = threading.Timer(0.3, flag.touch)
    timer.start()
    wait_for(str(flag), poll=0.01)
    assert flag.exists()            # returned only once the thread wrote it
    timer.join()
