"""The ``ntsm-platoon`` design, read and validated: paper 001's platoon and the
realistic scenario around it.

Tables: ``[plant]`` (nominal train, Table 1), ``[uncertainty]`` (seeded
parameter spread and external force, bounds G_w, G_d of eq 6), ``[leader]``
(accelerate - cruise - brake), ``[platoon]`` (n, D, T, horizon), ``[route]``
(gradients), ``[ntsm]`` (eqs 10-13), ``[pd]`` and ``[pd_ff]`` (baselines),
``[convergence]`` (eq 22 check), and the realistic scenario: ``[v2v]`` (the
train-to-train link), ``[actuator]`` (first-order lag, traction and brake
limits) and ``[emergency]`` (the leader's emergency brake and the safe
braking-distance envelope it is judged against).
"""
from __future__ import annotations

from dataclasses import dataclass

from ...controllers.ntsm import NTSMGains
from ...plants.platoon001 import PARAMETER_UNITS, TrainParams
from ...profiles import phase_time, spec_for_cruise
from ...reader import Quantity, Reader, read_gradients
from ...sim.platoon import JITTER, OWN_STATE
from ...sim.tracking import Route


@dataclass(frozen=True)
class LinkSpec:
    """``[v2v]``: packets every ``period`` (s), delay ``delay`` (s) plus, in the
    random case, a per-packet ``jitter`` (distribution, scale in s) and
    Bernoulli loss ``loss``; ``own_state`` as in :mod:`workbench.sim.platoon`."""

    period: Quantity
    delay: Quantity
    jitter: str
    jitter_scale: Quantity
    loss: float
    own_state: str
    seed: int


@dataclass(frozen=True)
class ActuatorSpec:
    """``[actuator]``: lag (s); traction and brake limits as accelerations of
    the nominal mass (m/s^2, both positive)."""

    lag: Quantity
    traction: Quantity
    brake: Quantity


@dataclass(frozen=True)
class EmergencySpec:
    """``[emergency]``: the leader's full brake from ``time`` (s); the
    envelope's reaction time (s) and standstill margin (m)."""

    time: Quantity
    reaction: Quantity
    margin: Quantity


@dataclass(frozen=True)
class PlatoonSpec:
    plant: dict                 # Quantity per PARAMETER_UNITS key
    mass_spread: float
    davis_spread: float
    G_w: float
    G_d: float
    hold: float
    seed: int
    v_cruise: Quantity
    cruise_time: float
    accel: float
    brake: float
    jerk: float
    leader_gain: float
    n: int
    D: Quantity
    T: float
    horizon: float
    route: Route
    gains: NTSMGains
    kp: float
    kd: float
    initial_errors: tuple[float, ...]
    reach_band: float
    converge_band: float
    kp_ff: float
    kd_ff: float
    link: LinkSpec
    actuator: ActuatorSpec
    emergency: EmergencySpec

    def nominal(self) -> TrainParams:
        p = {k: q.value for k, q in self.plant.items()}
        return TrainParams(p["m"], p["c0"], p["c1"], p["c2"], p["g"])


def _odd(r: Reader, name: str) -> int:
    return int(r.number(name, integer=True, positive=True, what="positive odd integer"))


def _multiple(r: Reader, name: str, q: Quantity, T: float) -> None:
    k = round(q.value / T)
    if k < 1 or abs(k * T - q.value) > 1e-9 * q.value:
        raise r.fail(name, q.value, f"a positive multiple of the step T = {T} s (s)")


def _read_link(root: Reader, T: float) -> LinkSpec:
    r = root.table("v2v")
    period = r.quantity("period", "s", positive=True, hi=5.0)
    _multiple(r, "period", period, T)
    delay = r.quantity("delay", "s", nonneg=True, hi=60.0)
    jitter = r.string("jitter", choices=JITTER)
    scale = r.quantity("jitter_scale", "s", nonneg=True, hi=60.0)
    loss = r.number("loss", lo=0.0, hi=0.99, what="packet-loss probability")
    own = r.string("own_state", choices=OWN_STATE)
    seed = int(r.number("seed", integer=True, nonneg=True, what="integer seed"))
    r.finish()
    return LinkSpec(period, delay, jitter, scale, loss, own, seed)


def _read_actuator(root: Reader) -> ActuatorSpec:
    r = root.table("actuator")
    lag = r.quantity("lag", "s", nonneg=True, hi=10.0)
    traction = r.quantity("traction", "m/s^2", positive=True, hi=5.0)
    brake = r.quantity("brake", "m/s^2", positive=True, hi=5.0)
    r.finish()
    return ActuatorSpec(lag, traction, brake)


def _read_emergency(root: Reader, t_brake: float, T: float) -> EmergencySpec:
    r = root.table("emergency")
    time = r.quantity("time", "s", positive=True)
    if not time.value < t_brake:
        raise r.fail("time", time.value, f"a time (s) before the leader's service braking "
                     f"starts ({t_brake:.4g} s)")
    _multiple(r, "time", time, T)
    reaction = r.quantity("reaction", "s", nonneg=True, hi=60.0)
    margin = r.quantity("margin", "m", nonneg=True)
    r.finish()
    return EmergencySpec(time, reaction, margin)


def _gains(root: Reader, name: str) -> tuple[float, float]:
    r = root.table(name)
    kp, kd = r.number("kp", positive=True), r.number("kd", positive=True)
    r.finish()
    return kp, kd


def load_spec(root: Reader) -> PlatoonSpec:
    """Read and validate every table of an ``ntsm-platoon`` design."""
    pl = root.table("plant")
    pl.string("model", choices=("davis-001",))
    plant = {k: pl.quantity(k, u, positive=True) for k, u in PARAMETER_UNITS.items()}
    pl.finish()
    un = root.table("uncertainty")
    ms = un.number("mass_spread", nonneg=True, hi=0.5)
    ds = un.number("davis_spread", nonneg=True, hi=0.5)
    G_w = un.quantity("G_w", "N", nonneg=True).value
    G_d = un.quantity("G_d", "N", nonneg=True).value
    hold = un.quantity("hold", "s", positive=True).value
    seed = int(un.number("seed", integer=True, nonneg=True, what="integer seed"))
    un.finish()
    le = root.table("leader")
    vc = le.quantity("cruise_speed", "m/s", positive=True, hi=100.0)
    ct = le.quantity("cruise_time", "s", positive=True).value
    acc = le.quantity("accel", "m/s^2", positive=True, hi=2.0).value
    brk = le.quantity("brake", "m/s^2", positive=True, hi=2.0).value
    jerk = le.quantity("jerk", "m/s^3", positive=True, hi=5.0).value
    lg = le.quantity("gain", "1/s", positive=True).value
    le.finish()
    pt = root.table("platoon")
    n = int(pt.number("trains", integer=True, lo=2, hi=20, what="number of trains"))
    D = pt.quantity("spacing", "m", positive=True)
    T = pt.quantity("T", "s", positive=True, hi=0.1).value
    horizon = pt.quantity("horizon", "s", positive=True, hi=3600.0).value
    pt.finish()
    ro = root.table("route")
    g_from, grade = read_gradients(ro)
    ro.finish()
    nt = root.table("ntsm")
    gains = NTSMGains(nt.number("beta", positive=True), _odd(nt, "a"), _odd(nt, "b"),
                      nt.number("j", positive=True), nt.number("k", positive=True),
                      _odd(nt, "alpha"), _odd(nt, "xi"))
    bad = gains.problems()
    if bad:
        raise nt.fail(*bad[0])
    nt.finish()
    kp, kd = _gains(root, "pd")
    kp_ff, kd_ff = _gains(root, "pd_ff")
    cv = root.table("convergence")
    e0 = cv.numbers("initial_errors", what="spacing errors (m)")
    if len(e0) != n - 1 or min(e0) < 0:
        raise cv.fail("initial_errors", list(e0), f"{n - 1} non-negative errors (m), one per "
                      "follower (a follower too close would have to reverse)")
    rb = cv.quantity("reach_band", "m", positive=True).value
    cb = cv.quantity("converge_band", "m", positive=True).value
    cv.finish()
    profile = spec_for_cruise(vc.value, ct, acc, brk, jerk)
    if profile.run_time > horizon:
        raise pt.fail("horizon", horizon, "a horizon longer than the leader's run")
    link = _read_link(root, T)
    act = _read_actuator(root)
    t_brake = profile.run_time - phase_time(vc.value, brk, jerk)   # service braking starts
    em = _read_emergency(root, t_brake, T)
    return PlatoonSpec(plant, ms, ds, G_w, G_d, hold, seed, vc, ct, acc, brk, jerk, lg, n, D,
                       T, horizon, Route(1e9, g_from, grade), gains, kp, kd, e0, rb, cb,
                       kp_ff, kd_ff, link, act, em)
