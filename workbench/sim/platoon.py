"""Fixed-step simulation of a leader-follower platoon (paper 001), with the
parts a real one has: a train-to-train (V2V) link with delay and packet loss,
a first-order traction/brake actuator with force limits, and a leader
emergency brake.

Every train is a point mass with Davis resistance and gradient
(:mod:`workbench.plants.platoon001`); all trains are stepped at once (arrays
over the trains) with one step T for control and integration.

The V2V link
    The predecessor sends its position, speed and last measured acceleration
    every ``period``; a packet arrives ``delay`` (whole steps, rounded up)
    later or is lost. The follower holds the newest packet it has received
    (by send time: a late packet older than the one held is ignored) until a
    newer one arrives. :func:`packet_delays` draws the per-packet delays,
    :func:`received_steps` turns them into the step whose predecessor state
    each follower holds at every step. Before the first packet arrives the
    follower holds the initial state (the platoon starts coupled at rest).
    The follower's own position and speed are its own measurements: current
    (``own_state = "current"``) or taken at the packet's time stamp
    (``"stamped"``: the gap and relative speed are then as old as the packet,
    which puts the delay inside the follower's loop).

The actuator
    The command u (N) is clipped to [f_min, f_max] and reaches the wheels
    through a first-order lag of time constant ``lag``, integrated exactly
    over the step with the command held (the train sees the mean force of
    the step). ``lag = 0`` and infinite limits give back the ideal actuator.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Literal

import numpy as np

from .tracking import Route

#: Per-packet delay distributions of :func:`packet_delays`.
JITTER = ("none", "uniform", "exponential")
#: Where the follower's own position and speed come from (see the module docstring).
OWN_STATE = ("current", "stamped")


@dataclass(frozen=True)
class PlatoonRun:
    """Histories of a leader-follower platoon, sampled every step T.

    Attributes
    ----------
    t : numpy.ndarray
        Times (s), shape (K,).
    x, v, u : numpy.ndarray
        Positions (m), speeds (m/s), commanded forces (N); shape (K, n).
    e, de, s : numpy.ndarray
        True spacing errors (m), their rates (m/s) and the sliding variable
        used by the law (m; zeros for laws without one); shape (K, n - 1).
    lumped : numpy.ndarray
        w + d of eq 5 as the controller sees it, m_nom v' - (u - f_nom - f_v,nom)
        (N), shape (K, n).
    force : numpy.ndarray
        Mean force the actuator applied over each step (N), shape (K, n).
    e_seen : numpy.ndarray
        Spacing errors as the followers' laws saw them (m), shape (K, n - 1).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    u: np.ndarray
    e: np.ndarray
    de: np.ndarray
    s: np.ndarray
    lumped: np.ndarray
    force: np.ndarray
    e_seen: np.ndarray

    @property
    def gap(self) -> np.ndarray:
        """x_{i-1} - x_i (m): the gap of each follower to its predecessor, (K, n - 1)."""
        return self.x[:, :-1] - self.x[:, 1:]


FollowerLaw = Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray],
                       tuple[np.ndarray, np.ndarray]]
"""``law(e, de, u1, a_pred) -> (u, s)`` for the followers (arrays of shape (n-1,))."""


@dataclass(frozen=True)
class Actuator:
    """First-order traction/brake actuator with force limits (every train).

    Attributes
    ----------
    lag : float
        Time constant (s); 0 for none.
    f_min, f_max : float
        Largest braking force (N, negative) and traction force (N).
    """

    lag: float
    f_min: float
    f_max: float


@dataclass(frozen=True)
class Link:
    """What the followers know of their predecessors.

    Attributes
    ----------
    source : numpy.ndarray
        Integer array (K, n - 1): the step whose predecessor state follower
        i holds at step k (:func:`received_steps`).
    own_state : {"current", "stamped"}
        The follower's own position and speed: now, or at that step.
    """

    source: np.ndarray
    own_state: Literal["current", "stamped"] = "current"


def packet_delays(n_packets: int, n_links: int, *, delay: float, jitter: float,
                  distribution: Literal["none", "uniform", "exponential"],
                  rng: np.random.Generator | None) -> np.ndarray:
    """Delay (s) of every packet on every link, shape (n_packets, n_links).

    ``delay`` plus a random part drawn per packet: none; uniform on
    [0, jitter]; or exponential with mean ``jitter`` (the shifted
    exponential usual for network latency).
    """
    if distribution not in JITTER:
        raise ValueError(f"distribution = {distribution!r}; expected one of {JITTER}")
    base = np.full((n_packets, n_links), float(delay))
    if distribution == "none" or jitter == 0.0:
        return base
    if distribution == "uniform":
        return base + rng.uniform(0.0, jitter, base.shape)
    return base + rng.exponential(jitter, base.shape)


def received_steps(K: int, *, T: float, period: float, delays: np.ndarray,
                   lost: np.ndarray) -> np.ndarray:
    """The step whose predecessor state each follower holds, shape (K, n_links).

    Packet p is sent at step p P (P = period / T, an integer) and arrives
    ceil(delay_p / T) steps later unless ``lost[p]``; at step k a follower
    holds the newest packet (latest send step) that has arrived by k, and
    step 0 before any has.

    Parameters
    ----------
    delays : numpy.ndarray
        Per-packet delays (s), shape (n_packets, n_links), n_packets = ceil(K / P);
        a negative delay counts as 0.
    lost : numpy.ndarray
        Boolean, same shape: packets that never arrive.
    """
    P = int(round(period / T))
    if P < 1 or not math.isclose(P * T, period, rel_tol=1e-9):
        raise ValueError(f"period = {period} s; expected a positive multiple of T = {T} s")
    n_packets = -(-K // P)
    if delays.shape != lost.shape or delays.ndim != 2 or delays.shape[0] != n_packets:
        raise ValueError(f"delays {delays.shape}, lost {lost.shape}; expected equal shapes "
                         f"({n_packets}, n_links): one row per packet sent in {K} steps")
    sent = np.arange(n_packets) * P
    arrive = sent[:, None] + np.maximum(np.ceil(np.round(delays / T, 9)), 0).astype(np.int64)
    best = np.full((K, delays.shape[1]), -1, dtype=np.int64)
    for i in range(delays.shape[1]):
        ok = ~lost[:, i] & (arrive[:, i] < K)
        np.maximum.at(best[:, i], arrive[ok, i], sent[ok])
    return np.maximum(np.maximum.accumulate(best, axis=0), 0)


def simulate_platoon(nominal, true, law: FollowerLaw, leader_ref: Callable, *, n: int,
                     spacing: float, T: float, horizon: float, w: np.ndarray,
                     leader_gain: float, route: Route,
                     initial_errors: np.ndarray | None = None, link: Link | None = None,
                     actuator: Actuator | None = None,
                     leader_brake: tuple[float, float] | None = None,
                     headway: float = 0.0) -> PlatoonRun:
    """Step a platoon of ``n`` trains with sampling = integration step ``T``.

    The leader tracks ``leader_ref(t) -> (v_ref, a_ref)`` (vectorised over the
    array of step times) with
    u_0 = m (a_ref + leader_gain (v_ref - v_0)) + u1 (nominal resistance and
    gradient); followers use ``law``, fed at step k with their spacing errors,
    their own u1 and the predecessor's acceleration of step k-1 (as it would be
    communicated) — or, with a ``link``, with what they received. Speeds are
    kept >= 0 (trains do not roll back) and positions advance by the
    trapezoid rule.

    Parameters
    ----------
    nominal, true : workbench.plants.platoon001.TrainParams
        What the controllers assume; the true (per-train) values.
    w : numpy.ndarray
        External force (N), shape (>= K, n).
    initial_errors : array, optional
        e_i(0) of the followers (m); trains start at rest.
    link : Link, optional
        The V2V link; None: every follower knows its predecessor's state now.
    actuator : Actuator, optional
        None: the command is the force.
    leader_brake : (time, force), optional
        From ``time`` (s) on the leader commands ``force`` (N): an emergency brake.
    headway : float
        Spacing policy: the desired gap is ``spacing + headway * v_i`` (s; 0:
        constant spacing), so e_i = gap - spacing - headway v_i, with v_i the
        follower's own speed as its law sees it; ``de`` stays the relative
        speed v_{i-1} - v_i.
    """
    K = int(round(horizon / T))
    e0 = np.zeros(n - 1) if initial_errors is None else np.asarray(initial_errors, float)
    x = -np.arange(n) * spacing - np.concatenate([[0.0], np.cumsum(e0)])
    v = np.zeros(n)
    a_prev = np.zeros(n)
    H = {k: np.zeros((K, n)) for k in ("x", "v", "a", "u", "lumped", "force")}
    He = {k: np.zeros((K, n - 1)) for k in ("e", "de", "s", "e_seen")}
    edges = np.asarray(route.grade_from[1:])
    grade = np.asarray(route.grade)
    # gradient forces per section (rows) and train (columns), nominal and true
    fv_nom = nominal.grade_force(grade)[:, None] * np.ones(n)
    fv_true = true.grade_force(grade[:, None]) * np.ones(n)
    cols = np.arange(n)
    pred, foll = cols[:-1], cols[1:]
    t_all = np.arange(K) * T
    v_ref, a_ref = leader_ref(t_all)
    u_lead = nominal.m * a_ref
    k_brake = K if leader_brake is None else int(round(leader_brake[0] / T))
    if actuator is not None:
        decay = math.exp(-T / actuator.lag) if actuator.lag > 0 else 0.0
        mean = actuator.lag / T * (1.0 - decay)      # mean of the lag's step response gap
        f = np.zeros(n)
    u = np.zeros(n)
    # per-step overhead cut, same arithmetic: the leader's scalars as Python floats, the
    # history rows and the (section, train) and (step, train) lookups by flat index
    u_lead_k, v_ref_k = u_lead.tolist(), v_ref.tolist()
    m_gain = nominal.m * leader_gain
    Hx, Hv, Ha, Hu, Hl, Hf = (H[k] for k in ("x", "v", "a", "u", "lumped", "force"))
    Ee, Ede, Es, Eseen = (He[k] for k in ("e", "de", "s", "e_seen"))
    fxf, fvf, faf = Hx.reshape(-1), Hv.reshape(-1), Ha.reshape(-1)
    fv_nom_f, fv_true_f = fv_nom.reshape(-1), fv_true.reshape(-1)
    # nominal and true resistance in one evaluation: row 0 nominal, row 1 true (elementwise)
    both = type(nominal)(*(np.stack([np.broadcast_to(np.asarray(getattr(p, c), float), (n,))
                                     for p in (nominal, true)]) for c in ("m", "c0", "c1", "c2")),
                         nominal.g)
    v2 = np.empty((2, n))
    stamped = link is not None and link.own_state != "current"
    for k in range(K):
        Hx[k], Hv[k], Ha[k] = x, v, a_prev
        ix = edges.searchsorted(x, side="right") * n + cols
        v2[:] = v
        res = both.resistance(v2)
        u1 = res[0] + fv_nom_f[ix]
        e = x[:-1] - x[1:] - spacing
        if headway:
            e = e - headway * v[1:]
        de = v[:-1] - v[1:]
        if link is None:
            e_seen, de_seen, a_seen = e, de, a_prev[:-1]
        else:
            row = link.source[k] * n
            ip = row + pred
            xo, vo = (fxf[row + foll], fvf[row + foll]) if stamped else (x[1:], v[1:])
            e_seen = fxf[ip] - xo - spacing
            if headway:
                e_seen = e_seen - headway * vo
            de_seen = fvf[ip] - vo
            a_seen = faf[ip]
        u_f, s = law(e_seen, de_seen, u1[1:], a_seen)
        u[0] = (u_lead_k[k] + m_gain * (v_ref_k[k] - float(v[0])) + float(u1[0]) if k < k_brake
                else leader_brake[1])
        u[1:] = u_f
        if actuator is None:
            force = u
        else:
            cmd = np.minimum(np.maximum(u, actuator.f_min), actuator.f_max)   # np.clip
            force = cmd + (f - cmd) * mean
            f = cmd + (f - cmd) * decay
        acc = (force - res[1] - fv_true_f[ix] + w[k]) / true.m
        v_new = np.maximum(v + T * acc, 0.0)
        a_real = (v_new - v) / T
        Hu[k], Hf[k] = u, force
        Hl[k] = nominal.m * a_real - (u - u1)
        Ee[k], Ede[k], Es[k], Eseen[k] = e, de, s, e_seen
        x = x + 0.5 * T * (v + v_new)
        v, a_prev = v_new, a_real
    return PlatoonRun(t_all, H["x"], H["v"], H["u"], He["e"], He["de"], He["s"],
                      H["lumped"], H["force"], He["e_seen"])
