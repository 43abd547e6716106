"""General parameter fitting (features.param_fit, param_fit_study) on a non-paper toy:
a first-order lag with dead time, y' = (K u(t - L) - y) / tau."""
import numpy as np
import pytest

from workbench.errors import DesignError
from workbench.features.param_fit import fit, pooled_rmse, synthetic_log
from workbench.features.param_fit_study import (compare, read_recovery, recover,
                                                recovery_table, relative_errors)
from workbench.reader import Reader

NAMES = ("K", "tau", "L")
TRUE = {"K": 2.0, "tau": 1.5, "L": 0.4}
DT = 0.02


def lag_dead_time(values, log):
    """Output at the log's samples for each row (K, tau, L): Euler at step DT."""
    values = np.atleast_2d(values)
    k, tau, delay = (values[:, i][:, None] for i in range(3))
    fine = np.arange(0.0, log.t[-1] + 1e-9, DT)
    u = np.interp(np.maximum(fine[None, :] - delay, 0.0), log.t, log.command, left=0.0)
    y = np.empty((values.shape[0], fine.size))
    y[:, 0] = log.y0
    for i in range(1, fine.size):
        y[:, i] = y[:, i - 1] + DT * (k[:, 0] * u[:, i - 1] - y[:, i - 1]) / tau[:, 0]
    step = int(round(log.dt_log / DT))
    return y[:, ::step][:, :log.t.size]


def toy_root(**fit_over):
    fit_table = {"flies": 24, "iterations": 30, "dt": DT,
                 "bounds": {"K": [0.5, 4.0], "tau": [0.3, 4.0], "L": [0.05, 1.0]}, **fit_over}
    return Reader("toy.toml", {
        "logs": [{"y0": 0.0, "duration": 12.0, "step_times": [0.0, 1.0, 6.0],
                  "step_levels": [0.0, 1.0, 0.3]}],
        "noise": {"dt_log": 0.1, "speed_sd": 0.02, "quantum": 0.001, "seed": 5},
        "fit": fit_table})


def read(root):
    return read_recovery(root, NAMES, lambda lg: lg.number("y0"))


def test_synthetic_log_is_noisy_quantised_and_seeded():
    spec = read(toy_root())
    row = np.array(list(TRUE.values()))
    a, b = (synthetic_log(lag_dead_time, row, spec.logs[0][2], y0=0.0, duration=12.0,
                          dt_log=0.1, noise_sd=0.02, quantum=0.001, seed=5) for _ in range(2))
    assert np.array_equal(a.output, b.output)
    assert np.allclose(a.output * 1000, np.round(a.output * 1000))
    noise = float(pooled_rmse(lag_dead_time, np.array([row]), [a])[0])
    assert 0.01 < noise < 0.03              # the 0.02 sd noise, seen by the RMSE


@pytest.mark.parametrize("method", ["foa", "de"])
def test_fit_recovers_gain_lag_and_dead_time(method):
    spec = read(toy_root())
    rec = recover(lag_dead_time, TRUE, spec)
    errors = relative_errors(rec, method)
    assert set(errors) == set(NAMES)
    assert all(abs(e) < 0.15 for e in errors.values()), errors
    assert getattr(rec, method).rmse < 1.5 * rec.rmse_truth


def test_fit_rejects_an_unknown_method():
    spec = read(toy_root())
    with pytest.raises(ValueError, match="expected 'foa' or 'de'"):
        fit(lag_dead_time, [], spec.bounds, method="nelder", seed=0)


def test_recovery_table_shows_truth_fits_and_derived_names():
    rec = recover(lag_dead_time, TRUE, read(toy_root(iterations=3)))
    lines = recovery_table(rec, lambda v: {**v, "K/tau": v["K"] / v["tau"]}).splitlines()
    assert "fruit fly" in lines[0] and "diff. evolution" in lines[0]
    firsts = [ln.split("|")[1].strip() for ln in lines[2:]]
    assert firsts == ["K", "tau", "L", "K/tau", "RMSE", "model runs"]
    assert str(24 * 4) in lines[-1]


def test_compare_scores_a_reference_model_and_returns_curves():
    rec = recover(lag_dead_time, TRUE, read(toy_root(iterations=3)))
    no_delay = dict(TRUE, L=0.05)
    err, curves = compare(rec, lag_dead_time, lag_dead_time, np.array(list(no_delay.values())))
    assert err > rec.rmse_truth                 # the wrong dead time fits worse than the truth
    (t, logged, fitted, ref), = curves
    assert t.shape == logged.shape == fitted.shape == ref.shape


def test_bad_bounds_and_step_are_design_errors():
    with pytest.raises(DesignError, match="lo < hi"):
        read(toy_root(bounds={"K": [2.0, 1.0], "tau": [0.3, 4.0], "L": [0.05, 1.0]}))
    with pytest.raises(DesignError, match="dividing noise.dt_log"):
        read(toy_root(dt=0.03))


def test_recovery_study_runs_a_toy_kind_with_its_quantities_json_and_verb(capsys):
    """The study object of :mod:`workbench.features.param_fit_kind` on the toy lag,
    the reference model being the lag without dead time."""
    from types import SimpleNamespace

    from workbench.features.param_fit_kind import (RecoveryModel, RecoveryNames,
                                                   RecoveryStudy)
    ref = dict(TRUE, L=0.0)
    study = RecoveryStudy(
        "toy-fit", lambda root: SimpleNamespace(recovery=read(root)),
        lambda spec: RecoveryModel(lag_dead_time, TRUE, lag_dead_time,
                                   np.array(list(ref.values()))),
        RecoveryNames("lagged", "undelayed", "1", "u"), NAMES,
        lambda v: {**v, "K/tau": v["K"] / v["tau"]})
    design = SimpleNamespace(name="toy", spec=study.load(toy_root(iterations=3)))
    res = study.run(design)
    q = study.quantities(res)
    assert set(q) == study.quantity_names(design.spec)
    assert q["rmse.undelayed"] > q["rmse.truth"]         # no dead time fits worse than the truth
    assert q["rmse.ratio_undelayed_over_lagged"] == q["rmse.undelayed"] / q["rmse.lagged_foa"]
    assert {"foa.K/tau.rel_error", "de.L.rel_error"} <= set(q)
    js = res.to_json()
    assert list(js) == ["truth", "rmse_truth_u", "rmse_undelayed_u", "foa", "de"]
    assert js["foa"]["rmse_u"] == q["rmse.lagged_foa"]
    assert study.command(design, "{name}: {logs} log", lambda r: "TABLE") == 0
    assert capsys.readouterr().out.splitlines()[:2] == ["toy: 1 log", "TABLE"]


def test_plot_curves_labels_the_axes_and_the_logs():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from workbench.features.param_fit_study import plot_curves
    rec = recover(lag_dead_time, TRUE, read(toy_root(iterations=3)))
    _, curves = compare(rec, lag_dead_time, lag_dead_time, np.array(list(TRUE.values())))
    fig = plt.figure()
    ax = fig.add_subplot(111)
    plot_curves(ax, curves, ("log {i}", "fit {i}", "ref {i}"), 10.0, ylabel="y (0.1 units)")
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("time (s)", "y (0.1 units)")
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["log 1", "fit 1", "ref 1"]
    assert np.allclose(ax.lines[0].get_ydata(), 10.0 * curves[0][1])
    plt.close(fig)
