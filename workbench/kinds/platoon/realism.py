"""The realistic platoon: V2V link, actuator lag and limits, the leader's
emergency brake against the braking-distance envelope, and the exact delay
margin of a linear law (first written for paper 001's NTSM platoon).

Runs, on the scenario of :mod:`.run` (same seeded trains and external
force):

* **emergency** — for each link case and each law of ``[emergency] laws``,
  the leader's normal run until ``[emergency] time``, then its full brake
  (the actuator's brake limit) to standstill. Link cases: ``constant`` (the
  ``[v2v]`` delay, no loss) and ``random`` (the delay plus the per-packet
  jitter, and Bernoulli loss), one seeded realisation shared by every law.
  Each follower's gap is compared with the safe braking-distance envelope
  (relative braking distance)::

      d_safe = s0 + v_f tau_r + max(0, v_f^2 / (2 b) - v_p^2 / (2 b))

  (s0 the standstill margin, tau_r the reaction time, b the brake limit of
  ``[actuator]``, v_f and v_p the follower's and predecessor's speeds).
* **delay margin** (``[delay_margin]``) — the exact margin of a law linear in
  e and e' (``law``: (u - u1)/m = k_e e + k_d e' + c a_pred; a nonlinear law,
  such as paper 001's eq 13, has no linearisation, so the design names a
  linear surrogate), with the actuator lag and the delay inside the loop (the
  follower's own state stamped with the packet's time: ``own_state =
  "stamped"``), by Chen-Gu-Nett and by python-control's crossovers; with the
  own state current the delay is not in any loop and the margin is infinite.
  A sweep simulates the laws of ``sweep`` with constant delays of ``factors``
  times h* (and the design's V2V delay) in the stamped arrangement.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...features.reproducible import window as window_mask
from ...margins import Agreement, DelayMargin, compare_margins, delay_margin_eig, delay_margin_siso
from ...sim.platoon import Actuator, Link, PlatoonRun, packet_delays, received_steps

__all__ = ["CASES", "DelayMarginStudy", "EmergencyRun", "LinkStats", "Realism", "SweepRow",
           "accel_end", "actuator", "delay_margin_model", "emergency_run", "envelope",
           "linear_gains", "link", "run_realism"]

CASES = ("constant", "random")


@dataclass(frozen=True)
class EmergencyRun:
    """One law under the leader's emergency brake (followers: trains 2..n).

    Attributes
    ----------
    run : PlatoonRun
    envelope : numpy.ndarray
        d_safe of every follower (m), shape (K, n - 1).
    min_gap, t_min_gap : float
        Smallest gap after the emergency brake (m) and when (s).
    min_margin, t_min_margin : float
        Smallest gap - d_safe after the emergency brake (m) and when (s).
    train_min_margin : int
        The follower (train number) where it occurs.
    cruise_abs_e : float
        Largest |e| (m) in the settled cruise before the emergency brake.
    stopped : bool
        Every train at rest at the end of the run.
    """

    run: PlatoonRun
    envelope: np.ndarray
    min_gap: float
    t_min_gap: float
    min_margin: float
    t_min_margin: float
    train_min_margin: int
    cruise_abs_e: float
    stopped: bool


@dataclass(frozen=True)
class LinkStats:
    """Age of the predecessor data the followers hold (s), and the packets lost."""

    mean_age: float
    max_age: float
    lost: float


@dataclass(frozen=True)
class SweepRow:
    """One constant delay of the sweep (own state stamped, packet every step).

    Attributes
    ----------
    law : str
    factor : float or None
        Asked delay / h* (None: the design's V2V delay).
    h : float
        Simulated delay (s): the asked one rounded to whole steps.
    amp_first, amp_worst : float
        Largest |e| (m) in the window: first follower; any follower.
    saturated : float
        Fraction of the window's steps at which the first follower's command
        is outside the actuator's limits.
    """

    law: str
    factor: float | None
    h: float
    amp_first: float
    amp_worst: float
    saturated: float
    trace: np.ndarray = field(compare=False, repr=False)   # (t (s), e (m)) of the first follower


@dataclass(frozen=True)
class DelayMarginStudy:
    """Exact delay margin of a linear law (see the module docstring).

    Attributes
    ----------
    law : str
        The linear law of ``[delay_margin]``.
    k_e, k_d : float
        Linear member's gains (1/s^2, 1/s).
    A, B, K : numpy.ndarray
        x' = A x + B K x(t - h), x = (e, e', a_f) (a_f the lagged
        acceleration; (e, e') without lag).
    eig, siso : DelayMargin
        Chen-Gu-Nett on (A, B K); python-control's crossovers on (A, B, K).
    current : DelayMargin
        Own state current: the delayed term is zero (Chen-Gu-Nett).
    sweep : tuple[SweepRow, ...]
    window : tuple[float, float]
        Where the sweep's amplitudes are measured (s).
    """

    law: str
    k_e: float
    k_d: float
    A: np.ndarray
    B: np.ndarray
    K: np.ndarray
    eig: DelayMargin
    siso: DelayMargin
    current: DelayMargin
    sweep: tuple[SweepRow, ...]
    window: tuple[float, float]
    factors: tuple[float, ...] = ()

    @property
    def agreement(self) -> tuple[Agreement, float | None]:
        """The two exact methods' agreement and relative difference."""
        return compare_margins(self.eig, self.siso)


@dataclass(frozen=True)
class Realism:
    delay: float           # the design's V2V delay (s)
    t_emergency: float
    horizon: float
    links: dict            # case -> LinkStats
    emergency: dict        # (case, law) -> EmergencyRun
    margin: DelayMarginStudy | None
    laws: tuple[str, ...] = ()   # the laws of the emergency runs


def actuator(spec) -> Actuator:
    """The ``[actuator]`` of every train: limits are accelerations of the nominal mass."""
    a, m = spec.actuator, spec.nominal().m
    return Actuator(a.lag.value, -a.brake.value * m, a.traction.value * m)


def link(spec, case: str, K: int, *, delay: float | None = None) -> tuple[Link, float]:
    """The V2V link of a case, and the fraction of packets lost: ``constant``,
    ``random`` or ``sweep`` (a constant ``delay`` with a packet every step, own
    state stamped)."""
    L, T, n_links = spec.link, spec.T, spec.n - 1
    period = T if case == "sweep" else L.period.value
    P = int(round(period / T))
    n_packets = -(-K // P)
    if case == "random":
        # two streams, so that a longer run extends the same realisation
        s_delay, s_loss = np.random.SeedSequence(L.seed).spawn(2)
        delays = packet_delays(n_packets, n_links, delay=L.delay.value,
                               jitter=L.jitter_scale.value, distribution=L.jitter,
                               rng=np.random.default_rng(s_delay))
        lost = np.random.default_rng(s_loss).random(delays.shape) < L.loss
    else:
        h = L.delay.value if delay is None else delay
        delays = packet_delays(n_packets, n_links, delay=h, jitter=0.0, distribution="none",
                               rng=None)
        lost = np.zeros(delays.shape, bool)
    own = "stamped" if case == "sweep" else L.own_state
    return (Link(received_steps(K, T=T, period=period, delays=delays, lost=lost), own),
            float(lost.mean()))


def envelope(v_f, v_p, *, reaction: float, brake: float, margin: float):
    """Safe braking-distance envelope d_safe (m) of the module docstring."""
    return margin + v_f * reaction + np.maximum(0.0, (v_f ** 2 - v_p ** 2) / (2.0 * brake))


def accel_end(profile) -> float:
    """Time (s) the leader's profile stops accelerating."""
    return float(profile.t[np.nonzero(profile.a > 0)[0][-1]])


def emergency_horizon(spec) -> float:
    """End (s) of an emergency run: the brake time plus twice the time to stop
    from cruise at the brake limit plus 20 s, within the design's horizon."""
    return min(spec.horizon, spec.emergency.time.value
               + 2.0 * spec.v_cruise.value / spec.actuator.brake.value + 20.0)


def emergency_run(sc, law: str, lk: Link) -> EmergencyRun:
    """The law ``law`` with the link ``lk`` under the leader's emergency brake,
    judged against the envelope (module docstring)."""
    spec = sc.spec
    act, em = actuator(spec), spec.emergency
    t_e = em.time.value
    run = sc.simulate(law, horizon=emergency_horizon(spec), link=lk, actuator=act,
                      leader_brake=(t_e, act.f_min))
    env = envelope(run.v[:, 1:], run.v[:, :-1], reaction=em.reaction.value,
                   brake=spec.actuator.brake.value, margin=em.margin.value)
    after = run.t >= t_e - 1e-9
    gap = run.gap[after]
    margin = gap - env[after]
    kg = np.unravel_index(np.argmin(gap), gap.shape)
    km = np.unravel_index(np.argmin(margin), margin.shape)
    t_after = run.t[after]
    # window ends on sample times (t_e is one, excluded): half a step to spare
    cw = window_mask(run.t, accel_end(sc.profile) + 10.0, t_e - sc.spec.T)
    return EmergencyRun(run, env, float(gap[kg]), float(t_after[kg[0]]), float(margin[km]),
                        float(t_after[km[0]]), int(km[1]) + 2,
                        float(np.abs(run.e[cw]).max()) if cw.any() else math.nan,
                        bool(np.all(run.v[-1] == 0.0)))


def _stats(lk: Link, T: float, lost_fraction: float) -> LinkStats:
    age = (np.arange(lk.source.shape[0])[:, None] - lk.source) * T
    return LinkStats(float(age.mean()), float(age.max()), lost_fraction)


def delay_margin_model(lag: float, k_e: float, k_d: float):
    """(A, B, K) of the linear member with the delay in the loop (module docstring)."""
    if lag > 0:
        A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, -1.0], [0.0, 0.0, -1.0 / lag]])
        return A, np.array([[0.0], [0.0], [1.0 / lag]]), np.array([[k_e, k_d, 0.0]])
    return (np.array([[0.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [-1.0]]),
            np.array([[k_e, k_d]]))


def _sweep_row(sc, law: str, factor, h: float, act: Actuator, window, K: int) -> SweepRow:
    run = sc.simulate(law, horizon=K * sc.spec.T, link=link(sc.spec, "sweep", K, delay=h)[0],
                      actuator=act)
    w = window_mask(run.t, *window)         # ends on sample times: half a step to spare
    e = np.abs(run.e[w])
    u = run.u[w, 1]
    sat = ((u < act.f_min) | (u > act.f_max)).mean()
    return SweepRow(law, factor, h, float(e[:, 0].max()), float(e.max()), float(sat),
                    np.stack([run.t[w], run.e[w, 0]], axis=1))


def linear_gains(spec) -> tuple[float, float]:
    """(k_e (1/s^2), k_d (1/s)) of the ``[delay_margin]`` law, read off the law
    with m = 1 (exact for a linear law); a law that is not linear in e, e' and
    a_pred, or whose feed-forward of a_pred is not 1, is a design error."""
    from ...errors import DesignError
    from .laws import compile_law
    i = next(k for k, x in enumerate(spec.laws) if x.name == spec.margin.law)
    law = compile_law(spec.laws[i], spec.constants, {"m": 1.0, "G_w": spec.G_w, "G_d": spec.G_d},
                      path=spec.path, index=i)
    one, zero = np.ones(1), np.zeros(1)
    f = lambda e, de, a: float(law(e * one, de * one, zero, a * one)[0][0])
    k_e, k_d, c = f(1.0, 0.0, 0.0), f(0.0, 1.0, 0.0), f(0.0, 0.0, 1.0)
    rng = np.random.default_rng(0)
    pts = rng.uniform(-3.0, 3.0, (8, 3))
    lin = all(math.isclose(f(*p), k_e * p[0] + k_d * p[1] + p[2], rel_tol=1e-9, abs_tol=1e-9)
              for p in pts)
    if not (lin and c == 1.0 and f(0.0, 0.0, 0.0) == 0.0 and k_e > 0 and k_d > 0):
        raise DesignError(spec.path, "delay_margin.law", spec.margin.law,
                          "a law u1 + m*(k_e*e + k_d*de) + m*a_pred with k_e, k_d > 0 (linear: "
                          "its exact margin is computed on it)")
    return k_e, k_d


def delay_margin_study(sc, act: Actuator, t_acc_end: float) -> DelayMarginStudy:
    spec = sc.spec
    k_e, k_d = linear_gains(spec)
    lag = spec.actuator.lag.value
    A, B, K = delay_margin_model(lag, k_e, k_d)
    eig, siso = delay_margin_eig(A, B @ K), delay_margin_siso(A, B, K)
    # own state current: the homogeneous loop has no delayed term (A_d = 0)
    current = delay_margin_eig(A + B @ K, np.zeros_like(A))
    window = (t_acc_end + 10.0, t_acc_end + 30.0)
    n_steps = int(round(window[1] / spec.T)) + 1
    steps = lambda h: round(h / spec.T) * spec.T        # whole steps, nearest
    hs = ([(f, steps(f * eig.h)) for f in spec.margin.factors]
          if math.isfinite(eig.h) and eig.h > 0 else [])
    hs.append((None, math.ceil(round(spec.link.delay.value / spec.T, 9)) * spec.T))
    rows = tuple(_sweep_row(sc, law, f, h, act, window, n_steps)
                 for law in spec.margin.sweep for f, h in hs)
    return DelayMarginStudy(spec.margin.law, k_e, k_d, A, B, K, eig, siso, current, rows, window,
                            spec.margin.factors)


def run_realism(sc) -> Realism:
    """Every run of the realistic scenario (module docstring)."""
    spec = sc.spec
    K = int(round(emergency_horizon(spec) / spec.T))
    links, runs = {}, {}
    for case in CASES:
        lk, lost = link(spec, case, K)
        links[case] = _stats(lk, spec.T, lost)
        for law in spec.emergency.laws:
            runs[case, law] = emergency_run(sc, law, lk)
    margin = (None if spec.margin is None else
              delay_margin_study(sc, actuator(spec), accel_end(sc.profile)))
    return Realism(spec.link.delay.value, spec.emergency.time.value, K * spec.T, links, runs,
                   margin, spec.emergency.laws)
