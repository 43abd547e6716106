"""Comfort: the general feature :mod:`workbench.features.comfort` on toy
speeds and toy recorded runs with an input (issues 19 item 5 and 35), whose
acceleration and jerk are known in closed form; no train model."""
from types import SimpleNamespace

import numpy as np
import pytest

from workbench.features.comfort import ComfortLimits
from workbench.features.comfort import comfort_of, comfort_quantities
from workbench.reader import Quantity

SPEC = ComfortLimits(Quantity(1.0, "m/s^2", "test"), Quantity(0.75, "m/s^3", "test"),
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
    assert comfort_of(_run(t, v, np.zeros_like(t)), None, 1e4, 0.05) is None   # no table
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


# The general feature (workbench.features.comfort) on a toy speed, no train model.

def test_feature_on_a_sine_speed_gives_the_centred_difference_exactly():
    """v = A sin(t): the centred differences over T are a = A c cos t and
    j = -A c² sin t with c = 2 sin(T/2) / T (exact, whatever the step)."""
    from workbench.features.comfort import comfort_of_speed
    A, T, step = 2.0, 0.1, 0.01
    t = np.arange(0.0, 4 * np.pi, step)
    lim = ComfortLimits(Quantity(1.0, "m/s^2", "toy"), Quantity(1.5, "m/s^3", "toy"),
                        Quantity(T, "s", "toy"))
    c = comfort_of_speed(t, A * np.sin(t), lim, step)
    k = 2 * np.sin(T / 2) / T
    assert c.a == pytest.approx(A * k * np.cos(c.t_a), abs=1e-9)
    assert c.j == pytest.approx(-A * k**2 * np.sin(c.t_j), abs=1e-7)
    assert c.a_max_abs == pytest.approx(A * k, rel=1e-4)
    # |a| = 2 k |cos t| > 1 for |cos t| > 1 / (2k): 4 arcs of 2 arccos(1/(2k)) in [0, 4 pi],
    # less T/2 at either end (a starts T/2 after the first sample, ends T/2 before the last)
    assert c.time_above_a == pytest.approx(8 * np.arccos(1 / (2 * k)) - T, abs=3 * step)
    # |j| > 1.5 on 4 stretches around t = pi/2, 3 pi/2, 5 pi/2, 7 pi/2
    mids = [(t0 + t1) / 2 for t0, t1, _ in c.jerk_windows]
    assert mids == pytest.approx([np.pi / 2, 3 * np.pi / 2, 5 * np.pi / 2, 7 * np.pi / 2],
                                 abs=2 * step)
    assert all(p > 1.5 for *_, p in c.jerk_windows)


def test_running_peaks_are_the_one_step_window_recipe():
    """Feeding acceleration samples one step at a time (a batch of runs) gives
    the peaks and times above of the recorded recipe with a one-step window,
    to the last bit, and nothing of a run after it stopped."""
    from workbench.features.comfort import RunningComfort, peak_abs, rate, time_above
    rng = np.random.default_rng(1)
    step, a = 0.05, rng.normal(size=(200, 3))
    lim = ComfortLimits(Quantity(1.0, "m/s^2", "toy"), Quantity(20.0, "m/s^3", "toy"))
    rc = RunningComfort(3, step, lim)
    active = np.ones(3, bool)
    for k, row in enumerate(a):
        active[2] = k < 100                      # run 2 stops at sample 100
        rc.add(row, active)
    m = rc.metrics()
    for r in range(2):
        j = rate(a[1:, r], a[:-1, r], step)
        assert m["peak_abs_accel"][r] == peak_abs(a[:, r])
        assert m["peak_abs_jerk"][r] == peak_abs(j)
        assert m["time_above_accel"][r] == time_above(a[:, r], 1.0, step)
        assert m["time_above_jerk"][r] == time_above(j, 20.0, step)
    assert m["peak_abs_accel"][2] == peak_abs(a[:100, 2])
    no_limits = RunningComfort(3, step)
    no_limits.add(a[0], active)
    assert set(no_limits.metrics()) == {"peak_abs_accel", "peak_abs_jerk"}


def test_rate_units():
    from workbench.features.comfort import rate_units
    assert rate_units("m/s") == ("m/s^2", "m/s^3")
    assert rate_units("km/h") == ("(km/h)/s", "(km/h)/s^2")
    assert rate_units("rad") == ("(rad)/s", "(rad)/s^2")


def test_general_peaks_converged_and_table_on_a_toy():
    """features.comfort.load_comfort / peaks_converged on no paper's run: a
    speed ramp whose slope moves with the level, read as three Comfort results."""
    from workbench.errors import DesignError
    from workbench.features.comfort import comfort_of_speed, load_comfort, peaks_converged
    from workbench.reader import Reader
    q = lambda v, u: {"value": v, "unit": u, "source": "toy"}
    root = Reader("toy.toml", {"comfort": {"a_max": q(1.0, "m/s^2"), "jerk_max": q(0.5, "m/s^3"),
                                           "window": q(1.0, "s")}})
    lim = load_comfort(root)
    assert (lim.a_max.value, lim.jerk_max.value, lim.window.value) == (1.0, 0.5, 1.0)
    assert load_comfort(Reader("toy.toml", {})) is None
    with pytest.raises(DesignError, match="comfort.window"):
        load_comfort(Reader("toy.toml", {"comfort": {"a_max": q(1.0, "m/s^2"),
                                                     "jerk_max": q(0.5, "m/s^3")}}))
    t = np.arange(0.0, 20.0 + 1e-9, 0.05)
    ramp = lambda k: comfort_of_speed(t, np.where(t < 5, k * t, 5 * k), lim, 0.05)
    assert peaks_converged((ramp(0.8), ramp(0.8), ramp(0.8))) == "yes"
    assert peaks_converged((ramp(0.84), ramp(0.8), ramp(0.798))) == "yes"
    assert peaks_converged((ramp(0.88), ramp(0.8), ramp(0.72))) is None


def test_phase_switches_and_jerk_windows_text_on_a_toy():
    """features.comfort_render on no paper's run: a three-phase toy record
    (idle, run, stop), one switch due at a known time."""
    from workbench.features.comfort_render import phase_switches, windows_text
    names = ("idle", "run", "stop")
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    phase = [0, 0, 1, 1, 2]
    assert phase_switches(t, phase, names) == [(2.0, "idle → run"), (4.0, "run → stop")]
    # the switch into "stop" was due at 3.9 s: given there, within the tolerance only
    assert phase_switches(t, phase, names, (("stop",), 3.9, 0.2))[1] == (3.9, "run → stop")
    assert phase_switches(t, phase, names, (("stop",), 3.5, 0.2))[1] == (4.0, "run → stop")
    assert phase_switches(t, phase, names, (("stop",), np.nan, 0.2))[1] == (4.0, "run → stop")
    # a switch within the group keeps its record time
    assert phase_switches(t, [0, 0, 1, 1, 2], names, (("run", "stop"), 3.9, 0.2))[1][0] == 4.0
    events = phase_switches(t, phase, names)
    text = windows_text([(1.5, 1.6, 0.912), (10.0, 11.0, 2.0)], events, 0.5)
    assert text == ("1.5-1.6 s (peak 0.91 m/s³; idle → run at 2 s); "
                    "10-11 s (peak 2 m/s³; no phase switch within the window)")
    assert windows_text([], events, 0.5) == ""


def test_plot_against_limits_on_a_toy():
    """report.case_figures.plot_against_limits: a line per trace, then each
    limit at + and - its value (+ lines first, the label on + only)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from workbench.report.case_figures import Palette, plot_against_limits
    t = np.linspace(0.0, 1.0, 11)
    fig = plt.figure()
    ax = fig.add_subplot(111)
    plot_against_limits(ax, [("a", t, np.sin(t)), ("b", t, 3 * t)], Palette({"a": "tab:red"}),
                        [(1.0, "--", "±1"), (2.0, ":", "±2")], lw=0.8)
    lines = ax.get_lines()
    assert [ln.get_label() for ln in lines[:2]] == ["a", "b"]
    assert (lines[0].get_color(), lines[1].get_color()) == ("tab:red", "tab:green")
    assert lines[0].get_linewidth() == 0.8
    assert [ln.get_ydata()[0] for ln in lines[2:]] == [1.0, 2.0, -1.0, -2.0]
    assert [ln.get_linestyle() for ln in lines[2:]] == ["--", ":", "--", ":"]
    assert [ln.get_label() for ln in lines[2:4]] == ["±1", "±2"]
    assert all(ln.get_label().startswith("_") for ln in lines[4:])   # unlabelled
    plt.close(fig)


def test_converged_column_on_a_toy():
    """features.comfort_render.converged_cell / _head / _text: a speed ramp
    whose slope moves with the level (no paper's run)."""
    from workbench.features.comfort import comfort_of_speed
    from workbench.features.comfort_render import converged_cell, converged_head, converged_text
    t = np.arange(0.0, 20.0 + 1e-9, 0.05)
    ramp = lambda k: comfort_of_speed(t, np.where(t < 5, k * t, 5 * k), SPEC, 0.05)
    assert converged_cell((ramp(0.84), ramp(0.8), ramp(0.798))) == "yes"
    assert converged_cell((ramp(0.88), ramp(0.8), ramp(0.72))) == "**not converged**"
    assert converged_cell(None) == "—"                      # no dt/4 run
    assert converged_head() == "converged, dt to dt/4 (1 %)"
    assert converged_text(0.02).startswith("Converged: the |a| and |jerk| peaks at dt, dt/2 "
                                           "and dt/4 have a Richardson error estimate within 2 %")


def test_comfort_table_and_jerk_text_on_a_toy():
    """features.comfort_render.comfort_table / jerk_text on speed ramps
    (no paper's run): one row per case with the study's extra column, and
    the stretches above the jerk limit with the events near them."""
    from workbench.features.comfort import comfort_of_speed
    from workbench.features.comfort_render import (comfort_cells, comfort_headers, comfort_table,
                                                   converged_head, jerk_text, limits_text,
                                                   window_text)
    from workbench.report.markdown import md_table
    t = np.arange(0.0, 20.0 + 1e-9, 0.05)
    ramp = lambda k: comfort_of_speed(t, np.where(t < 5, k * t, 5 * k), SPEC, 0.05)
    levels = (ramp(0.84), ramp(0.8), ramp(0.798))
    md = comfort_table([("gentle", ramp(0.8), levels, ["x1"]), ("steep", ramp(3.0), None, ["x2"])],
                       SPEC, ["extra"])
    head = md_table(["case", *comfort_headers(SPEC), "extra", converged_head()],
                    [["`gentle`", *comfort_cells(ramp(0.8)), "x1", "yes"]], "lrrrrrl")
    assert md.splitlines()[:3] == head.splitlines()
    assert md.splitlines()[3].endswith("| x2 | — |")
    steep = ramp(3.0)
    assert steep.jerk_windows                     # the ramp's corners exceed the jerk limit
    text = jerk_text("steep", steep, [(5.0, "run → hold")], SPEC)
    assert text.startswith(f"`steep`: |jerk| > {SPEC.jerk_max.value:g} m/s³ at ")
    assert "run → hold at 5 s" in text and text.endswith(").")
    assert jerk_text("flat", ramp(0.0), [], SPEC) == (
        f"`flat`: |jerk| > {SPEC.jerk_max.value:g} m/s³ at no time.")
    a, j, w = SPEC.a_max, SPEC.jerk_max, SPEC.window
    assert limits_text(SPEC, "g", "g/s") == (f"|a| <= {a.value:g} g ({a.source}) and |jerk| <= "
                                             f"{j.value:g} g/s ({j.source})")
    assert window_text(SPEC) == f"averaged over a {w.value:g} s window ({w.source})"
