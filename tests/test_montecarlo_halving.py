"""Step-halving check of the Monte Carlo runs (issue 5, item 1): the first n
runs of a design's sweep as one batch at dt and one at dt / 2. A shortened
dry design (braking from 10 s, run ends at 40 s; v(0) near v_d so that the
runs reach cruise) keeps this file fast."""
from __future__ import annotations

import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest

from workbench.controllers.antiskid003_settings import BRAKE, BRAKE_IN, CRUISE
from workbench.design import load_design
from workbench.features.montecarlo_halving import HalvingCheck
from workbench.features.quantities import names, values
from workbench.papers.p003.antiskid_halving import (COMPARED, HALVING_METRICS, HALVING_OUTCOMES,
                                                    QUANTITIES, start_halving)
from workbench.papers.p003.antiskid_montecarlo import draw_samples, sweep
from workbench.papers.p003.antiskid_montecarlo_render import WORDS
from workbench.papers.p003.antiskid_run_spec import SweepSpec, gain_for


def halving_section(hc, spec) -> str:
    """The report's text of the check of the design's sweep."""
    return WORDS.halving(hc, spec.montecarlo.samples)


N = 4


def halving_quantities(hc) -> dict:
    """The study's quantities of the check (its declared table on a result holding it)."""
    return values(QUANTITIES, load_design("designs/antiskid-run-dry.toml").spec,
                  SimpleNamespace(halving=hc))


@pytest.fixture(scope="module")
def short():
    """(design, K): the dry design cut to 40 s, sweep of 8 runs, v(0) in [60, 68] m/s."""
    d = load_design("designs/antiskid-run-dry.toml")
    sp = d.spec
    spec = dataclasses.replace(
        sp, scenario={**sp.scenario, "t_brake": 10.0, "t_end": 40.0},
        montecarlo=dataclasses.replace(sp.montecarlo, samples=8, halving=N, v0=(60.0, 68.0),
                                       dt=0.01))
    return dataclasses.replace(d, spec=spec), gain_for(spec)[0]


@pytest.fixture(scope="module")
def check(short) -> HalvingCheck:
    d, K = short
    return start_halving(d, N, K=K, pool=False).result()


def _nan_equal(a: HalvingCheck, b: HalvingCheck) -> None:
    """Field by field (dataclass equality is defeated by NaN != NaN)."""
    for f in dataclasses.fields(HalvingCheck):
        if f.compare:
            np.testing.assert_equal(getattr(a, f.name), getattr(b, f.name), err_msg=f.name)


def test_sweep_spec_has_halving_field():
    assert SweepSpec.__dataclass_fields__["halving"].default == 0
    assert load_design("designs/antiskid-run-dry.toml").spec.montecarlo.halving >= 0


@pytest.mark.slow   # the module's halving check fixture: ~22 s (issue 36: full tier)
def test_draws_and_coarse_batch_are_the_sweeps(short, check):
    d, K = short
    ms = d.spec.montecarlo
    assert check.n == N and check.seed == ms.seed and check.case == ms.case
    full = draw_samples(ms.samples, ms.seed, ms)        # the sweep's draws
    for k, v in check.draws.items():
        np.testing.assert_array_equal(v, full[k][:N])
    # the dt batch is the sweep of the first N runs run as one chunk: bit for bit
    res = sweep(d, N, ms.seed, workers=1, chunk=N, progress=False)
    assert res.samples == {k: list(v) for k, v in check.draws.items()}
    for m in HALVING_METRICS:
        got, want = np.asarray(check.coarse[m]), np.asarray(res.metrics[m])
        keep = ~np.isnan(got) | (m != "lam_max_over_opt")   # NaN: diverged in traction
        np.testing.assert_array_equal(got[keep], want[keep], err_msg=m)
    assert check.coarse["diverged"] == tuple(res.violations["diverged"])
    assert check.coarse["stopped"] == tuple(not x for x in res.violations["not_stopped"])
    assert check.dt == (ms.dt or d.spec.dt) and check.rtol == d.spec.conv_rtol
    assert check.atol["t_cruise"] == d.spec.conv_atol["t_cruise"]
    assert check.atol["lam_max_over_opt"] == d.spec.conv_atol.get("lam_max_over_opt", 0.0)


@pytest.mark.slow   # the module's halving check fixture: ~22 s (issue 36: full tier)
def test_flags_follow_the_rule(check):
    # each metric's flag recomputed from the stored values at both steps
    for m in HALVING_METRICS:
        for a, b, ok in zip(check.coarse[m], check.fine[m], check.agree[m]):
            tol = check.atol[m] + check.rtol * max(abs(a), abs(b))
            assert ok == ((math.isnan(a) and math.isnan(b)) or abs(a - b) <= tol)
    for o in HALVING_OUTCOMES:
        assert check.agree[o] == tuple(a == b for a, b in zip(check.coarse[o], check.fine[o]))
    assert check.run_agree == tuple(all(check.agree[k][i] for k in check.agree)
                                    for i in range(N))
    assert np.isfinite(check.fine["t_cruise"]).any()   # the short runs do reach cruise
    q = halving_quantities(check)
    assert set(q) == names(QUANTITIES, load_design("designs/antiskid-run-dry.toml").spec)
    assert q["montecarlo.halving.runs"] == N
    assert q["montecarlo.halving.agree"] == sum(check.run_agree)
    assert q["montecarlo.halving.fraction_agree"] == sum(check.run_agree) / N


def test_compare_steps_on_hand_made_values():
    nan = math.nan
    base = {"lam_max_over_opt": [0.99, 0.99, 0.99, 1.20, 0.99, 0.99],
            "t_cruise": [31.0, nan, nan, 30.0, 30.0, 30.0],
            "omega3_after_brake": [85.0, 85.0, 85.0, nan, 85.0, 85.0],
            "t_diverged": [nan, nan, nan, 12.0, nan, nan],
            "diverged": [False, False, False, True, False, False],
            "stopped": [True, True, True, False, True, True],
            "above_lambda_opt": [False] * 6,
            "phase_diverged": [nan, nan, nan, CRUISE, nan, nan]}
    fine = {k: list(v) for k, v in base.items()}
    fine["t_cruise"][0] = 31.323     # inside: |d| <= 0.01 + 0.01 max(|a|, |b|) at d < 0.32324
    fine["t_cruise"][2] = 30.0                                  # NaN against finite
    fine["lam_max_over_opt"][3] = 5.0                          # traction divergence: not compared
    fine["t_diverged"][3] = 12.2                                # within atol 0.5
    fine["omega3_after_brake"][4] = 86.37   # outside: the bound is d < 1.3637
    fine["stopped"][5] = False                                  # outcome flips
    atol = {"t_cruise": 0.01, "omega3_after_brake": 0.5, "t_diverged": 0.5}
    c, f, agree = COMPARED.compare(base, fine, 0.01, atol)
    assert agree["t_cruise"] == (True, True, False, True, True, True)     # [1]: both NaN
    assert math.isnan(c["lam_max_over_opt"][3]) and math.isnan(f["lam_max_over_opt"][3])
    assert agree["lam_max_over_opt"] == (True,) * 6
    assert agree["t_diverged"] == (True,) * 6
    assert agree["omega3_after_brake"] == (True,) * 4 + (False, True)
    assert agree["stopped"] == (True,) * 5 + (False,)
    assert c["stopped"] == tuple(base["stopped"]) and f["stopped"][5] is False
    # a divergence in braking keeps lam_max_over_opt; in traction at one step only drops it
    for ph_c, ph_f, dropped in ((BRAKE, BRAKE, False), (nan, BRAKE_IN - 1, True),
                                (BRAKE_IN, nan, False)):
        cc = {**base, "phase_diverged": [ph_c] * 6}
        ff = {**fine, "phase_diverged": [ph_f] * 6}
        c2, _, ag = COMPARED.compare(cc, ff, 0.01, atol)
        assert math.isnan(c2["lam_max_over_opt"][0]) == dropped
        assert ag["lam_max_over_opt"][3] == dropped     # 1.20 against 5.0 when compared


@pytest.mark.slow   # the module's halving check fixture: ~22 s (issue 36: full tier)
def test_deterministic_and_pool_independent(short, check):
    d, K = short
    again = start_halving(d, N, K=K, pool=False).result()
    pooled = start_halving(d, N, K=K, pool=True)
    assert pooled.workers == 2
    pooled = pooled.result()
    for other in (again, pooled):
        _nan_equal(other, check)
        assert halving_section(other, d.spec) == halving_section(check, d.spec)
        assert halving_quantities(other) == halving_quantities(check)
    assert pooled.workers == 2 and check.workers == 1


@pytest.mark.slow   # the module's halving check fixture: ~22 s (issue 36: full tier)
def test_section_text(short, check):
    d, _ = short
    md = halving_section(check, d.spec)
    assert not md.startswith("#")
    assert f"The first {N} of the sweep's 8 runs" in md and "dt = 0.01 s" in md
    assert f"**{sum(check.run_agree)} of {N} runs agree" in md
    for m in HALVING_METRICS + HALVING_OUTCOMES:
        assert f"`{m}`" in md
    if all(check.run_agree):
        assert md.endswith("Runs that disagree: none.")
    else:
        rows = sum(ln.startswith("| ") for ln in md.splitlines())
        assert rows == (2 + 4) + (2 + 3) + 2 + sum(not x for v in check.agree.values()
                                                   for x in v)
    bad = dataclasses.replace(check, agree={**check.agree, "t_cruise": (False,) * N})
    assert "Runs that disagree: none." not in halving_section(bad, d.spec)


@pytest.mark.slow   # the module's halving check fixture: ~22 s (issue 36: full tier)
def test_dt_side_taken_from_the_sweep_is_the_same_check(short, check):
    """The study reuses the sweep's first runs as the dt side (a batch run
    follows its single-run trajectory whatever its chunk mates): the check
    equals the self-contained one, with the sweep run as a bigger chunk."""
    d, K = short
    ms = d.spec.montecarlo
    res = sweep(d, ms.samples, ms.seed, workers=1, chunk=ms.samples, progress=False)
    reused = start_halving(d, N, K=K, pool=False, coarse=False).result()(res)
    for f in ("coarse", "fine"):
        for k, v in getattr(check, f).items():
            np.testing.assert_allclose(np.asarray(getattr(reused, f)[k], float),
                                       np.asarray(v, float), rtol=1e-9, err_msg=f"{f} {k}")
    assert reused.agree == check.agree
