"""The general rate sweep (:mod:`workbench.features.rate_sweep`) on a system
of no paper: an unstable first-order plant x' = a x + u + d under a sampled
proportional law u = -k x(t_k), quantised and held (ZOH), the plant stepped
by explicit Euler on sub-steps of at most ``step``.

With exact ZOH the loop contracts per sample by |e^{aT} - k (e^{aT} - 1) / a|;
for a = 10, k = 30 it is stable for T < ln 2 / 10, rates above
10 / ln 2 = 14.43 Hz."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from workbench.features import rate_sweep as RS
from workbench.features import rate_sweep_quantities as RQ
from workbench.sim.convergence import CONVERGED

A, K, T_END = 10.0, 30.0, 1.0
BOUNDARY_HZ = A / math.log(2.0)


def toy_run(rate, scenario, q, tau, step):
    """Scenario 0: from x = 1, no disturbance; 1: from 0, d = 1. Outputs:
    |x| at the end and its largest value."""
    assert tau == 0.0
    x, d = (1.0, 0.0) if scenario == 0 else (0.0, 1.0)
    t, peak, k_next, u = 0.0, abs(x), 0, 0.0
    T = 1.0 / rate
    while t < T_END - 1e-12:
        if t >= k_next * T - 1e-12:           # a sample: the law, quantised, held
            u = -K * x
            u = q * round(u / q) if q else u
            k_next += 1
        t_next = min(k_next * T, T_END)
        n = max(1, math.ceil((t_next - t) / step - 1e-9))
        h = (t_next - t) / n
        for _ in range(n):
            x += h * (A * x + u + d)
            peak = max(peak, abs(x))
        t = t_next
    return {"x_end": abs(x), "peak": peak}


def combine(got):
    s0, s1 = got[0], got[1]            # a scenario not run: NaN outputs (DECL.outputs)
    ok0, ok1 = s0["x_end"] < 1.0, s1["peak"] < 10.0
    return {"x_end": s0["x_end"], "peak": s1["peak"], "decays": "yes" if ok0 else "no",
            "bounded": "yes" if ok1 else "no", "ok": "yes" if ok0 and ok1 else "no"}


DECL = RS.RateMetrics(("x_end", "peak", "decays", "bounded", "ok"), (0, 1), combine,
                      {0: ("x_end", "decays"), 1: ("peak", "bounded")},
                      {"x_end": 1e-2}, mesh_max_rate=50.0, outputs=("x_end", "peak"))
RATES = (5.0, 10.0, 20.0, 50.0, 100.0)


def _counted():
    calls = []

    def run(*key):
        calls.append(key)
        return toy_run(*key)
    return RS.Runs(run), calls


def test_the_sweep_brackets_the_stability_boundary_of_a_toy_loop():
    runs, calls = _counted()
    claimed = RQ.claimed_rate_metrics(
        "toy", ["p"], RATES, DECL.names, DECL.mesh_max_rate,
        [{"quantity": "toy.p.rate[20].x_end"}, {"quantity": "toy.p.rate[100].x_end"},
         {"quantity": "toy.p.rate[50].decays"}, {"quantity": "toy.q.rate[20].x_end"}])
    assert claimed == (("p", 20.0, "x_end"), ("p", 50.0, "decays"))   # 100 Hz: above the max
    v = RS.sweep_variant(runs, DECL, RATES, 1e-4, "p", 0.0, 0.0, bisect=4, claimed=claimed)
    assert [r.ok for r in v.rows] == [False, False, True, True, True]
    assert v.min_rate == 20.0
    lo, hi = v.bracket
    assert lo < BOUNDARY_HZ < hi and hi - lo <= 1.0 and lo >= 10.0
    assert all(r.probe for r in v.probes) and 1 <= len(v.probes) <= 4
    # the mesh check: grid rates up to 50 Hz at step / 2, Euler's error within 1e-2
    assert [m[0] for m in v.mesh] == [5.0, 10.0, 20.0, 50.0]
    assert all(a for r, a, _ in v.mesh if r >= 20.0)
    # three levels: x_end at 20 Hz converges at order ~1; the 50 Hz outcome agrees
    by = {(t.rate, t.metric): t for t in v.three_level}
    t = by[(20.0, "x_end")]
    assert t.outcome == CONVERGED and t.tolerance == 1e-2 and t.values[0] == v.row(20.0).metrics[
        "x_end"]
    assert by[(50.0, "decays")].values == ("yes",) * 3 and by[(50.0, "decays")].converged
    # the growing runs below the boundary move by more than the tolerance: not converged
    assert [r for r, a, _ in v.mesh if not a] == [5.0, 10.0] and not v.mesh_converged
    # step / 4: only the scenario the claimed metric needs, and only its metrics
    quarter = {r.rate: r for r in v.quarter_rows}
    assert set(quarter[20.0].metrics) == {"x_end", "decays"}
    assert sum(1 for c in calls if c[4] == 1e-4 / 4) == 2         # 20 Hz and 50 Hz, scenario 0
    assert len(calls) == len(set(calls)) == runs.made


def test_runs_shared_between_sweeps_are_made_once():
    runs, calls = _counted()
    a = RS.sweep_variant(runs, DECL, RATES, 1e-4, "p", 0.0, 0.0, bisect=2)
    n = len(calls)
    b = RS.sweep_variant(runs, DECL, RATES, 1e-4, "p", 0.0, 0.0, bisect=2)
    assert a == b and len(calls) == n
    # a quantised variant is a different run, and coarse quantisation loses the loop
    coarse = RS.sweep_variant(runs, DECL, RATES, 1e-4, "q", 40.0, 0.0, bisect=0)
    assert len(calls) > n and coarse.row(100.0).metrics["x_end"] != a.row(100.0).metrics[
        "x_end"]
    # a partial row has the numbers of the full row, bit for bit
    full = RS.rate_row(runs, DECL, 20.0, 0.0, 0.0, 1e-4).metrics
    part = RS.partial_row(runs, DECL, 20.0, (1,), 0.0, 0.0, 1e-4).metrics
    assert set(part) == {"peak", "bounded"} and all(part[k] == full[k] for k in part)


def test_a_grid_failing_at_the_top_has_no_lowest_rate():
    runs, _ = _counted()
    v = RS.sweep_variant(runs, DECL, (2.0, 5.0, 10.0), 1e-3, "p", 0.0, 0.0)
    assert v.min_rate is None and v.bracket == (10.0, None) and v.probes == ()


@pytest.mark.parametrize("values, outcome", [
    ((1.0, 0.5, 0.25), "NOT_CONVERGED"), ((1.0, 1.0 + 1e-9, 1.0 + 1.5e-9), CONVERGED),
    (("yes", "no", "no"), "NOT_CONVERGED"), ((math.nan, 1.0, 1.0), "INCONCLUSIVE")])
def test_three_level_check_outcomes(values, outcome):
    t = RS.three_level_check("p", 20.0, "x_end", values, 1e-3)
    assert t.outcome == outcome
    assert (t.reason() == "") == (outcome == CONVERGED)
    assert np.isfinite(t.rate)


def test_mesh_replay_agrees_with_an_exact_record_and_sees_a_tampered_one():
    """x' = -x + u under a held input, recorded at the exact solution on a
    mesh: Radau agrees within its tolerance; a state moved by hand is seen."""
    from workbench.features.mesh_replay import replay
    t = np.linspace(0.0, 1.0, 101)
    u = np.where(t <= 0.5, 1.0, -1.0)      # the input over the sub-step ending at t
    x = np.empty_like(t)
    x[0] = 2.0
    for i in range(1, len(t)):
        x[i] = u[i] + (x[i - 1] - u[i]) * math.exp(-(t[i] - t[i - 1]))
    rec = np.column_stack([t, x, u])
    d_abs, d_rel, pieces = replay(lambda v: lambda s, y: -y + v, rec, 1e-10, 1e-12)
    assert pieces == 2 and d_abs[0] <= 1e-8 and d_rel[0] <= 1e-7
    bad = rec.copy()
    bad[70:, 1] += 1e-4
    assert replay(lambda v: lambda s, y: -y + v, bad, 1e-10, 1e-12)[0][0] >= 0.9e-4


def test_variants_of_a_sweep():
    assert RS.variants(0.0, 0.0) == (("zoh", 0.0, 0.0),)
    assert RS.variants(8.0, 0.0) == (("zoh", 0.0, 0.0), ("zoh_q_tau", 8.0, 0.0))
    assert RS.variants(0.0, 0.002)[1] == ("zoh_q_tau", 0.0, 0.002)


def test_quantities_of_a_toy_variant():
    runs, _ = _counted()
    v = RS.sweep_variant(runs, DECL, RATES, 1e-3, "p", 0.0, 0.0, bisect=0)
    ref = {"x_end": 0.0}
    q = RQ.quantities("toy", v, ("x_end", "ok"), "reference", ref, ("x_end",),
                      {"x_end_minus_reference": "x_end"})
    names = RQ.quantity_names("toy", "p", RATES, ("x_end", "ok"), "reference", ("x_end",),
                              {"x_end_minus_reference": "x_end"})
    assert set(q) == names
    assert q["toy.p.min_rate"] == 20.0 and q["toy.p.bracket_low"] == 10.0
    assert q["toy.p.rate[100].ok"] == "yes" and q["toy.p.mesh_converged"] is None
    assert q["toy.p.gap_to_reference.x_end"] == v.row(100.0).metrics["x_end"]
    assert q["toy.p.rate[20].x_end_minus_reference"] == q["toy.p.rate[20].x_end"]
    assert RQ.quantity_value(math.nan) is None and RQ.quantity_value("no") == "no"


def test_the_words_of_a_toy_sweep():
    """The general rendering of a sweep (:mod:`workbench.features.rate_sweep_render`)
    on the toy loop: its input is a voltage in V."""
    from types import SimpleNamespace

    from workbench.features import rate_sweep_render as RR
    from workbench.reader import Quantity
    runs, _ = _counted()
    v = RS.sweep_variant(runs, DECL, RATES, 1e-4, "p", 0.0, 0.0, bisect=4)
    zoh = SimpleNamespace(name="zoh", q=0.0, tau=0.0)
    qt = SimpleNamespace(name="zoh_q_tau", q=0.5, tau=0.002)
    assert RR.variant_label(zoh, "voltage", "V") == "ZOH (exact samples, unquantised voltage)"
    assert RR.variant_label(qt, "voltage", "V") == (
        "ZOH, voltage quantised to 0.5 V, measurement delay 2 ms")
    src = RR.variant_sources(Quantity(0.5, "V", "an 8-bit DAC"), None, "V")
    assert src == " Quantisation: 0.5 V (an 8-bit DAC)."
    label = lambda w: "proportional"                     # noqa: E731
    why = lambda w, row: "decay" if row.metrics["decays"] == "no" else "bound"  # noqa: E731
    (line,) = RR.summary_lines((v,), label, why, requirement="the decay", short="it")
    lo, hi = v.bracket
    assert line.startswith("- **proportional**: lowest rate of the grid meeting the decay "
                           "(and every higher grid rate) **20 Hz**")
    assert f"fails at {lo:g} Hz, meets at {hi:g} Hz; at {lo:g} Hz it fails in decay." in line
    text = RR.mesh_text((v,), label, DECL.mesh_atol, max_rate=50.0, step=1e-4)
    assert "every grid rate up to 50 Hz again with sub-steps of at most 0.05 ms" in text
    assert "(tolerances: x_end 0.01; the outcomes must agree)" in text
    assert text.count("| proportional |") == 4 and "**no**" in text     # 5 and 10 Hz
    (table,) = RR.rate_tables((v,), label, ["f_c (Hz)", "x_end", "ok"],
                              lambda f, m: [f, f"{m['x_end']:.3g}", m["ok"]])
    assert table.count("(bisection)") == len(v.probes) and "| 100 |" in table
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    ax = Figure().add_subplot(111)
    traces = [RS.Trace("p", f, np.arange(3.0), np.ones(3) * f) for f in (20.0, 50.0)]
    RR.plot_traces(ax, traces, "y", lambda tr: "k", lambda tr: f"{tr.rate:g} Hz", {20.0: "-"})
    assert [ln.get_label() for ln in ax.lines] == ["20 Hz", "50 Hz"]
    assert [ln.get_linestyle() for ln in ax.lines] == ["-", ":"]
    RR.mark_requirement(ax, 0.25, "x <= 0.25", "x = 0")
    base, req = ax.lines[2:]
    assert (base.get_ydata()[0], base.get_linestyle(), base.get_label()) == (0.0, "-", "x = 0")
    assert (req.get_ydata()[0], req.get_linestyle(), req.get_label()) == (0.25, ":", "x <= 0.25")
    # printed digits: NaN is "—", a value near a rounding tie gets one more digit
    assert RR.printed(math.nan, 3) == "—" and RR.printed(0.123456, 3) == "0.123"
    assert RR.printed(0.1235000001, 3) == "0.1235"
    fig = Figure()
    axes = RR.plot_rate_panels(fig, (v,), (("x_end", "x at the end", "x_end"),
                                           ("peak", "peak", "peak")), lambda w: "k", label,
                               {"x_end": 0.5, "peak": math.nan}, "reference", {"x_end": 0.5},
                               cols=1)
    assert len(axes) == 2 and axes[0].get_ylabel() == "x at the end"
    assert axes[1].get_xlabel() == "control rate f_c (Hz)" and axes[0].get_xlabel() == ""
    # x_end shifted by 0.5 with its reference at 0 (dashed); no reference drawn for NaN
    assert axes[0].lines[-1].get_label() == "reference" and axes[0].lines[-1].get_ydata()[0] == 0
    assert all(ln.get_label() != "reference" for ln in axes[1].lines)


def test_replay_windows_of_two_toy_runs():
    """Windows of two runs of x' = -x + u replayed (:func:`replay_windows`):
    one record per run spanning its windows, the windows in their order,
    a window without two mesh points left out."""
    from workbench.features.mesh_replay import replay_windows, window

    def exact(x0, u0):
        t = np.linspace(0.0, 2.0, 201)
        u = np.where(t <= 1.0, u0, -u0)
        x = np.empty_like(t)
        x[0] = x0
        for i in range(1, len(t)):
            x[i] = u[i] + (x[i - 1] - u[i]) * math.exp(-(t[i] - t[i - 1]))
        return np.column_stack([t, x, u])
    made = []

    def record(run, a, b):
        made.append((run, a, b))
        return window(exact(*run), a, b)
    wins = [("a early", 0.1, 0.5, (2.0, 1.0)), ("b", 0.9, 1.3, (0.0, 3.0)),
            ("a late", 0.8, 1.6, (2.0, 1.0)), ("a none", 1.601, 1.605, (2.0, 1.0))]
    out = replay_windows(lambda v: lambda s, y: -y + v, wins, record, 1e-10, 1e-12)
    assert made == [((2.0, 1.0), 0.1, 1.605), ((0.0, 3.0), 0.9, 1.3)]
    assert [w.name for w in out] == ["a early", "b", "a late"]
    assert [w.pieces for w in out] == [1, 2, 2]
    assert all(w.d_abs[0] <= 1e-8 for w in out) and out[0].rec[0, 0] >= 0.1
    # a window in numbers, and its table (the general rendering)
    from workbench.features.rate_sweep_render import replay_table
    c = out[1].check("run b")
    assert (c.key, c.name, c.points, c.pieces) == ("run b", "b", len(out[1].rec), 2)
    assert 0.9 <= c.t0 < c.t1 <= 1.3 and c.lo == out[1].rec[:, 1].min() < c.hi
    assert c.d_abs == out[1].d_abs and c.d_rel == out[1].d_rel
    table = replay_table([w.check(1.0) for w in out], ["run", "window", "t", "x", "pieces",
                                                       "max |dx|"], (lambda c: c.d_abs[0],))
    assert table.count("\n") == 4 and "| 1 | a early | 0.1–0.5 |" in table
    assert table.splitlines()[1] == "| :--- | :--- | :--- | ---: | ---: | ---: |"
    from workbench.features.rate_sweep_render import replay_text
    text = replay_text(table, input_name="voltage", receiver="the coil", samples=4,
                       variant="exact", rtol=1e-10, model="x' = -x + u")
    assert text.startswith("*Radau*: the voltage the coil received in a window of 4 samples "
                           "(exact) replayed") and text.endswith(table)
    assert "(rtol 1e-10)" in text and "every change of the voltage" in text


def test_windows_at_events_and_a_record_made_anyway():
    """:func:`sample_windows` places windows at events (one not reached: NaN,
    left out), shifted earlier; :func:`reusing` takes a record made anyway
    only when it runs on past the window by the margin."""
    from workbench.features.mesh_replay import reusing, sample_windows
    wins = sample_windows(("start", "event", "never"), (0.5, 2.0, math.nan), ("a", "b", "b"),
                          1.0, 0.25)
    assert wins == (("start", 0.25, 1.25, "a"), ("event", 1.75, 2.75, "b"))
    have = np.column_stack([np.linspace(0.0, 2.0, 5), np.zeros((5, 2))])
    made = []
    rec = reusing({"a": have, "b": None}, lambda run, a, b: made.append((run, a, b)) or run,
                  margin=0.5)
    assert rec("a", 0.25, 1.25) is have and made == []
    assert rec("a", 0.25, 1.75) == "a" and rec("b", 1.75, 2.75) == "b"
    assert rec("c", 0.0, 1.0) == "c" and made == [("a", 0.25, 1.75), ("b", 1.75, 2.75),
                                                   ("c", 0.0, 1.0)]


def test_a_sweep_table_is_read_and_checked():
    from workbench.errors import DesignError
    from workbench.reader import Reader
    t = Reader("toy.toml", {"rates_hz": [5.0, 10.0], "quantisation": {
        "value": 0.5, "unit": "V", "source": "DAC"}}, "sampled")
    assert RS.read_rates(t) == (5.0, 10.0)
    q, tau = RS.read_inputs(t, "V")
    assert q.value == 0.5 and tau is None
    assert RS.variants(q.value, 0.0)[1] == ("zoh_q_tau", 0.5, 0.0)
    with pytest.raises(DesignError, match="sampled.rates_hz"):
        RS.read_rates(Reader("toy.toml", {"rates_hz": [10.0, 5.0]}, "sampled"))
    # the whole general table, and a sweep of its variants on the toy loop
    t = Reader("toy.toml", {"rates_hz": [5.0, 20.0, 100.0], "plant_step": 1e-3,
                            "measurement_delay": {"value": 0.0, "unit": "s", "source": "-"},
                            "quantisation": {"value": 40.0, "unit": "V", "source": "DAC"}},
               "sampled")
    table = RS.SweepTable(**RS.read_table(t, "V", plant_step_hi=1e-2))
    t.finish()
    assert (table.rates, table.plant_step, table.bisect) == ((5.0, 20.0, 100.0), 1e-3, 4)
    assert [v[0] for v in table.variants()] == ["zoh", "zoh_q_tau"]
    with pytest.raises(DesignError, match="sampled.plant_step"):
        RS.read_table(Reader("toy.toml", {"rates_hz": [5.0], "plant_step": 0.5}, "sampled"),
                      "V", plant_step_hi=1e-2)
    runs, _ = _counted()
    out = RS.sweep(runs, DECL, dataclasses.replace(table, bisect=0))
    assert [v.name for v in out] == ["zoh", "zoh_q_tau"] and out[0].min_rate == 20.0
    assert out[1].q == 40.0 and out[1].row(100.0).metrics != out[0].row(100.0).metrics
    ref = {"x_end": 0.0, "ok": "yes"}
    q = RQ.sweep_quantities("toy", out, ("x_end", "ok"), "reference", ref, ("x_end",))
    assert set(q) == RQ.sweep_quantity_names("toy", table, ("x_end", "ok"), "reference",
                                             ("x_end",))
    assert q["toy.reference.ok"] == "yes" and q["toy.zoh_q_tau.min_rate"] == out[1].min_rate
    # the same through a Section, with a difference to the reference and the claims it reads
    sec = RQ.Section("toy", ("x_end", "ok"), 50.0, "reference", ("x_end",), {"x_minus_ref": "x_end"})
    res = RS.SweepResult(table, RS.RateRow(math.nan, ref), 1e-3, out)
    got = sec.quantities(res)
    assert set(got) == sec.quantity_names(table) and got["toy.zoh.rate[20].x_minus_ref"] == \
        got["toy.zoh.rate[20].x_end"] == q["toy.zoh.rate[20].x_end"]
    assert sec.claimed(table, [{"quantity": "toy.zoh.rate[20].x_minus_ref"},
                               {"quantity": "toy.zoh_q_tau.rate[100].ok"}]) == (
        ("zoh", 20.0, "x_end"),)                  # 100 Hz: above max_rate
    # the section's other quantities (of its own checks, say) join its names and values
    more = dataclasses.replace(sec, extra_names=("toy.runs",),
                               extra=lambda r: {"toy.runs": len(r.variants)})
    assert more.quantity_names(table) == sec.quantity_names(table) | {"toy.runs"}
    assert more.quantities(res) == {**got, "toy.runs": 2}


def test_three_levels_of_a_claimed_rate_quantity_of_a_toy_sweep():
    """:meth:`Section.levels` on the toy loop: a claimed rate metric at a rate
    the sweep's checks cover takes their rows (no run made); one above
    ``max_rate`` runs the rate at step / 2 and / 4 (once, whatever quantity
    asks); a difference to the reference stays one; a rate off the grid has
    no levels."""
    from workbench.features.refinement import Levels
    runs, calls = _counted()
    sec = RQ.Section("toy", ("x_end", "ok"), 50.0, "reference", (), {"x_minus_ref": "x_end"})
    table = RS.SweepTable((5.0, 20.0, 100.0), 1e-4, 0, three_level=sec.claimed(
        RS.SweepTable((5.0, 20.0, 100.0), 1e-4, 0), [{"quantity": "toy.zoh.rate[20].x_end"}]))
    res = RS.SweepResult(table, RS.RateRow(math.nan, {"x_end": 0.25, "ok": "yes"}), 1e-4,
                         RS.sweep(runs, DECL, table))
    n = len(calls)
    lv = sec.levels(res, "toy.zoh.rate[20].x_end", runs, DECL)
    assert isinstance(lv, Levels) and len(calls) == n
    assert lv.values == res.variant("zoh").three_level[0].values
    assert (lv.parameter, lv.step) == ("plant_step", 1e-4)
    top = sec.levels(res, "toy.zoh.rate[100].x_end", runs, DECL)
    assert [(c[0], c[4]) for c in calls[n:]] == [(100.0, 5e-5)] * 2 + [(100.0, 2.5e-5)] * 2
    assert top.values[0] == res.variant("zoh").row(100.0).metrics["x_end"]
    assert top.values[2] == toy_run(100.0, 0, 0.0, 0.0, 2.5e-5)["x_end"] != top.values[0]
    diff = sec.levels(res, "toy.zoh.rate[100].x_minus_ref", runs, DECL)
    assert len(calls) == n + 4 and diff.values == tuple(x - 0.25 for x in top.values)
    assert sec.levels(res, "toy.zoh.rate[50].ok", runs, DECL).reason == (
        "rate 50 Hz is not a grid rate")
    assert sec.rate_pattern().match("toy.zoh_q_tau.rate[1e3].ok").groups() == (
        "zoh_q_tau", "1e3")


def test_the_outcome_words_of_a_toy_rate():
    """:func:`outcome` and :func:`missed` of the general rendering on a toy
    rate with two requirements, one met, one missed (diverged or not)."""
    from workbench.features import rate_sweep_render as RR
    m = {"decay_ok": "no", "decay_diverged": 0.30625, "bound_ok": "yes",
         "bound_diverged": math.nan}
    assert RR.outcome(m, "decay", "slow") == "diverged, t = 0.3063 s"
    assert RR.outcome(m, "bound", "too high") == "meets"
    word = lambda m, r: RR.outcome(m, r, "slow")          # noqa: E731
    assert RR.missed(m, ("decay", "bound"), word) == "decay (diverged, t = 0.3063 s)"
    m.update(decay_diverged=math.nan, bound_ok="no")
    assert RR.missed(m, ("decay", "bound"), word) == "decay (slow) and bound (slow)"


def test_the_trace_records_of_a_toy_table():
    """:func:`trace_records`: every variant at the asked rates on the grid, at
    the table's plant_step, then the reference at its own rate and step."""
    from types import SimpleNamespace
    table = RS.SweepTable((5.0, 20.0), 1e-3, 0, quantisation=SimpleNamespace(value=40.0))
    got = RS.trace_records(table, (20.0, 50.0), lambda *a: a, ("reference", 200.0, 5e-3))
    assert got == [("zoh", 20.0, (20.0, 0.0, 0.0, 1e-3, False)),
                   ("zoh_q_tau", 20.0, (20.0, 40.0, 0.0, 1e-3, False)),
                   ("reference", 200.0, (200.0, 0.0, 0.0, 5e-3, True))]
    # the records are the toy loop's own runs
    assert RS.trace_records(table, (5.0,), lambda f, q, tau, step, ref: toy_run(
        f, 0, q, tau, step)["x_end"], ("reference", 5.0, 1e-3))[0][2] == toy_run(
        5.0, 0, 0.0, 0.0, 1e-3)["x_end"]
