"""Paper 001: odd-root powers, the NTSM law of eq 13, eq 22, the platoon simulator."""
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from workbench.controllers.ntsm import (NTSMGains, convergence_time, ntsm_force,
                                        odd_root_power, surface)
from workbench.design import load_design
from workbench.errors import DesignError
from workbench.plants.platoon001 import TrainParams, external_force, perturbed
from workbench.sim.platoon import simulate_platoon
from workbench.sim.tracking import Route

DESIGN = Path("designs/platoon-ntsm-001.toml")
G = NTSMGains(beta=0.2, a=5, b=7, j=3.0, k=3.0, alpha=3, xi=5)
# paper 001 Table 1 (per-mass units garbled; SEEDS.md)
NOM = TrainParams(5e5, 5.88e3, 388.0, 8.0, 9.8)


def test_odd_root_power_is_the_real_root():
    x = np.array([-8.0, -1.0, 0.0, 1.0, 27.0])
    assert np.allclose(odd_root_power(x, 1, 3), np.cbrt(x))                 # odd: sign kept
    assert np.allclose(odd_root_power(x, 2, 3), np.cbrt(x) ** 2)            # even: >= 0
    assert np.all(odd_root_power(x, 7, 5) * x >= 0)
    with pytest.raises(ValueError):
        odd_root_power(x, 1, 2)


@pytest.mark.parametrize("kw, field", [
    (dict(a=4), "a"), (dict(a=5, b=11), "b"), (dict(alpha=5, xi=3), "alpha"),
    (dict(beta=0.0), "beta"),
])
def test_gain_conditions_of_eqs_10_12(kw, field):
    g = NTSMGains(**{**G.__dict__, **kw})
    assert field in [p[0] for p in g.problems()]
    assert G.problems() == []


def test_eq13_yields_the_reaching_law_eq12():
    """Substitute u of eq 13 into the error dynamics (eq 9) without disturbance:
    s' = e' + (b/(beta a)) |e'|^(b/a-1) e'' must equal -(j s + k sig(s)^(alpha/xi)) |e'|^(b/a-1)."""
    rng = np.random.default_rng(3)
    e, de = rng.uniform(-2, 2, 200), rng.uniform(-1, 1, 200)
    v, a_pred = rng.uniform(1, 25, 200), rng.uniform(-1, 1, 200)
    s = surface(e, de, G)
    u1 = NOM.resistance(v) + NOM.grade_force(0.004)
    u = ntsm_force(e, de, s, u1, NOM.m, a_pred, 0.0, G)
    dde = a_pred - (u - u1) / NOM.m                     # eq 9 with w = d = 0
    p = odd_root_power(de, G.b - G.a, G.a)              # |e'|^(b/a - 1)
    s_dot = de + G.b / (G.beta * G.a) * p * dde
    law = -(G.j * s + G.k * odd_root_power(s, G.alpha, G.xi)) * p
    assert np.allclose(s_dot, law, atol=1e-9)


@pytest.mark.parametrize("e0, band", [(3.0, 0.0), (3.0, 1e-3), (0.4, 1e-2)])
def test_eq22_against_integrating_the_sliding_law(e0, band):
    """On s = 0: e' = -sig(beta e)^(a/b); eq 22 (band 0) and its banded form
    against a numerical integration."""
    rhs = lambda t, y: -odd_root_power(G.beta * y, G.a, G.b)
    hit = lambda t, y: y[0] - max(band, 1e-9)
    hit.terminal = True
    sol = solve_ivp(rhs, (0, 100), [e0], events=hit, rtol=1e-10, atol=1e-12, max_step=0.01)
    floor = max(band, 1e-9)
    assert sol.t_events[0][0] == pytest.approx(convergence_time(e0, G, floor), rel=1e-4)
    # band 0 is eq 22 as printed: b/(b - a) beta^(-a/b) |e|^(1 - a/b)
    eq22 = 7 / 2 * 0.2 ** (-5 / 7) * e0 ** (2 / 7)
    assert convergence_time(e0, G) == pytest.approx(eq22, rel=1e-12)


def test_disturbances_are_bounded_and_seeded():
    w1 = external_force(4, 5000, 0.01, 5e3, 2.0, np.random.default_rng(7))
    w2 = external_force(4, 5000, 0.01, 5e3, 2.0, np.random.default_rng(7))
    assert np.array_equal(w1, w2) and np.abs(w1).max() <= 5e3 and np.abs(w1).max() > 1e3
    tp = perturbed(NOM, 4, np.random.default_rng(1), mass_spread=0.02, davis_spread=0.1)
    assert np.all(np.abs(tp.m / NOM.m - 1) <= 0.02) and np.all(np.abs(tp.c0 / NOM.c0 - 1) <= 0.1)


def _ref(t):
    return np.minimum(t, 20.0) * 0.5, np.where(t < 20.0, 0.5, 0.0)


def test_platoon_exact_model_keeps_spacing():
    """No disturbance, true = nominal: NTSM holds the spacing to well under a
    millimetre through the leader's acceleration (only the one-step-old
    predecessor acceleration separates it from exact)."""
    n, T, H = 4, 0.01, 40.0
    law = lambda e, de, u1, ap: (ntsm_force(e, de, surface(e, de, G), u1, NOM.m, ap, 0.0, G),
                                 surface(e, de, G))
    r = simulate_platoon(NOM, NOM, law, _ref, n=n, spacing=80.0, T=T, horizon=H,
                         w=np.zeros((int(H / T), n)), leader_gain=0.5, route=Route(1e9))
    assert np.abs(r.e).max() < 1e-3
    assert r.v[-1, 0] == pytest.approx(10.0, abs=0.05)
    assert np.allclose(r.x[0, 1:] - r.x[0, :-1], -80.0)


def test_platoon_initial_error_converges_near_eq22():
    n, T, H = 2, 0.01, 30.0
    law = lambda e, de, u1, ap: (ntsm_force(e, de, surface(e, de, G), u1, NOM.m, ap, 0.0, G),
                                 surface(e, de, G))
    r = simulate_platoon(NOM, NOM, law, _ref, n=n, spacing=80.0, T=T, horizon=H,
                         w=np.zeros((int(H / T), n)), leader_gain=0.5, route=Route(1e9),
                         initial_errors=np.array([2.0]))
    k = np.argmax(np.abs(r.s[:, 0]) <= 1e-3)
    t_pred = r.t[k] + convergence_time(r.e[k, 0], G, 1e-3)
    t_meas = r.t[np.nonzero(np.abs(r.e[:, 0]) > 1e-3)[0][-1] + 1]
    assert t_meas == pytest.approx(t_pred, rel=0.1)
    assert np.abs(r.e[-100:, 0]).max() < 1e-3


@pytest.mark.parametrize("old, new, key", [
    # another exponent changes the units of eq 13's terms: the unit check names the term
    ('a = { value = 5,', 'a = { value = 4,', "laws[0].definitions.s"),
    ('b = { value = 7,', 'b = { value = 11,', "laws[0].definitions.s"),
    ("initial_errors = [3.0, 2.0, 1.0]", "initial_errors = [3.0, 2.0]",
     "runs[1].initial_errors"),
    ('T = { value = 0.01, unit = "s"', 'T = { value = 0.5, unit = "s"', "platoon.T.value"),
    # the realistic scenario (tests/test_platoon_realism.py)
    ('jitter = "exponential"', 'jitter = "gaussian"', "v2v.jitter"),
    ("loss = 0.05 ", "loss = 1.5 ", "v2v.loss"),
    ('period = { value = 0.1,', 'period = { value = 0.015,', "v2v.period"),
    ('own_state = "current"', 'own_state = "later"', "v2v.own_state"),
    ("seed = 2\n", "seed = 2.5\n", "v2v.seed"),
    ('lag = { value = 0.65, unit = "s"', 'lag = { value = -0.65, unit = "s"',
     "actuator.lag.value"),
    ('brake = { value = 1.2, unit = "m/s^2"', 'brake = { value = 1.2, unit = "m/s2"',
     "actuator.brake.unit"),
    ("[actuator]   # every train, the leader included\n",
     "[actuator]   # every train, the leader included\nlagg = 1.0\n", "actuator.lagg"),
    ('time = { value = 100.0, unit = "s"', 'time = { value = 500.0, unit = "s"',
     "emergency.time"),
    ('margin = { value = 10.0, unit = "m"', 'margin = { value = "ten", unit = "m"',
     "emergency.margin.value"),
    ('law = "u1 + m*(kp*e + kd*de)"', 'law = "u1 + m*(kp*e + kd*de"', "laws[1].law"),
    ('kp = { value = 0.1, unit = "1/s^2"', 'kp = { value = 0.1, unit = "1/s"', "laws[1].law"),
    ('surface = "s"', 'surface = "u9"', "laws[0].surface"),
    ('laws = ["ntsm", "pd", "pd_ff"]', 'laws = ["ntsm", "pid"]', "emergency.laws"),
    ('law = "linear"', 'law = "ntsm"', "delay_margin.law"),
    ('module = "p001.ntsm_analysis"', 'module = "os.path"', "analysis.module"),
    ('module = "p001.ntsm_analysis"', 'module = "p001.nothing"', "analysis.module"),
])
def test_bad_designs_name_the_key(tmp_path, old, new, key):
    text = DESIGN.read_text()
    assert old in text
    p = tmp_path / DESIGN.name
    p.write_text(text.replace(old, new, 1))
    with pytest.raises(DesignError) as exc:
        load_design(p)
    assert exc.value.key == key


@pytest.mark.parametrize("name, value", [("a", 4), ("xi", 3), ("beta", -0.2)])
def test_eq10_12_conditions_are_checked_by_the_paper_module(name, value):
    """Gains that keep the units but break eqs 10-12 (an even a, alpha/xi > 1, a
    negative beta): paper 001's module names the constant."""
    import dataclasses

    from workbench.papers.p001.ntsm_analysis import PLATOON_ANALYSIS
    spec = load_design(DESIGN).spec
    c = dict(spec.constants)
    c[name] = dataclasses.replace(c[name], value=value)
    with pytest.raises(DesignError) as exc:
        PLATOON_ANALYSIS.load(None, dataclasses.replace(spec, constants=c))
    assert exc.value.key == f"constants.{name if name != 'xi' else 'alpha'}.value"


def test_study_claims_are_ok():
    from workbench.verify import evaluate_design
    ev = evaluate_design(load_design(DESIGN))
    assert ev.ok
    m = ev.result.metrics
    assert max(m["pd"].max_abs_e) > 100 * max(m["ntsm"].max_abs_e)
    assert all(c.slide_measured is not None for c in ev.result.convergence)


def test_constant_values_of_a_non_paper_platoon():
    """PlatoonSpec.constant_values on the synthetic platoon (no paper): values in
    the order asked, a missing constant names its key and what needs it."""
    spec = load_design("designs/platoon-synthetic.toml").spec
    keys = tuple(spec.constants)[:2]
    assert spec.constant_values(keys, "x") == tuple(spec.constants[k].value for k in keys)
    with pytest.raises(DesignError) as exc:
        spec.constant_values(keys + ("no_such_gain",), "the gains of my law")
    assert exc.value.key == "constants.no_such_gain" and "the gains of my law" in str(exc.value)


def test_linear_law_math_with_and_without_symbolic_forms():
    """realism_render.linear_law_math, general (synthetic platoon's gains) and with
    a law's symbolic forms before the values (as paper 001 writes them)."""
    from types import SimpleNamespace

    from workbench.kinds.platoon.realism_render import linear_law_math
    m = SimpleNamespace(k_e=0.2, k_d=0.9)
    assert linear_law_math(m) == ("$$\n(u - u_1)/m = \\dot v_{i-1} + k_e e + k_d \\dot e, "
                                  "\\qquad k_e = 0.2\\ \\mathrm{s^{-2}},\\quad k_d = 0.9"
                                  "\\ \\mathrm{s^{-1}}\n$$")
    assert "k_e = \\beta(j + k) = 0.2\\ " in linear_law_math(m, "\\beta(j + k) = ", "x = ")
    assert "k_d = x = 0.9\\ " in linear_law_math(m, "\\beta(j + k) = ", "x = ")


def test_platoon_hooks_take_a_function_or_a_fixed_text():
    """A platoon ``[analysis]`` hook (render.HOOKS) is a function of (spec, res)
    or a fixed text; without one the general text (no paper: toy analyses)."""
    from types import SimpleNamespace

    from workbench.kinds.platoon.render import _hook
    general = lambda: "general"  # noqa: E731
    assert _hook(SimpleNamespace(analysis=None), "bound_note", 3, general) == "general"
    fixed = SimpleNamespace(analysis=SimpleNamespace(bound_note="fixed"))
    assert _hook(fixed, "bound_note", 3, general) == "fixed"
    assert _hook(fixed, "comparison", 3, general) == "general"
    fn = SimpleNamespace(analysis=SimpleNamespace(bound_note=lambda spec, res: f"res {res}"))
    assert _hook(fn, "bound_note", 3, general) == "res 3"
