"""Paper 000 eqs 11-12: synthetic logs, fruit fly, differential evolution, CLI."""
import numpy as np
import pytest

from workbench.cli import main
from workbench.fit import (FITTED, fit, fruit_fly, model_speeds, rmse_cm, synthetic_log)

TABLE1 = dict(T1=0.9, T2=0.83, P1=0.85, T3=0.8, T4=1.741, K1=1.0142, K2=0.01191,  # 000 Table 1
              k_bra=0.4, v_ho=8 / 3.6, d0=2.755, d1=0.014, d2=0.00075, g=9.8)
STEPS = ((0.0, 0.0), (1.0, 0.6), (8.0, 0.8))
BOUNDS = np.array([(0.3, 1.5), (0.3, 1.5), (0.3, 1.5), (0.8, 3.0), (0.5, 2.0), (0.005, 0.02)])


@pytest.fixture(scope="module")
def log():
    return synthetic_log(TABLE1, STEPS, v0=14.0, duration=30.0, dt_log=0.2, noise_sd=0.05,
                         quantum=0.01, seed=7, dt=0.04)


def test_synthetic_log_is_sampled_quantised_and_noisy(log):
    assert np.allclose(np.diff(log.t), 0.2)
    assert np.allclose(log.output * 100, np.round(log.output * 100))
    clean = model_speeds(TABLE1, np.array([[TABLE1[k] for k in FITTED]]), log, dt=0.04)[0]
    assert 3.0 < rmse_cm(clean, log.output) < 7.0        # the 5 cm/s noise, seen by eq 12
    assert log.output[-1] < 0.2                          # stopped (one-sided noise at 0)


def test_k1_k2_enter_only_as_ratio(log):
    v = np.array([[TABLE1[k] for k in FITTED]])
    w = v.copy()
    w[0, 4:] *= 1.7
    u = v.copy()
    u[0, 4] *= 1.2
    a, b, c = (model_speeds(TABLE1, x, log, dt=0.04)[0] for x in (v, w, u))
    assert np.allclose(a, b, atol=1e-12) and not np.allclose(a, c, atol=1e-3)


def test_fruit_fly_finds_a_quadratic_minimum():
    target = np.array([0.2, 0.7, 0.5])
    f = lambda U: np.sum((np.atleast_2d(U) - target) ** 2, axis=1)
    x, fx, evals, hist = fruit_fly(f, 3, flies=20, iterations=60, seed=1)
    assert np.allclose(x, target, atol=0.02) and fx < 1e-3
    assert evals == 20 * 61 and all(a >= b for a, b in zip(hist, hist[1:]))


@pytest.mark.parametrize("method", ["foa", "de"])
def test_fit_reaches_the_noise_floor_and_recovers_identifiable_parameters(log, method):
    r = fit(TABLE1, [log], BOUNDS, method=method, dt=0.04, seed=3, flies=24, iterations=25)
    clean = model_speeds(TABLE1, np.array([[TABLE1[k] for k in FITTED]]), log, dt=0.04)[0]
    floor = float(rmse_cm(clean, log.output))
    assert r.rmse < 1.3 * floor
    got = dict(zip(FITTED, r.values))
    # T1 and T2 trade off; their sum (electric dead time + lag) is identified
    assert got["T1"] + got["T2"] == pytest.approx(0.9 + 0.83, rel=0.1)


def test_fit_verb_rejects_other_design_kinds(capsys):
    assert main(["fit", "designs/stopping-line5.toml"]) == 2
    assert "brake-fit" in capsys.readouterr().err
