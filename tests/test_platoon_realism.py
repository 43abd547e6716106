"""Paper 001 made realistic: the V2V link, the actuator, the leader's emergency
brake against the braking-distance envelope, the PD + feed-forward baseline and
the exact delay margin of the NTSM's linear member."""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from workbench.claims import Verdict, check_claim
from workbench.cli import main
from workbench.controllers.ntsm import NTSMGains, linear_member, pd_ff_force, pd_force
from workbench.design import load_design
from workbench.margins import delay_margin_eig, delay_margin_siso
from workbench.kinds.platoon.realism import (delay_margin_model, emergency_run, envelope,
                                             linear_gains, link)
from workbench.kinds.platoon.run import scenario
from workbench.plants.platoon001 import TrainParams
from workbench.sim.platoon import Actuator, Link, packet_delays, received_steps

DESIGN = Path("designs/platoon-ntsm-001.toml")
G = NTSMGains(beta=0.2, a=5, b=7, j=3.0, k=3.0, alpha=3, xi=5)


@pytest.fixture(scope="module")
def spec():
    return load_design(DESIGN).spec


def _short(spec, **link_changes):
    """The design with the emergency right after the leader's acceleration (45 s):
    a 105 s emergency run instead of 160 s."""
    em = dataclasses.replace(spec.emergency, time=dataclasses.replace(spec.emergency.time,
                                                                      value=45.0))
    return dataclasses.replace(spec, emergency=em,
                               link=dataclasses.replace(spec.link, **link_changes))


# -- design keys (bad values: tests/test_platoon.py::test_bad_designs_name_the_key) ---------
def test_bad_realism_key_is_exit_2_with_one_line(tmp_path, capsys):
    p = tmp_path / DESIGN.name
    p.write_text(DESIGN.read_text().replace('jitter = "exponential"', 'jitter = "gauss"', 1))
    assert main(["verify", str(p)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "v2v.jitter = 'gauss'" in err and "expected one of" in err and p.name in err


# -- the V2V link ---------------------------------------------------------------------------
def test_received_steps_holds_the_newest_packet():
    # packets every 2 steps; delays in steps 1, 4, 1, 1, 1; packet 3 lost
    T = 0.1
    delays = np.array([[0.1], [0.4], [0.1], [0.1], [0.1]])
    lost = np.array([[False], [False], [False], [True], [False]])
    src = received_steps(10, T=T, period=0.2, delays=delays, lost=lost)[:, 0]
    # packet 0 (sent 0) at 1; packet 2 (sent 4) at 5 before packet 1 (sent 2) at 6,
    # which is older and ignored; packet 3 lost; packet 4 (sent 8) at 9
    assert src.tolist() == [0, 0, 0, 0, 0, 4, 4, 4, 4, 8]
    with pytest.raises(ValueError, match="multiple of T"):
        received_steps(10, T=T, period=0.15, delays=delays, lost=lost)
    with pytest.raises(ValueError, match="one row per packet"):
        received_steps(12, T=T, period=0.2, delays=delays, lost=lost)


def test_packet_delays_are_seeded_and_shaped():
    d1 = packet_delays(1000, 3, delay=0.2, jitter=0.1, distribution="exponential",
                       rng=np.random.default_rng(5))
    d2 = packet_delays(1000, 3, delay=0.2, jitter=0.1, distribution="exponential",
                       rng=np.random.default_rng(5))
    assert np.array_equal(d1, d2) and d1.min() >= 0.2
    assert (d1 - 0.2).mean() == pytest.approx(0.1, rel=0.1)
    u = packet_delays(1000, 3, delay=0.2, jitter=0.1, distribution="uniform",
                      rng=np.random.default_rng(5))
    assert u.min() >= 0.2 and u.max() <= 0.3
    assert np.all(packet_delays(4, 2, delay=0.3, jitter=0.1, distribution="none",
                                rng=None) == 0.3)


def test_random_link_is_seeded_and_extends_with_the_run(spec):
    a, lost_a = link(spec, "random", 4000)
    b, lost_b = link(spec, "random", 4000)
    assert np.array_equal(a.source, b.source) and lost_a == lost_b
    longer, _ = link(spec, "random", 6000)
    assert np.array_equal(longer.source[:4000], a.source)       # same realisation, longer
    other, _ = link(dataclasses.replace(spec, link=dataclasses.replace(spec.link, seed=3)),
                    "random", 4000)
    assert not np.array_equal(other.source, a.source)
    const, lost_c = link(spec, "constant", 4000)
    age = np.arange(4000)[20:, None] - const.source[20:]
    assert lost_c == 0.0 and age.min() == 20 and age.max() == 29     # 0.2 s + up to 0.09 s


def test_a_perfect_link_and_actuator_give_back_the_ideal_run(spec):
    """Packet every step, no delay or loss, lag 0, no limits: byte-identical to
    the ideal simulator path."""
    sc = scenario(spec)
    K = 1500
    src = received_steps(K, T=spec.T, period=spec.T, delays=np.zeros((K, spec.n - 1)),
                         lost=np.zeros((K, spec.n - 1), bool))
    ideal = sc.simulate("ntsm", horizon=K * spec.T)
    real = sc.simulate("ntsm", horizon=K * spec.T, link=Link(src, "current"),
                       actuator=Actuator(0.0, -np.inf, np.inf))
    assert np.array_equal(ideal.x, real.x) and np.array_equal(ideal.u, real.u)


def test_actuator_lag_and_limits():
    """One train at rest, a step command: the applied force follows the exact
    first-order response, and a command beyond the limit is clipped."""
    from workbench.sim.platoon import simulate_platoon
    from workbench.sim.tracking import Route
    T, lag, K = 0.01, 0.65, 300
    one = TrainParams(5e5, 0.0, 0.0, 0.0, 9.8)                     # nominal
    two = TrainParams(np.array([5e5, 5e5]), 0.0, 0.0, 0.0, 9.8)     # true, per train
    ref = lambda t: (np.zeros_like(t), np.zeros_like(t))
    for cmd, limit in ((2e5, 1e6), (2e6, 5e5)):
        law = lambda e, de, u1, ap: (np.full_like(e, cmd), np.zeros_like(e))
        r = simulate_platoon(one, two, law, ref, n=2, spacing=80.0, T=T, horizon=K * T,
                             w=np.zeros((K, 2)), leader_gain=0.0, route=Route(1e9),
                             actuator=Actuator(lag, -limit, limit))
        c = min(cmd, limit)
        t1 = (np.arange(K) + 1) * T
        # mean over each step of c (1 - exp(-t/lag))
        mean = c * (1 - lag / T * (np.exp(-(t1 - T) / lag) - np.exp(-t1 / lag)))
        assert np.allclose(r.force[:, 1], mean, rtol=1e-12)


# -- the baseline and the surrogate ----------------------------------------------------------
def test_pd_ff_is_pd_plus_the_communicated_acceleration(spec):
    rng = np.random.default_rng(0)
    e, de, ap, u1 = (rng.uniform(-1, 1, 3) for _ in range(4))
    u = pd_ff_force(e, de, u1, 5e5, ap, 0.1, 0.6)
    assert np.allclose(u, u1 + 5e5 * (0.1 * e + 0.6 * de + ap))
    assert np.allclose(u - pd_force(e, de, u1, 5e5, 0.1, 0.6), 5e5 * ap)
    law = scenario(spec).law("pd_ff")           # the design's law uses kp_ff, kd_ff
    got, s = law(e, de, u1, ap)
    c = spec.constants
    assert np.array_equal(got, pd_ff_force(e, de, u1, spec.nominal().m, ap, c["kp_ff"].value,
                                           c["kd_ff"].value)) and not s.any()


def test_linear_member_is_eq13_with_unit_powers():
    """b = a, alpha = xi, no switching: eq 13's (u - u1)/m reduces to
    a_pred + k_e e + k_d e' with k_e = beta (j + k), k_d = beta + j + k."""
    from workbench.controllers.ntsm import ntsm_force, surface
    lin = NTSMGains(beta=0.2, a=5, b=5, j=3.0, k=3.0, alpha=5, xi=5)
    rng = np.random.default_rng(1)
    e, de, ap = rng.uniform(-1, 1, 20), rng.uniform(-1, 1, 20), rng.uniform(-1, 1, 20)
    u = ntsm_force(e, de, surface(e, de, lin), 0.0, 1.0, ap, 0.0, lin)
    k_e, k_d = linear_member(G)
    assert (k_e, k_d) == pytest.approx((1.2, 6.2))
    assert np.allclose(u, ap + k_e * e + k_d * de)
    # the design's linear law carries exactly these gains (read off the law with m = 1)
    assert linear_gains(load_design(DESIGN).spec) == (k_e, k_d)


def test_delay_margin_model_against_the_closed_form():
    """Without lag e'' = -k_e e(t-h) - k_d e'(t-h): omega^4 = k_e^2 + k_d^2 omega^2,
    h* = atan2(k_d omega, k_e) / omega (Gu, Kharitonov & Chen 2003, sec. 2.2)."""
    k_e, k_d = linear_member(G)
    A, B, K = delay_margin_model(0.0, k_e, k_d)
    w = math.sqrt((k_d ** 2 + math.sqrt(k_d ** 4 + 4 * k_e ** 2)) / 2)
    h = math.atan2(k_d * w, k_e) / w
    assert delay_margin_eig(A, B @ K).h == pytest.approx(h, rel=1e-9)
    assert delay_margin_siso(A, B, K).h == pytest.approx(h, rel=1e-9)
    A, B, K = delay_margin_model(0.65, k_e, k_d)            # with the design's lag
    assert delay_margin_eig(A, B @ K).h == pytest.approx(delay_margin_siso(A, B, K).h,
                                                         rel=1e-9)
    assert delay_margin_eig(A, B @ K).h < h                   # the lag costs margin


# -- the emergency brake and the envelope ----------------------------------------------------
def test_envelope_is_the_relative_braking_distance():
    assert envelope(np.array(20.0), np.array(20.0), reaction=1.0, brake=1.2,
                    margin=10.0) == pytest.approx(30.0)
    assert envelope(np.array(20.0), np.array(10.0), reaction=0.0, brake=1.0,
                    margin=0.0) == pytest.approx((400 - 100) / 2)
    assert envelope(np.array(10.0), np.array(20.0), reaction=0.0, brake=1.0, margin=5.0) == 5.0


def test_emergency_is_deterministic(spec):
    sp = _short(spec)
    K = int(round(105.0 / sp.T))
    a = emergency_run(scenario(sp), "ntsm", link(sp, "random", K)[0])
    b = emergency_run(scenario(sp), "ntsm", link(sp, "random", K)[0])
    assert np.array_equal(a.run.x, b.run.x) and a.min_gap == b.min_gap
    assert a.stopped


def _claim(cid):
    return next(c for c in load_design(DESIGN).claims if c.id == cid)


def test_the_gap_claim_flips_with_heavy_packet_loss(spec):
    """The PD + feed-forward envelope claim holds on the design's random link
    (5 % loss) and fails when 90 % of the packets are lost (the follower holds
    data seconds old and learns of the emergency brake too late)."""
    claim = _claim("pd-ff-gap-above-envelope")
    K = int(round(105.0 / spec.T))
    margin = {loss: emergency_run(scenario(sp), "pd_ff", link(sp, "random", K)[0]).min_margin
              for loss, sp in ((loss, _short(spec, loss=loss)) for loss in (0.05, 0.9))}
    assert check_claim(claim, margin[0.05]).verdict is Verdict.PASS
    assert check_claim(claim, margin[0.9]).verdict is Verdict.FAIL


def test_the_gap_claim_flips_with_the_delay_in_the_loop(spec):
    """With the gap taken at the packet's time stamp a 1 s constant delay makes
    the PD (no feed-forward) close the gap to a collision under the emergency
    brake; with the design's 0.2 s it stays above the envelope."""
    claim = _claim("pd-gap-above-envelope")
    K = int(round(105.0 / spec.T))
    got = {}
    for delay in (0.2, 1.0):
        sp = _short(spec, own_state="stamped",
                    delay=dataclasses.replace(spec.link.delay, value=delay))
        got[delay] = emergency_run(scenario(sp), "pd", link(sp, "constant", K)[0])
    assert check_claim(claim, got[0.2].min_margin).verdict is Verdict.PASS
    assert check_claim(claim, got[1.0].min_margin).verdict is Verdict.FAIL
    assert got[1.0].min_gap < 0 < got[0.2].min_gap


def test_design_quantities(spec):
    """The whole study (memoised with the other tests of this process)."""
    from workbench.verify import evaluate_design
    ev = evaluate_design(load_design(DESIGN))
    assert ev.ok
    q = {r.claim.quantity: r.got for r in ev.claims}
    assert q["delay_margin.agreement"] == "agree" and q["delay_margin.current_h"] == math.inf
    rz = ev.result.realism
    assert rz.margin.eig.h == pytest.approx(0.1446, abs=5e-5)
    assert all(e.stopped for e in rz.emergency.values())
    assert {law for _, law in rz.emergency} == {"ntsm", "pd", "pd_ff"}
