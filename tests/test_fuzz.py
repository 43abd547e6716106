"""No input reaches a panic, a traceback or a hang (issue 32, item 1).

``test_fuzz_full``: the re-run's campaign (seed 3202,
benchmarks/fuzz-campaign-3202.log): 300 seeded mutations of six shipped designs
(numbers, units, expressions, structure, and the newer tables: phases, guards,
laws, ``[montecarlo]``, ``[convergence]``, ``[sampled]``) through
``synthesize``, ``verify`` and ``report`` in rotation, each in a forked child
with a 120 s limit (:mod:`tests.fuzz_designs`), then the Python API misuses of
``fuzz_designs.api_cases``; every run must exit 0, 1 (a claim failed or is
INCONCLUSIVE, with its reason) or 2 with one line. The first campaign's four
designs are among the six. It is ``slow`` and runs only when the slow tier is
selected (``pytest -m slow tests/test_fuzz.py`` or ``WORKBENCH_FULL_TIER=1``).
``test_fuzz_smoke``: 20 mutations that fail while the file is read (a few
seconds), in the default tier.
"""
import os
import sys
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_designs as fz  # noqa: E402

SMOKE_KINDS = ["duplicate_header", "deep_nesting", "huge_int", "bad_utf8", "dotdot_name",
               "deep_dotted", "empty"]


def _report(results) -> str:
    bad = [(m.design, m.kind, m.detail, c, cls, msg[-600:]) for m, c, cls, msg in results
           if cls in ("traceback", "timeout")]
    counts = Counter(cls for _, _, cls, _ in results)
    return f"{dict(counts)}; failures: {bad[:5]}"


def test_fuzz_smoke(tmp_path):
    res = fz.campaign(20260326, 20, tmp_path, SMOKE_KINDS, timeout=60.0)
    assert len(res) == 20
    assert {cls for _, _, cls, _ in res} == {"exit2"}, _report(res)
    for _, _, _, msg in res:
        assert msg.startswith("error: ") and len(msg) < 400, msg


def _slow_selected(config) -> bool:
    expr = config.getoption("-m") or ""
    return os.environ.get("WORKBENCH_FULL_TIER") == "1" or (
        "slow" in expr and "not slow" not in expr)


@pytest.mark.slow
def test_fuzz_full(tmp_path, request):
    if not _slow_selected(request.config):
        pytest.skip("the full tier: pytest -m slow tests/test_fuzz.py (about 8 minutes)")
    res = fz.campaign(3202, 300, tmp_path, timeout=120.0, newer=True)
    counts = Counter(cls for _, _, cls, _ in res)
    print("fuzz classes:", dict(counts))
    assert counts["traceback"] == 0 and counts["timeout"] == 0, _report(res)
    assert sum(counts.values()) == 300
    api = [(name, *fz.run_api(name, tmp_path, 120.0, tag=str(k)))
           for k, (name, _) in enumerate(fz.api_cases())]
    bad = [(name, cls, msg[-300:]) for name, cls, msg in api if cls not in ("exit2", "ok")]
    assert not bad and len(api) >= 30, bad


# -- the Python API, misused ------------------------------------------------------------
def _misuse_cases():
    import control

    from workbench import api
    A, B = np.array([[0.0, 1.0], [-2.0, -3.0]]), np.array([[0.0], [1.0]])
    yield "nan entry", lambda: api.simulate_delay(np.array([[np.nan]]), np.array([[1.0]]),
                                                  h=0.1, t_end=1.0, dt=0.01, x0=[1.0])
    yield "t_end 1e308", lambda: api.simulate_delay(A, B @ np.array([[1.0, 1.0]]), h=0.1,
                                                    t_end=1e308, dt=0.01, x0=[1.0, 0.0])
    yield "dt 1e-300", lambda: api.simulate_delay(A, B @ np.array([[1.0, 1.0]]), h=0.1,
                                                  t_end=1.0, dt=1e-300, x0=[1.0, 0.0])
    yield "string matrix", lambda: api.simulate_delay("A", "B", h=0.1, t_end=1.0, dt=0.01,
                                                      x0=[1.0])
    yield "transfer function", lambda: api.simulate_delay(control.tf([1], [1, 1]), 1.0,
                                                          h=0.1, t_end=1.0, dt=0.01, x0=[1.0])
    yield "negative h", lambda: api.simulate_delay(A, A, h=-1.0, t_end=1.0, dt=0.01,
                                                   x0=[1.0, 0.0])
    yield "shape mismatch", lambda: api.simulate_delay(A, np.eye(3), h=0.1, t_end=1.0,
                                                       dt=0.01, x0=[1.0, 0.0])
    U = np.array([[0.0, 1.0], [2.0, -1.0]])
    yield "huge entry", lambda: api.delay_bound(np.array([[1e300, 1.0], [2.0, -1.0]]), B,
                                                method="wirtinger")
    yield "h_max 1e308", lambda: api.delay_bound(U, B, method="wirtinger", h_max=1e308)
    yield "tf to delay_bound", lambda: api.delay_bound(control.tf([1], [1, 1]))
    yield "unknown method", lambda: api.delay_bound(U, B, method="magic")
    yield "negative order", lambda: api.delay_bound(U, B, method="bessel-legendre", N=-1)
    yield "eps text", lambda: api.delay_bound(U, B, method="free-weighting-003", eps="x")
    yield "500 states", lambda: api.delay_bound(np.eye(500), np.ones((500, 1)))


def test_api_misuse_raises_value_errors_only():
    """Every misuse is a ValueError (DesignError, ModelError are ValueErrors)
    with a message of one line, at most about 300 characters."""
    for name, call in _misuse_cases():
        try:
            call()
        except ValueError as exc:
            msg = str(exc)
            assert "\n" not in msg and len(msg) < 400, (name, msg)
        except BaseException as exc:   # noqa: BLE001 - any other exception is the failure
            pytest.fail(f"{name}: {type(exc).__name__}: {str(exc)[:300]}")
