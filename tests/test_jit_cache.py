"""The compiled kernels' disk cache (workbench/sim/jit_cache.py) and the code it
made necessary: the stiff step's halvings as a loop, bit for bit the recursion
(issue 36, item 3); the single-run fast path of the predictor's step."""
from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

numba = pytest.importorskip("numba")

from workbench.sim import jit_cache  # noqa: E402
from workbench.sim import wheel_slip_jit as W  # noqa: E402
from workbench.sim.wheel_slip import (MAX_DLAMBDA, MAX_HALVINGS, PARAM_ORDER,  # noqa: E402
                                      ScalarOps, model_functions, stiff_step)

def _params():
    """The dry design's plant (designs/antiskid-run-dry.toml), in PARAM_ORDER."""
    from workbench.design import load_design
    from workbench.papers.p003.antiskid_run_spec import plant_values
    pv = plant_values(load_design("designs/antiskid-run-dry.toml").spec)
    return np.array([pv[k] for k in PARAM_ORDER], float)


@numba.njit
def _recursive(v, lam, u, dt, p, v_floor, form, depth):
    """The recursion the loop replaced (wheel_slip_jit before the cache)."""
    f1, f20, f2u, j0, ju = W.forms(W.fmax(v, v_floor), lam, p, form)
    nv = v + dt * f1
    nl = lam + dt * W.phi1((j0 + ju * u) * dt) * (f20 + f2u * u)
    big = not abs(nl - lam) <= MAX_DLAMBDA
    if depth < MAX_HALVINGS and big:
        hv, hl, bad1 = _recursive(v, lam, u, dt / 2, p, v_floor, form, depth + 1)
        nv2, nl2, bad2 = _recursive(hv, hl, u, dt / 2, p, v_floor, form, depth + 1)
        return nv2, nl2, bad1 or bad2
    return nv, nl, big


@numba.njit
def _both(V, L, U, DT, p, form, out):
    for i in range(V.shape[0]):
        a = _recursive(V[i], L[i], U[i], DT[i], p, 1e-3, form, 0)
        b = W.stiff_step(V[i], L[i], U[i], DT[i], p, 1e-3, form)
        out[i, 0], out[i, 1], out[i, 2] = a[0], a[1], a[2]
        out[i, 3], out[i, 4], out[i, 5] = b[0], b[1], b[2]


@pytest.mark.parametrize("form", [W.BY_SIGN, W.TRACTION, W.BRAKING])
def test_halving_loop_is_the_recursion_bit_for_bit(form):
    rng = np.random.default_rng(36)
    n = 20000
    V, L = rng.uniform(0.0, 100.0, n), rng.uniform(-0.5, 0.5, n)
    U, DT = rng.uniform(-3e4, 3e4, n), 10 ** rng.uniform(-4, -0.5, n)
    out = np.empty((n, 6))
    _both(V, L, U, DT, _params(), form, out)
    assert np.array_equal(out[:, :3].view(np.int64), out[:, 3:].view(np.int64))
    # the sample reaches every depth: unresolved steps and steps never halved
    assert 0 < out[:, 2].sum() < n


def test_scalar_predictor_step_is_the_generic_step_bit_for_bit():
    from workbench.controllers.antiskid003 import _scalar_stiff_step
    fns, p = model_functions("math"), tuple(_params())
    rng = np.random.default_rng(7)
    for form in ("traction", "braking"):
        fn = fns[form]
        for _ in range(2000):
            v, lam = rng.uniform(0.0, 100.0), rng.uniform(-0.5, 0.5)
            u, dt = rng.uniform(-3e4, 3e4), 10 ** rng.uniform(-4, -0.5)
            ref = stiff_step(v, lam, u, dt, lambda vv, ll: fn(max(vv, 0.5), ll, *p), ScalarOps)
            assert _scalar_stiff_step(v, lam, u, dt, fn, 0.5, p, 0) == ref


def _env(tmp_path, **extra):
    env = {k: v for k, v in os.environ.items() if not k.startswith("WORKBENCH_")}
    return dict(env, WORKBENCH_CACHE_DIR=str(tmp_path), **extra)


_CHILD = textwrap.dedent("""
    import math, numba
    from workbench.sim.jit_cache import cached, cache_dir

    @numba.njit
    def f(x):
        return math.expm1(x) / x + max(x, 0.5)

    f = cached(f, "test.f")
    r = f(0.25)
    print(repr(r), sum(f.stats.cache_hits.values()), cache_dir())
""")


def test_a_second_process_loads_what_the_first_compiled(tmp_path):
    runs = [subprocess.run([sys.executable, "-c", _CHILD], env=_env(tmp_path), check=True,
                           capture_output=True, text=True).stdout.split() for _ in range(2)]
    assert runs[0][0] == runs[1][0] == repr(math.expm1(0.25) / 0.25 + 0.5)
    assert (runs[0][1], runs[1][1]) == ("0", "1")    # compiled, then loaded
    d = runs[0][2]
    assert d == str(tmp_path / "numba" / jit_cache.source_stamp()[:32])
    assert any(n.endswith(".nbi") for n in os.listdir(d))
    assert not [n for n in os.listdir(d) if ".tmp." in n]     # written by rename only


def test_cache_can_be_turned_off_and_an_unwritable_folder_turns_it_off(tmp_path):
    off = subprocess.run([sys.executable, "-c", _CHILD],
                         env=_env(tmp_path, WORKBENCH_NUMBA_CACHE="0"), check=True,
                         capture_output=True, text=True).stdout.split()
    assert off[1:] == ["0", "None"] and not (tmp_path / "numba").exists()
    blocker = tmp_path / "file"
    blocker.write_text("")
    bad = subprocess.run([sys.executable, "-c", _CHILD], env=_env(blocker), check=True,
                         capture_output=True, text=True).stdout.split()
    assert bad[1:] == ["0", "None"]


def test_two_functions_cannot_share_a_cache_name():
    @numba.njit
    def a(x):
        return x + 1.0

    @numba.njit
    def b(x):
        return x * 2.0

    jit_cache.cached(a, "test.shared-name")
    with pytest.raises(RuntimeError, match="share the cache name"):
        jit_cache.cached(b, "test.shared-name")


_WAITING_CHILD = _CHILD.replace("r = f(0.25)", "print('ready', flush=True)\nr = f(0.25)")


def test_two_processes_at_once_compile_once(tmp_path):
    """Two processes that miss the cache together: the second waits on the
    first's lock and loads what it compiled (issue 36: the two workers of
    `workbench check --jobs 2` start the antiskid runs together)."""
    import fcntl
    d = tmp_path / "numba" / jit_cache.source_stamp()[:32]
    d.mkdir(parents=True)
    with open(d / "test.f.lock", "a") as held:
        fcntl.flock(held, fcntl.LOCK_EX)     # both children miss and queue behind this
        kids = [subprocess.Popen([sys.executable, "-c", _WAITING_CHILD], env=_env(tmp_path),
                                 stdout=subprocess.PIPE, text=True) for _ in range(2)]
        assert [k.stdout.readline().strip() for k in kids] == ["ready", "ready"]
    outs = [k.communicate(timeout=120)[0].split() for k in kids]
    assert [k.returncode for k in kids] == [0, 0]
    assert outs[0][0] == outs[1][0] == repr(math.expm1(0.25) / 0.25 + 0.5)
    assert sorted((outs[0][1], outs[1][1])) == ["0", "1"]   # one compiled, one loaded
