"""The realistic platoon of paper 001: V2V link, actuator lag and limits, the
leader's emergency brake against the braking-distance envelope, and the exact
delay margin of the NTSM's linear member.

Runs, on the scenario of :mod:`.ntsm_platoon` (same seeded trains and external
force):

* **emergency** — for each link case and each law of :data:`CONTROLLERS`,
  the leader's normal run until ``[emergency] time``, then its full brake
  (the actuator's brake limit) to standstill. Link cases: ``constant`` (the
  ``[v2v]`` delay, no loss) and ``random`` (the delay plus the per-packet
  jitter, and Bernoulli loss), one seeded realisation shared by every law.
  Each follower's gap is compared with the safe braking-distance envelope
  (relative braking distance)::

      d_safe = s0 + v_f tau_r + max(0, v_f^2 / (2 b) - v_p^2 / (2 b))

  (s0 the standstill margin, tau_r the reaction time, b the brake limit of
  ``[actuator]``, v_f and v_p the follower's and predecessor's speeds).
* **delay margin** — eq 13 has no linearisation at e = e' = 0 (powers
  2 - b/a and alpha/xi below 1: infinite slope; sign(s): a jump); its
  Lipschitz part linearises to e'' = -(beta a j / b) e, a spring without
  damping. The exact margin is therefore computed on the law's linear member
  (:func:`~workbench.controllers.ntsm.linear_member`) with the actuator lag,
  with the delay inside the loop (the follower's own state stamped with the
  packet's time: ``own_state = "stamped"``), by Chen-Gu-Nett and by
  python-control's crossovers; with the own state current the delay is not
  in any loop and the margin is infinite. A sweep simulates NTSM and linear
  member with constant delays around h* in the stamped arrangement.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...controllers.ntsm import linear_member
from ...features.reproducible import window as window_mask
from ...margins import Agreement, DelayMargin, compare_margins, delay_margin_eig, delay_margin_siso
from ...sim.platoon import Actuator, Link, PlatoonRun, packet_delays, received_steps

CASES = ("constant", "random")
CONTROLLERS = ("ntsm", "pd", "pd_ff")
#: Delays of the sweep, as multiples of h*.
SWEEP_FACTORS = (0.5, 0.9, 1.1)
SWEEP_LAWS = ("ntsm", "linear")


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
    """Exact delay margin of the NTSM's linear member (see the module docstring).

    Attributes
    ----------
    lowest_power : float
        min(2 - b/a, alpha/xi): below 1, eq 13 has an infinite slope at 0.
    switching : float
        G_w + G_d (N): the gain of sign(s), a jump at s = 0 unless 0.
    spring : float
        beta a j / b (1/s^2): the Lipschitz part's only linear term.
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

    lowest_power: float
    switching: float
    spring: float
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

    @property
    def linearisable(self) -> bool:
        """Eq 13 is differentiable at e = e' = 0."""
        return self.lowest_power >= 1.0 and self.switching == 0.0

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
    margin: DelayMarginStudy


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


def delay_margin_study(sc, act: Actuator, t_acc_end: float) -> DelayMarginStudy:
    spec = sc.spec
    g = spec.gains
    k_e, k_d = linear_member(g)
    lag = spec.actuator.lag.value
    A, B, K = delay_margin_model(lag, k_e, k_d)
    eig, siso = delay_margin_eig(A, B @ K), delay_margin_siso(A, B, K)
    # own state current: the homogeneous loop has no delayed term (A_d = 0)
    current = delay_margin_eig(A + B @ K, np.zeros_like(A))
    window = (t_acc_end + 10.0, t_acc_end + 30.0)
    n_steps = int(round(window[1] / spec.T)) + 1
    steps = lambda h: round(h / spec.T) * spec.T        # whole steps, nearest
    hs = ([(f, steps(f * eig.h)) for f in SWEEP_FACTORS]
          if math.isfinite(eig.h) and eig.h > 0 else [])
    hs.append((None, math.ceil(round(spec.link.delay.value / spec.T, 9)) * spec.T))
    rows = tuple(_sweep_row(sc, law, f, h, act, window, n_steps)
                 for law in SWEEP_LAWS for f, h in hs)
    return DelayMarginStudy(min(2.0 - g.b / g.a, g.alpha / g.xi), spec.G_w + spec.G_d,
                            g.beta * g.a * g.j / g.b,
                            k_e, k_d, A, B, K, eig, siso, current, rows, window)


def run_realism(sc) -> Realism:
    """Every run of the realistic scenario (module docstring)."""
    spec = sc.spec
    K = int(round(emergency_horizon(spec) / spec.T))
    links, runs = {}, {}
    for case in CASES:
        lk, lost = link(spec, case, K)
        links[case] = _stats(lk, spec.T, lost)
        for law in CONTROLLERS:
            runs[case, law] = emergency_run(sc, law, lk)
    return Realism(spec.link.delay.value, spec.emergency.time.value, K * spec.T, links, runs,
                   delay_margin_study(sc, actuator(spec), accel_end(sc.profile)))


def realism_quantity_names() -> set[str]:
    names = set()
    for case in CASES:
        names |= {f"emergency.{case}.link.{k}" for k in ("mean_age", "max_age", "lost")}
        names |= {f"emergency.{case}.{law}.{k}" for law in CONTROLLERS for k in
                  ("min_gap", "t_min_gap", "min_margin", "t_min_margin", "cruise_abs_e",
                   "stopped")}
        names |= {f"emergency.{case}.{d}.{k}" for d in ("ntsm_minus_pd_ff", "pd_ff_minus_pd")
                  for k in ("min_gap", "min_margin")}
    names |= {f"emergency.{who}.{k}" for who in CONTROLLERS + ("worst",)
              for k in ("min_gap", "min_margin")}
    names |= {f"delay_margin.{k}" for k in ("linearisable", "lowest_power", "spring", "k_e",
                                             "k_d", "h_eig",
                                             "h_siso", "omega", "agreement", "h_over_delay",
                                             "current_h")}
    names |= {f"delay_sweep.{law}.{k}" for law in SWEEP_LAWS
              for k in ("amp_ratio", "amp_at_delay", "saturated_at_delay")}
    return names


def _amp(rows, law: str, factor) -> SweepRow | None:
    return next((r for r in rows if r.law == law and r.factor == factor), None)


def realism_quantities(r: Realism) -> dict:
    q = {}
    for case, st in r.links.items():
        q.update({f"emergency.{case}.link.{k}": getattr(st, k)
                  for k in ("mean_age", "max_age", "lost")})
    for (case, law), e in r.emergency.items():
        for k in ("min_gap", "t_min_gap", "min_margin", "t_min_margin", "cruise_abs_e"):
            q[f"emergency.{case}.{law}.{k}"] = getattr(e, k)
        q[f"emergency.{case}.{law}.stopped"] = "yes" if e.stopped else "no"
    for case in CASES:
        for k in ("min_gap", "min_margin"):
            x = {law: getattr(r.emergency[case, law], k) for law in CONTROLLERS}
            q[f"emergency.{case}.ntsm_minus_pd_ff.{k}"] = x["ntsm"] - x["pd_ff"]
            q[f"emergency.{case}.pd_ff_minus_pd.{k}"] = x["pd_ff"] - x["pd"]
    for who in CONTROLLERS + ("worst",):
        runs = [e for (case, law), e in r.emergency.items() if who in (law, "worst")]
        q[f"emergency.{who}.min_gap"] = min(e.min_gap for e in runs)
        q[f"emergency.{who}.min_margin"] = min(e.min_margin for e in runs)
    m = r.margin
    q.update({"delay_margin.linearisable": "yes" if m.linearisable else "no",
              "delay_margin.lowest_power": m.lowest_power, "delay_margin.spring": m.spring,
              "delay_margin.k_e": m.k_e, "delay_margin.k_d": m.k_d,
              "delay_margin.h_eig": m.eig.h, "delay_margin.h_siso": m.siso.h,
              "delay_margin.omega": m.eig.omega,
              "delay_margin.agreement": m.agreement[0].value,
              "delay_margin.current_h": m.current.h})
    delay = r.delay
    q["delay_margin.h_over_delay"] = m.eig.h / delay if delay > 0 else math.inf
    for law in SWEEP_LAWS:
        lo, hi, d = _amp(m.sweep, law, 0.9), _amp(m.sweep, law, 1.1), _amp(m.sweep, law, None)
        q[f"delay_sweep.{law}.amp_ratio"] = (hi.amp_first / lo.amp_first
                                             if lo is not None and hi is not None else None)
        q[f"delay_sweep.{law}.amp_at_delay"] = d.amp_first
        q[f"delay_sweep.{law}.saturated_at_delay"] = d.saturated
    return q
