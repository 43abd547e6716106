"""Comfort and torque of an antiskid run (issue 19, item 5), on runs whose
acceleration and jerk are known in closed form."""
from types import SimpleNamespace

import numpy as np
import pytest

from workbench.papers.p003.antiskid_comfort import ComfortSpec, comfort_of, comfort_quantities
from workbench.reader import Quantity

SPEC = ComfortSpec(Quantity(1.0, "m/s^2", "test"), Quantity(0.75, "m/s^3", "test"),
                   Quantity(1.0, "s", "test"))


def _run(t, v, u):
    return SimpleNamespace(t=t, x=np.vstack([v, np.zeros_like(v)]), u=np.atleast_2d(u))


def test_constant_acceleration_then_cruise():
    # a = 2 m/s^2 for 10 s, then 0: the 1 s averages ramp a from 2 to 0 over 1 s,
    # so the jerk peaks at -2 m/s^3 around t = 10 s
    t = np.arange(0.0, 30.0 + 1e-9, 0.05)
    v = np.where(t < 10, 2 * t, 20.0)
    c = comfort_of(_run(t, v, 1.2e4 * np.ones_like(t)), SPEC, 1e4, 0.05)
    assert c.a_max_abs == pytest.approx(2.0, rel=1e-9)
    assert c.jerk_max_abs == pytest.approx(2.0, rel=1e-9)
    # the 1 s averages start at t = 0.5 s and cross 1 m/s^2 at t = 10 s
    assert c.time_above_a == pytest.approx(9.5, abs=0.06)
    assert len(c.jerk_windows) == 1
    t0, t1, peak = c.jerk_windows[0]
    assert 9.0 <= t0 < 10.0 < t1 <= 11.0 and peak == pytest.approx(2.0)
    assert c.u_max_over_peak == pytest.approx(1.2)


def test_within_the_limits_nothing_is_flagged():
    t = np.arange(0.0, 60.0 + 1e-9, 0.05)
    v = 0.25 * t**2 / 60.0 * 2           # a = t / 60 <= 1 m/s^2, jerk 1/60 m/s^3
    c = comfort_of(_run(t, v, np.zeros_like(t)), SPEC, 1e4, 0.05)
    assert c.a_max_abs <= 1.0 and c.time_above_a == 0.0
    assert c.jerk_max_abs == pytest.approx(1 / 60, rel=1e-6) and c.jerk_windows == ()


def test_converged_flag_refines_the_peaks_three_levels():
    t = np.arange(0.0, 30.0 + 1e-9, 0.05)
    run = lambda k: comfort_of(_run(t, np.where(t < 10, k * t, 10 * k), np.ones_like(t)),
                               SPEC, 1.0, 0.05)
    fine = run(2.0)
    q = lambda *lv: comfort_quantities("x", *lv)["cases[x].comfort_converged"]
    assert q(fine, fine, fine) == "yes"
    # peaks 2.1 / 2.0 / 1.995: first order, estimate 0.005 < 1 % of 2.1
    assert q(fine, run(2.1), run(1.995)) == "yes"
    # 2.2 / 2.0 / 1.8: order 0 (not in the asymptotic range), 0.2 / (sqrt 2 - 1) > 1 %
    assert q(fine, run(2.2), run(1.8)) is None
    # no dt/4 run: a two-level agreement is no convergence
    assert q(fine, fine) is None


@pytest.mark.parametrize("t_show", [300.0000000001, 299.99999999])
def test_switch_to_braking_is_given_at_t_brake(t_show):
    # which record sample first shows braking (300 or 300.05 s) depends on
    # the last bit of the accumulated time: the text gives t_brake either way
    from workbench.papers.p003.antiskid_comfort_render import _switches
    ph = [2, 2, 4, 4] if t_show > 300 else [2, 2, 2, 4]
    run = SimpleNamespace(t=np.array([299.9, 299.95, t_show, 300.05]), phase=ph)
    c = SimpleNamespace(run=run, metrics={"t_brake": 300.0, "omega3_after_brake": np.nan})
    assert _switches(c, SimpleNamespace(profile={"omega_switch": 3.0})) == [
        (300.0, "cruise → braking")]
