"""Three-level convergence claims of paper 003's runs and the oscillation
guard of their refinement (issues 33 item 4 and 36 item 5): the values are
the compensated dry run's, measured at dt, dt/2, dt/4 with the inputs as
designed and moved +3 ulp (``WORKBENCH_PERTURB_ULPS=3``)."""
import math
from types import SimpleNamespace

import pytest

from workbench.papers.p003.antiskid_refine import quarter_cases, three_level_metrics
from workbench.papers.p003.antiskid_run_spec import METRICS
from workbench.features.refinement import guarded_check, screen
from workbench.sim.convergence import CONVERGED, INCONCLUSIVE, refinement_check

#: braking time to v_stop (s) at dt, dt/2, dt/4: as designed, and moved +3 ulp.
STOP = (85.96, 86.68, 86.1425)
STOP_3ULP = (87.18, 86.28, 86.45)
#: largest creep-speed error after 5 s of braking (m/s), the same two runs.
EVS = (0.000530648, 0.00196505, 0.000119306)
EVS_3ULP = (0.00522413, 0.000765674, 0.00046013)


def test_an_oscillation_is_not_in_the_asymptotic_range():
    # the plain check calls the perturbed levels converged at order 2.4 ...
    assert refinement_check(*STOP_3ULP, tolerance=0.5).outcome == CONVERGED
    # ... the guard estimates from the larger difference at p = 0.5: 0.9 / 0.414
    r = guarded_check(*STOP_3ULP, tolerance=0.5)
    assert r.outcome == INCONCLUSIVE and r.estimate == pytest.approx(0.9 / (2 ** 0.5 - 1))
    assert "change sign" in r.note
    # both runs give the same outcome now
    assert guarded_check(*STOP, tolerance=0.5).outcome == INCONCLUSIVE


def test_the_guard_leaves_monotone_and_rounding_level_sequences_alone():
    mono = (1.0, 0.9, 0.875)
    assert guarded_check(*mono, tolerance=0.1) == refinement_check(*mono, tolerance=0.1)
    flat = (1.0, 1.0 + 2e-16, 1.0)
    assert guarded_check(*flat, tolerance=1e-9).outcome == CONVERGED
    # an oscillation that is small against the tolerance converges
    assert guarded_check(1.0, 1.001, 1.0005, tolerance=0.01).outcome == CONVERGED


def test_screen_names_what_did_not_converge():
    vals = {"a": (1.0, 0.9, 0.875), "b": STOP, "c": (math.nan,) * 3}
    assert screen(vals, {"a": 0.1, "b": 1.4, "c": 0.0}) == (None, ("b",))
    assert screen({"a": (1.0, 0.9, 0.875)}, {"a": 0.1}) == ("yes", ())
    # a metric reached at one level only is not converged
    assert screen({"a": (math.nan, 1.0, 1.0)}, {"a": 1.0}) == (None, ("a",))


def _spec():
    atol = {"braking_duration": 0.5, "evs_max_tracking": 0.002}
    return SimpleNamespace(conv_rtol=0.01, conv_atol=atol)


def test_compensated_run_is_inconclusive_both_ways_on_its_braking_time():
    for stop, evs in ((STOP, EVS), (STOP_3ULP, EVS_3ULP)):
        lv = [{k: 1.0 for k in METRICS} for _ in range(3)]
        for i in range(3):
            lv[i].update(braking_duration=stop[i], evs_max_tracking=evs[i],
                         t_diverged=math.nan)
        conv, bad = three_level_metrics(_spec(), *lv)
        # the first metric not converged is the braking time, under both
        assert bad[0] == "braking_duration" and not conv["braking_duration"]
        assert conv["t_diverged"] and conv["v_max"]


def test_only_cases_with_a_claimed_convergence_get_a_quarter_run():
    claim = lambda q: SimpleNamespace(quantity=q)
    design = SimpleNamespace(claims=(claim("cases[compensated].converged"),
                                     claim("cases[paper].comfort_converged"),
                                     claim("cases[uncompensated].diverged")))
    assert quarter_cases(design) == {"compensated", "paper"}


@pytest.mark.parametrize("ulps", ["3", "-3"])
def test_t_brake_stays_on_its_step_under_a_last_bit_move(monkeypatch, ulps):
    # t_brake = 300 s is a step time: moved 3 ulp, the braking law fired one
    # step later and the braking run moved by 1 s (issue 36 item 5)
    from workbench.design import PERTURB_ENV, load_design
    from workbench.papers.p003.antiskid_run_spec import event_time
    assert event_time(math.nextafter(math.nextafter(300.0, 400.0), 400.0)) == 300.0
    assert event_time(299.99999999999994) == 300.0 and event_time(300.25) == 300.25
    monkeypatch.setenv(PERTURB_ENV, ulps)
    spec = load_design("designs/antiskid-run-dry.toml").spec
    assert spec.scenario["t_brake"] == 300.0 and spec.scenario["t_end"] == 420.0
    assert spec.scenario["v_d"] != 70.0          # the other inputs did move


def test_creep_speed_error_at_the_stop_is_floored_at_rounding_noise():
    from workbench.papers.p003.antiskid_run_spec import EVS_FLOOR, evs_floor
    # 9.4734e-17 as designed, 9.4832e-17 with the inputs moved 3 ulp: both 0
    assert evs_floor(9.4734e-17) == evs_floor(-9.4832e-17) == 0.0
    assert evs_floor(2 * EVS_FLOOR) == 2 * EVS_FLOOR
    assert math.isnan(evs_floor(math.nan))


def test_sampled_rate_row_prints_a_tie_of_sub_steps_with_one_more_digit():
    from workbench.papers.p003.antiskid_sampled import RATE_METRICS
    from workbench.papers.p003.antiskid_sampled_render import _row
    m = {k: math.nan for k in RATE_METRICS}
    m.update(traction_diverged=math.nan, braking_diverged=math.nan, traction_ok="yes",
             braking_ok="yes", ok="yes")
    # 21 sub-steps of 0.5 ms above the requirement: 0.0105 s, a 2-digit tie
    cells = [_row("50", dict(m, time_above=t))[2] for t in (0.0105, math.nextafter(0.0105, 1))]
    assert cells == ["0.0105", "0.0105"]


def test_the_unconverged_case_says_which_metric_and_what_to_use_instead():
    """Issue 33: ``cases[compensated].converged`` INCONCLUSIVE names each
    metric not converged, its three values, its Richardson error against its
    tolerance, and the quantity to claim instead (the paper's choice for the
    braking time; a converged metric of the case otherwise)."""
    from workbench.papers.p003.antiskid_refine import CONVERGED_INSTEAD, unconverged_reason
    lv = [{k: 1.0 for k in METRICS} for _ in range(3)]
    for i in range(3):
        lv[i].update(braking_duration=STOP[i], evs_max_tracking=EVS[i])
    conv, bad = three_level_metrics(_spec(), *lv)
    why = unconverged_reason(_spec(), "compensated", *lv, bad)
    stop_est = guarded_check(*STOP, tolerance=0.0).estimate
    assert why.startswith("not converged: cases[compensated].braking_duration 85.96 / 86.68 / "
                          "86.1425 at dt, dt/2, dt/4, Richardson error ")
    assert f"Richardson error {stop_est:.2g} > tol " in why
    assert "use `cases[compensated].omega3_after_brake` instead" in why
    assert CONVERGED_INSTEAD["braking_duration"] == "omega3_after_brake" and conv[
        "omega3_after_brake"]
    assert "; cases[compensated].evs_max_tracking 0.000530648 / 0.00196505 / 0.000119306" in why
    assert why.endswith("use a metric of the case that converges instead")
    assert unconverged_reason(_spec(), "compensated", *lv, ()) == ""
