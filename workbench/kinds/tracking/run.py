"""Computation of the ``ato-tracking`` study (paper 002): per plant reading,
multi-objective tuning of CFDL-MFAC and PID, their Pareto fronts, the chosen
points, the PPD diagnostics and the synthetic line.

Per reading (:class:`~.ato_tracking.Reading`):

1. every combination of the MFAC grid (eta, mu, rho, lambda, phi(1)) and of
   the PID grid (kp, ki, kd) is simulated on the main pair, one batch each;
2. each run gets the four objectives (stop error, punctuality, RMS jerk,
   traction energy; :class:`~workbench.sim.tracking.Objectives`), each
   controller its Pareto front (:func:`workbench.tuning.pareto.pareto_mask`), and the design
   point is the run with the smallest weighted sum sum_j w_j x_j / s_j (scales
   and weights from ``[tuning]``) among the runs that stop within the stop
   requirement (all runs if none does); it lies on the front. Only
   reproducible runs take part: the grid is run again on the train moved
   by +-1e-9 (relative), and a run whose objectives move more than
   :data:`~workbench.features.reproducible.RTOL` is left out of fronts,
   choice and counts (a relay-like loop turns last bits into another run);
3. the chosen MFAC run is examined against the CFDL assumptions: the share of
   samples where eq 9's reset fired, by condition; the range of the estimate;
   the *realised* PPD dy(k+1) / du(k) of the run (samples with |du| > epsilon),
   whose sign the CFDL-MFAC analysis assumes fixed and whose size it assumes
   bounded (Hou & Jin 2011); and the poles of the eq 7 law with the PPD
   frozen at its median, around the sampled linearised plant with its delay;
4. "MFAC beats PID" on a reading when MFAC's chosen point has the smaller
   weighted cost, both counted from the reading's utopia point (the best
   value of each objective over both grids), so that an objective's common
   floor (the energy any run needs) does not decide a tie; equal at 3
   significant digits is a tie.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ...controllers.mfac import RESET_CONDITIONS, MFAC, MFACGains, frozen_loop_poles
from ...controllers.pid import BatchPID
from ...errors import ModelError
from ...features.reproducible import NUDGE, decide, nudged, reproducible
from ...jsonable import finite_or_none, json_method
from ...plants.train002 import dc_gain, linear_model, speed_time_constant
from ...profiles import Profile, build_profile
from ...report.markdown import fmt
from ...sim.tracking import Objectives, TrackingRun, objectives, simulate_tracking
from ...tuning.pareto import choose, dominated_share, grid_edges, pareto_mask, weighted_cost
from .spec import MFAC_KEYS, OBJECTIVES, PID_KEYS, Reading, Section, TrackingSpec

WINNER_DIGITS = 3   # significant digits at which two values count as a tie
SENSITIVITY_KEYS = ("eta", "mu", "rho", "lam")


@dataclass(frozen=True)
class Comparison:
    """MFAC and PID (chosen points) on one section: profile, histories, objectives."""

    section: Section
    profile: Profile
    mfac: TrackingRun
    pid: TrackingRun
    mfac_q: Objectives
    pid_q: Objectives

    def value(self, ctrl: str, name: str) -> float:
        return float(getattr(self.mfac_q if ctrl == "MFAC" else self.pid_q, name)[0])

    def winner(self, name: str) -> str:
        return winner(self.value("MFAC", name), self.value("PID", name))


def winner(m: float, p: float) -> str:
    """"MFAC", "PID", "tie" (equal at :data:`WINNER_DIGITS`) or "undetermined"."""
    if not (np.isfinite(m) and np.isfinite(p)):
        return "undetermined"
    if fmt(m, WINNER_DIGITS) == fmt(p, WINNER_DIGITS):
        return "tie"
    return "MFAC" if m < p else "PID"


@dataclass(frozen=True)
class Tuning:
    """One controller's grid on one reading.

    Attributes
    ----------
    keys : tuple[str, ...]
        Parameter names (columns of ``params``).
    params : numpy.ndarray
        (N, P) every combination of the grid.
    objectives : numpy.ndarray
        (N, 4) stop error (m), punctuality (s), RMS jerk (m/s^3), energy (J/kg).
    front : numpy.ndarray
        (N,) bool, the Pareto front.
    cost : numpy.ndarray
        (N,) weighted cost (inf for a run that did not stop).
    chosen : int
        Row of the design point.
    reset_rate : numpy.ndarray or None
        (N,) MFAC: share of samples up to the stop where eq 9's reset fired.
    reproducible : numpy.ndarray or None
        (N,) bool: the run's objectives move at most
        :data:`~workbench.features.reproducible.RTOL` (relative) when the train's
        parameters move by +-:data:`~workbench.features.reproducible.NUDGE`. Only these runs form the front, are chosen,
        and enter the counts, bests and utopia point: the others' metrics
        differ between CPUs.
    """

    keys: tuple[str, ...]
    params: np.ndarray
    objectives: np.ndarray
    front: np.ndarray
    cost: np.ndarray
    chosen: int
    reset_rate: np.ndarray | None = None
    reproducible: np.ndarray | None = None
    stops: np.ndarray | None = None

    @property
    def usable(self) -> np.ndarray:
        """(N,) bool: runs that stopped and are reproducible."""
        ok = np.isfinite(self.cost)
        return ok if self.reproducible is None else ok & self.reproducible

    @property
    def edges(self) -> tuple[str, ...]:
        """Parameters whose chosen value is the first or last of its grid
        (:func:`~workbench.tuning.pareto.grid_edges`)."""
        return grid_edges(self.params, self.chosen, self.keys)

    def chosen_params(self) -> dict[str, float]:
        return {k: float(self.params[self.chosen, i]) for i, k in enumerate(self.keys)}

    def best(self, name: str) -> float:
        """Smallest value of one objective over the runs that stopped."""
        col = self.objectives[:, OBJECTIVES.index(name)]
        col = col[self.usable]
        return float(col.min()) if col.size else math.nan


@dataclass(frozen=True)
class PPDStats:
    """The chosen MFAC run against the CFDL assumptions (see the module docstring).

    Attributes
    ----------
    samples : int
        Samples up to the stop with an estimate (k >= 2).
    reset_rate : float
        Share of them where the reset fired; ``by_condition`` per condition
        (a sample may meet several), and ``"at_limit"``: fired by a small
        du(k-1) with the command u(k-1) at a limit.
    saturated : float
        Share of samples with the command at a limit.
    phi_min, phi_max : float
        Range of the estimate in use.
    updates : int
        Samples with |du(k)| > epsilon (where the realised PPD is defined).
    data_sign_agreement, data_median, data_p95 : float
        Share of those where dy(k+1) / du(k) has the sign of phi(1); median and
        95th percentile of its magnitude.
    t, phi, data_t, data_ppd : numpy.ndarray
        Histories for the figure.
    """

    samples: int
    reset_rate: float
    by_condition: dict
    saturated: float
    phi_min: float
    phi_max: float
    updates: int
    data_sign_agreement: float
    data_median: float
    data_p95: float
    t: np.ndarray
    phi: np.ndarray
    data_t: np.ndarray
    data_ppd: np.ndarray


@dataclass(frozen=True)
class ReadingResult:
    """Everything computed on one plant reading."""

    reading: Reading
    mfac: Tuning
    pid: Tuning
    main: Comparison
    ppd: PPDStats
    utopia_cost: float           # weighted cost of the utopia point (subtracted)
    v_ref: float                 # speed of the linearisation (cruise speed, m/s)
    dc_gain: float               # (m/s) per unit command at v_ref
    time_constant: float         # s, slowest speed mode at v_ref
    frozen_gain: float           # G = rho phi / (lambda + phi^2), phi the median estimate
    frozen_radius: float | None  # spectral radius of the frozen-PPD loop (None: delay not k Ts)
    line: tuple[Comparison, ...]
    sensitivity: dict            # parameter -> max relative cost change to a grid neighbour

    def cost(self, ctrl: str) -> float:
        """Weighted cost of a controller's chosen point, from the utopia point."""
        tun = self.mfac if ctrl == "MFAC" else self.pid
        return float(tun.cost[tun.chosen]) - self.utopia_cost

    @property
    def verdict(self) -> str:
        return winner(self.cost("MFAC"), self.cost("PID"))


@dataclass(frozen=True)
class TrackingResult:
    readings: tuple[ReadingResult, ...]
    stop_tolerance: float
    scales: dict                 # objective -> scale (its unit)
    weights: tuple[float, ...]

    @property
    def profile(self) -> Profile:
        return self.readings[0].main.profile

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"scales": "scales", "weights": "weights",
                   "readings": lambda res: [_reading_json(r) for r in res.readings]}
    to_json = json_method


def _reading_json(r) -> dict:
    return {"name": r.reading.name, "model": r.reading.model, "verdict": r.verdict,
            "mfac": r.mfac.chosen_params(), "pid": r.pid.chosen_params(),
            "objectives": {c: {k: finite_or_none(r.main.value(c, k)) for k in OBJECTIVES}
                           for c in ("MFAC", "PID")},
            "cost": {c: r.cost(c) for c in ("MFAC", "PID")},
            "reset_rate": r.ppd.reset_rate, "dc_gain": r.dc_gain,
            "frozen_radius": r.frozen_radius}


# -- simulation --------------------------------------------------------------------
def _sim(spec: TrackingSpec, train, sec: Section, prof: Profile, control, n) -> TrackingRun:
    brake_start = float(prof.t[np.argmax(prof.a < 0)])
    return simulate_tracking(train, sec.route, prof.speed_at, control, n, Ts=spec.Ts,
                             dt=spec.dt, horizon=sec.run_time + 60.0, brake_start=brake_start)


def _mfac(reading: Reading, gains: dict, n: int) -> MFAC:
    g = MFACGains(**{k: np.asarray(gains[k], float) for k in MFAC_KEYS},
                  epsilon=reading.epsilon)
    return MFAC(g, n, u_min=reading.train.u_min, u_max=reading.train.u_max)


def _pid(spec, reading: Reading, gains: dict, n: int) -> BatchPID:
    return BatchPID(*(np.asarray(gains[k], float) for k in PID_KEYS), n, dt=spec.Ts,
                    u_min=reading.train.u_min, u_max=reading.train.u_max)


def _before_stop(run: TrackingRun) -> np.ndarray:
    """(N, K) mask of the samples before each run's stop (all when it did not stop)."""
    stop = np.where(np.isfinite(run.stop_time), run.stop_time, np.inf)
    return run.t[None, :] < stop[:, None]


def _grid_run(spec, reading, trains, sec, prof, kind: str, P: np.ndarray):
    """Every combination ``P`` of one controller's grid on each of ``trains``,
    one batch (block g of the batch: the grid on train g; runs are independent,
    so each gets the bits of a batch of its own train)."""
    keys = MFAC_KEYS if kind == "mfac" else PID_KEYS
    PP = np.tile(P, (len(trains), 1))
    gains = dict(zip(keys, PP.T))
    ctl = (_mfac(reading, gains, len(PP)) if kind == "mfac" else
           _pid(spec, reading, gains, len(PP)))
    run = _sim(spec, trains, sec, prof,
               lambda k, y, yn: ctl.step(y, yn) if kind == "mfac" else ctl.step(yn - y), len(PP))
    return run, ctl, objectives(run, sec.route.distance, sec.run_time)


def _tune(spec, reading, sec, prof, kind: str) -> tuple[Tuning, TrackingRun, MFAC | None]:
    keys = MFAC_KEYS if kind == "mfac" else PID_KEYS
    grid = reading.mfac_grid if kind == "mfac" else reading.pid_grid
    P = np.array(list(itertools.product(*(grid[k] for k in keys))))
    # each run's reproducibility band: the grid again on the train moved by +-NUDGE
    # (relative; the delay stays whole steps); a run whose objectives move more than
    # RTOL is no result (issue 36, item 5). One batch of the three: one time loop
    trains = (reading.train, *(nudged(reading.train, s * NUDGE, keep=("delay",)) for s in (1, -1)))
    run3, ctl, q3 = _grid_run(spec, reading, trains, sec, prof, kind, P)
    N = len(P)
    obj, *again = (q3.matrix()[g * N:(g + 1) * N] for g in range(len(trains)))
    run = run3.rows(slice(0, N))
    peak_jerk = q3.peak_jerk[:N]
    repro = reproducible([obj, *again])
    col = OBJECTIVES.index("stop_error")
    errs = np.stack([x[:, col] for x in (obj, *again)])
    # within the stop requirement: decided on the band (a band across it is undecided)
    stops = decide(errs.min(axis=0), errs.max(axis=0), spec.stop_tolerance.value, 0.0)
    scales = [spec.scales[k].value for k in OBJECTIVES]
    rate = None
    if kind == "mfac":
        resets = ctl.record("reset")[:N, :run.t.size - 1]
        rate = _mean_before_stop(resets, _before_stop(run)[:, 1:])
    admissible = (stops == -1) & repro
    if spec.peak_jerk is not None:       # comfort: a peak constraint, not a weighted term
        comfortable = admissible & (peak_jerk <= spec.peak_jerk.value)
        if comfortable.any():            # else: no run meets it; the claims say so
            admissible = comfortable
    try:
        chosen = choose(obj, scales, spec.weights, admissible if admissible.any() else repro)
    except ValueError:
        raise ModelError(f"reading {reading.name!r}: no reproducible run of the "
                         f"{kind.upper()} grid ({len(P)} parameter sets) stops on {sec.name}; "
                         f"widen the grid in plant_readings.{kind}") from None
    front = np.zeros(len(P), bool)
    front[repro] = pareto_mask(obj[repro])
    tuning = Tuning(keys, P, obj, front, weighted_cost(obj, scales, spec.weights),
                    chosen, rate, repro, stops)
    return tuning, run, (ctl if kind == "mfac" else None)


def _mean_before_stop(flags: np.ndarray, mask: np.ndarray) -> np.ndarray:
    n = mask[:, :flags.shape[1]].sum(axis=1)
    return np.where(n > 0, (flags * mask[:, :flags.shape[1]]).sum(axis=1) / np.maximum(n, 1),
                    np.nan)


def _compare(spec, reading: Reading, sec: Section, mg: dict, pg: dict):
    """MFAC (row 0) and PID (row 1) in one batch; also the MFAC controller."""
    prof = build_profile(spec.profile_spec(sec), dt=spec.Ts)
    mfac, pid = _mfac(reading, mg, 1), _pid(spec, reading, pg, 1)
    ctl = lambda k, y, yn: np.concatenate([mfac.step(y[:1], yn[:1]), pid.step(yn[1:] - y[1:])])
    both = _sim(spec, reading.train, sec, prof, ctl, 2)
    m, p = both.rows(slice(0, 1)), both.rows(slice(1, 2))
    d, T = sec.route.distance, sec.run_time
    return Comparison(sec, prof, m, p, objectives(m, d, T), objectives(p, d, T)), mfac


# -- CFDL diagnostics ----------------------------------------------------------------
def _ppd_stats(reading: Reading, run: TrackingRun, ctl: MFAC) -> PPDStats:
    K = int(_before_stop(run)[0].sum())             # samples before the stop
    flags = {k: ctl.record(k)[0, :max(K - 1, 0)] for k in ("reset", *RESET_CONDITIONS)}
    phi = ctl.record("phi")[0, :max(K - 1, 0)]
    u, y = run.u[0, :K], run.v[0, :K]
    tr = reading.train
    limit = (u <= tr.u_min) | (u >= tr.u_max)
    flags["at_limit"] = flags["small_du"] & limit[:max(K - 1, 0)]
    du, dy = np.diff(u)[:-1], np.diff(y)[1:]          # du(k), dy(k+1) for k = 1 .. K-2
    upd = np.abs(du) > reading.epsilon
    data = dy[upd] / du[upd]
    sign1 = np.sign(ctl.phi1[0])
    sat = np.mean(limit) if K else math.nan
    mean = lambda x: float(np.mean(x)) if x.size else math.nan
    return PPDStats(
        int(phi.size), mean(flags["reset"]),
        {k: mean(flags[k]) for k in (*RESET_CONDITIONS, "at_limit")},
        float(sat), float(phi.min()), float(phi.max()), int(upd.sum()),
        mean(np.sign(data) == sign1), float(np.median(np.abs(data))) if data.size else math.nan,
        float(np.percentile(np.abs(data), 95)) if data.size else math.nan,
        run.t[1:K], phi, run.t[1:K - 1][upd], data)


def _frozen(spec, reading: Reading, v_ref: float, mg: dict, phi: float):
    """(G, spectral radius) of the eq 7 law with the PPD frozen at ``phi`` around
    the ZOH-sampled linearised plant at ``v_ref`` with its delay (whole samples)."""
    from scipy.signal import cont2discrete, ss2tf
    G = mg["rho"] * phi / (mg["lam"] + phi * phi)
    d = reading.train.delay / spec.Ts
    if abs(d - round(d)) > 1e-9:
        return G, None
    A, B, C = linear_model(reading.train, v_ref)
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, np.zeros((1, 1))), spec.Ts, method="zoh")
    num, den = ss2tf(Ad, Bd, Cd, Dd)
    den = np.polymul(den, np.r_[1.0, np.zeros(int(round(d)))])
    poles = frozen_loop_poles(G, np.trim_zeros(num[0], "f"), den)
    return G, float(np.max(np.abs(poles)))


def _sensitivity(tun: Tuning) -> dict:
    """Per parameter: the largest relative change of the weighted cost when that
    parameter alone moves to a neighbouring grid value (inf: a neighbour did not
    stop; a neighbour that is not reproducible is left out, nan when none is left)."""
    i = tun.chosen
    base = tun.cost[i]
    out = {}
    for key in SENSITIVITY_KEYS:
        j = tun.keys.index(key)
        others = np.delete(np.arange(len(tun.keys)), j)
        same = np.all(tun.params[:, others] == tun.params[i, others], axis=1)
        vals = np.unique(tun.params[same, j])
        pos = int(np.searchsorted(vals, tun.params[i, j]))
        nb = [vals[p] for p in (pos - 1, pos + 1) if 0 <= p < len(vals)]
        rows = [np.flatnonzero(same & (tun.params[:, j] == x))[0] for x in nb]
        rows = [r for r in rows if tun.reproducible is None or tun.reproducible[r]]
        out[key] = max((abs(tun.cost[r] - base) / base for r in rows),
                       default=math.nan if nb else 0.0)   # nan: no reproducible neighbour
    return out


def most_sensitive(sens: dict) -> str:
    """The parameter with the largest finite sensitivity (nan: not measured)."""
    return max(sens, key=lambda k: sens[k] if not math.isnan(sens[k]) else -math.inf)


def run_reading(spec: TrackingSpec, reading: Reading) -> ReadingResult:
    """Tuning, chosen-point comparison, diagnostics and line of one reading."""
    prof = build_profile(spec.profile_spec(spec.main), dt=spec.Ts)
    mt, _, _ = _tune(spec, reading, spec.main, prof, "mfac")
    pt, _, _ = _tune(spec, reading, spec.main, prof, "pid")
    mg, pg = mt.chosen_params(), pt.chosen_params()
    main, ctl = _compare(spec, reading, spec.main, mg, pg)
    ppd = _ppd_stats(reading, main.mfac, ctl)
    v_ref = prof.v_cruise
    G, radius = _frozen(spec, reading, v_ref, mg, float(np.median(ppd.phi)))
    line = tuple(_compare(spec, reading, sec, mg, pg)[0] for sec in spec.line)
    both = np.vstack([t.objectives[t.usable] for t in (mt, pt)])
    scales = [spec.scales[k].value for k in OBJECTIVES]
    utopia = float(weighted_cost(both.min(axis=0)[None, :], scales, spec.weights)[0])
    return ReadingResult(reading, mt, pt, main, ppd, utopia, v_ref, dc_gain(reading.train, v_ref),
                         speed_time_constant(reading.train, v_ref), G, radius, line,
                         _sensitivity(mt))


def run_study(spec: TrackingSpec) -> TrackingResult:
    """Every reading of the design (see the module docstring)."""
    return TrackingResult(tuple(run_reading(spec, r) for r in spec.readings),
                          spec.stop_tolerance.value,
                          {k: q.value for k, q in spec.scales.items()}, spec.weights)


# -- quantities ----------------------------------------------------------------------
def study_quantities(res: TrackingResult) -> dict:
    """Values of every quantity :meth:`~.ato_tracking.ATOTracking.quantity_names` lists."""
    m0 = res.readings[0].main
    q = {"profile.v_cruise": m0.profile.v_cruise,
         # to 1 nm: below, the closed-form profile's end error (about 2e-11 m over
         # 1.6 km) is rounding whose digits move under a few-ulp input change
         "profile.end_error": round(abs(m0.profile.s[-1] - m0.section.route.distance), 9),
         "line.sections": len(res.readings[0].line)}
    for r in res.readings:
        p = f"reading[{r.reading.name}]"
        for c, tun in (("MFAC", r.mfac), ("PID", r.pid)):
            lc = c.lower()
            for i in (*OBJECTIVES, "rms_speed_error"):
                q[f"{p}.{lc}.{i}"] = finite_or_none(r.main.value(c, i))
            q[f"{p}.{lc}.cost"] = finite_or_none(r.cost(c))
            q[f"{p}.{lc}.front_size"] = int(tun.front.sum())
            q[f"{p}.{lc}.peak_jerk"] = finite_or_none(r.main.value(c, "peak_jerk"))
            q[f"{p}.{lc}.grid_edge"] = ", ".join(tun.edges) or "none"
            for i in OBJECTIVES:
                q[f"{p}.best.{lc}.{i}"] = finite_or_none(tun.best(i))
            errs = [x.value(c, "stop_error") for x in r.line]
            q[f"{p}.line.{lc}.within_tolerance"] = sum(e <= res.stop_tolerance for e in errs)
            q[f"{p}.line.{lc}.max_stop_error"] = finite_or_none(max(
                errs, key=lambda e: e if np.isfinite(e) else np.inf)) if errs else None
        # a chosen point on its grid's edge is not a converged optimum (issue 33,
        # item 4): the comparison of the design points is then not determined
        edge = bool(r.mfac.edges or r.pid.edges)
        q[f"{p}.design_points_interior"] = "no" if edge else "yes"
        q[f"{p}.verdict"] = None if edge else r.verdict
        q[f"{p}.mfac_wins"] = None if edge else sum(r.main.winner(i) == "MFAC"
                                                    for i in OBJECTIVES)
        mf, pf = r.mfac.objectives[r.mfac.front], r.pid.objectives[r.pid.front]
        q[f"{p}.front.pid_dominated"] = dominated_share(mf, pf)
        q[f"{p}.front.mfac_dominated"] = dominated_share(pf, mf)
        s = r.ppd
        q[f"{p}.mfac.reset_rate"] = s.reset_rate
        for k in (*RESET_CONDITIONS, "at_limit"):
            q[f"{p}.mfac.reset_rate.{k}"] = s.by_condition[k]
        q[f"{p}.mfac.saturated"] = s.saturated
        stopped = r.mfac.reset_rate[r.mfac.usable]
        q[f"{p}.grid.reset_rate_min"] = finite_or_none(stopped.min()) if stopped.size else None
        q[f"{p}.grid.reset_rate_median"] = finite_or_none(np.median(stopped)) if stopped.size else None
        for k in ("phi_min", "phi_max", "data_sign_agreement", "data_median", "data_p95"):
            q[f"{p}.ppd.{k}"] = finite_or_none(getattr(s, k))
        q[f"{p}.ppd.median_to_dc_gain"] = finite_or_none(s.data_median / r.dc_gain)
        q[f"{p}.plant.dc_gain"] = r.dc_gain
        q[f"{p}.plant.time_constant"] = r.time_constant
        q[f"{p}.frozen.spectral_radius"] = r.frozen_radius
        for k, v in r.sensitivity.items():
            q[f"{p}.sensitivity.{k}"] = finite_or_none(v)
        q[f"{p}.sensitivity.most_sensitive"] = most_sensitive(r.sensitivity)
    return q
