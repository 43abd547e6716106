"""Computation of a ``tracking`` design: per plant reading, multi-objective
tuning of each controller (PID and/or CFDL-MFAC), their Pareto fronts, the
chosen points, the MFAC's CFDL diagnostics and the line.

Per reading (:class:`~.spec.Reading`):

1. every combination of each controller's grid (PID: kp, ki, kd; MFAC: eta,
   mu, rho, lambda, phi(1)) is simulated on the main pair, one batch each;
2. each run gets the four objectives (stop error, punctuality, RMS jerk,
   traction energy; :class:`~workbench.sim.tracking.Objectives`), each
   controller its Pareto front (:func:`workbench.tuning.pareto.pareto_mask`), and the design
   point is the run with the smallest weighted sum sum_j w_j x_j / s_j (scales
   and weights from ``[tuning]``) among the runs that stop within the stop
   requirement (all runs if none does) and keep the peak-jerk limit (when
   any does); it lies on the front. Only
   reproducible runs take part: the grid is run again on the train moved
   by +-1e-9 (relative), and a run whose objectives move more than
   :data:`~workbench.features.reproducible.RTOL` is left out of fronts,
   choice and counts (a relay-like loop turns last bits into another run);
3. a chosen MFAC run is examined against the CFDL assumptions (:mod:`.mfac`);
4. with both controllers, "MFAC beats PID" on a reading when MFAC's chosen
   point has the smaller weighted cost, both counted from the reading's
   utopia point (the best value of each objective over both grids), so that
   an objective's common floor (the energy any run needs) does not decide a
   tie; equal at 3 significant digits is a tie.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ...controllers.mfac import RESET_CONDITIONS, MFAC, MFACGains
from ...controllers.pid import BatchPID
from ...errors import ModelError
from ...features.reproducible import NUDGE, decide, nudged, reproducible
from ...jsonable import finite_or_none, json_method
from ...plants.train002 import dc_gain, speed_time_constant
from ...profiles import Profile, build_profile
from ...report.markdown import fmt
from ...sim.tracking import Objectives, TrackingRun, objectives, simulate_tracking
from ...tuning.pareto import choose, dominated_share, grid_edges, pareto_mask, weighted_cost
from .mfac import (PPDStats, before_stop, frozen, mean_before_stop, most_sensitive, ppd_stats,
                   sensitivity)
from .spec import MFAC_KEYS, OBJECTIVES, PID_KEYS, Reading, Section, TrackingSpec

__all__ = ["Comparison", "ReadingResult", "TrackingResult", "Tuning", "run_reading", "run_study",
           "study_quantities", "winner"]

WINNER_DIGITS = 3   # significant digits at which two values count as a tie


@dataclass(frozen=True)
class Comparison:
    """MFAC and PID (chosen points) on one section: profile, histories, objectives
    (None for a controller the reading does not have)."""

    section: Section
    profile: Profile
    mfac: TrackingRun | None
    pid: TrackingRun | None
    mfac_q: Objectives | None
    pid_q: Objectives | None

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
class ReadingResult:
    """Everything computed on one plant reading."""

    reading: Reading
    mfac: Tuning | None          # None: the reading has no such controller
    pid: Tuning | None
    main: Comparison
    ppd: PPDStats | None         # the CFDL diagnostics (None without an MFAC)
    utopia_cost: float           # weighted cost of the utopia point (subtracted)
    v_ref: float                 # speed of the linearisation (cruise speed, m/s)
    dc_gain: float               # (m/s) per unit command at v_ref
    time_constant: float         # s, slowest speed mode at v_ref
    frozen_gain: float | None    # G = rho phi / (lambda + phi^2), phi the median estimate
    frozen_radius: float | None  # spectral radius of the frozen-PPD loop (None: delay not k Ts)
    line: tuple[Comparison, ...]
    sensitivity: dict            # parameter -> max relative cost change to a grid neighbour

    @property
    def tunings(self) -> tuple[tuple[str, Tuning], ...]:
        """("MFAC" | "PID", tuning) of each controller the reading has."""
        return tuple((c, t) for c, t in (("MFAC", self.mfac), ("PID", self.pid))
                     if t is not None)

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
    ctrls = [c for c, _ in r.tunings]
    return {"name": r.reading.name, "model": r.reading.model,
            "verdict": r.verdict if len(ctrls) == 2 else None,
            "mfac": None if r.mfac is None else r.mfac.chosen_params(),
            "pid": None if r.pid is None else r.pid.chosen_params(),
            "objectives": {c: {k: finite_or_none(r.main.value(c, k)) for k in OBJECTIVES}
                           for c in ctrls},
            "cost": {c: r.cost(c) for c in ctrls},
            "reset_rate": None if r.ppd is None else r.ppd.reset_rate, "dc_gain": r.dc_gain,
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
        rate = mean_before_stop(resets, before_stop(run)[:, 1:])
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
                         "widen the grid in "
                         + ".".join(x for x in (reading.table, kind) if x)) from None
    front = np.zeros(len(P), bool)
    front[repro] = pareto_mask(obj[repro])
    tuning = Tuning(keys, P, obj, front, weighted_cost(obj, scales, spec.weights),
                    chosen, rate, repro, stops)
    return tuning, run, (ctl if kind == "mfac" else None)


def _compare(spec, reading: Reading, sec: Section, gains: dict):
    """The chosen points (``gains``: controller -> parameters) in one batch, one
    row each in the order of :attr:`Reading.controllers`; also the MFAC
    controller (None without one)."""
    prof = build_profile(spec.profile_spec(sec), dt=spec.Ts)
    mfac = _mfac(reading, gains["mfac"], 1) if "mfac" in gains else None
    pid = _pid(spec, reading, gains["pid"], 1) if "pid" in gains else None
    if mfac is not None and pid is not None:
        ctl = lambda k, y, yn: np.concatenate([mfac.step(y[:1], yn[:1]), pid.step(yn[1:] - y[1:])])
    elif mfac is not None:
        ctl = lambda k, y, yn: mfac.step(y, yn)
    else:
        ctl = lambda k, y, yn: pid.step(yn - y)
    ctrls = [c for c in ("mfac", "pid") if c in gains]
    both = _sim(spec, reading.train, sec, prof, ctl, len(ctrls))
    runs = {c: both.rows(slice(i, i + 1)) for i, c in enumerate(ctrls)}
    d, T = sec.route.distance, sec.run_time
    q = {c: objectives(r, d, T) for c, r in runs.items()}
    return Comparison(sec, prof, runs.get("mfac"), runs.get("pid"), q.get("mfac"),
                      q.get("pid")), mfac


def run_reading(spec: TrackingSpec, reading: Reading) -> ReadingResult:
    """Tuning, chosen-point comparison, diagnostics and line of one reading."""
    prof = build_profile(spec.profile_spec(spec.main), dt=spec.Ts)
    tun = {c: _tune(spec, reading, spec.main, prof, c)[0] for c in reading.controllers}
    gains = {c: t.chosen_params() for c, t in tun.items()}
    main, ctl = _compare(spec, reading, spec.main, gains)
    v_ref = prof.v_cruise
    mt = tun.get("mfac")
    ppd = G = radius = None
    sens: dict = {}
    if mt is not None:           # the CFDL diagnostics of the chosen MFAC run
        ppd = ppd_stats(reading, main.mfac, ctl)
        G, radius = frozen(spec, reading, v_ref, gains["mfac"], float(np.median(ppd.phi)))
        sens = sensitivity(mt)
    line = tuple(_compare(spec, reading, sec, gains)[0] for sec in spec.line)
    both = np.vstack([t.objectives[t.usable] for t in tun.values()])
    scales = [spec.scales[k].value for k in OBJECTIVES]
    utopia = float(weighted_cost(both.min(axis=0)[None, :], scales, spec.weights)[0])
    return ReadingResult(reading, mt, tun.get("pid"), main, ppd, utopia, v_ref,
                         dc_gain(reading.train, v_ref), speed_time_constant(reading.train, v_ref),
                         G, radius, line, sens)


def run_study(spec: TrackingSpec) -> TrackingResult:
    """Every reading of the design (see the module docstring)."""
    return TrackingResult(tuple(run_reading(spec, r) for r in spec.readings),
                          spec.stop_tolerance.value,
                          {k: q.value for k, q in spec.scales.items()}, spec.weights)


# -- quantities ----------------------------------------------------------------------
def study_quantities(res: TrackingResult) -> dict:
    """Values of every quantity :func:`.spec.quantity_names` lists."""
    m0 = res.readings[0].main
    q = {"profile.v_cruise": m0.profile.v_cruise,
         # to 1 nm: below, the closed-form profile's end error (about 2e-11 m over
         # 1.6 km) is rounding whose digits move under a few-ulp input change
         "profile.end_error": round(abs(m0.profile.s[-1] - m0.section.route.distance), 9),
         "line.sections": len(res.readings[0].line)}
    for r in res.readings:
        p = f"reading[{r.reading.name}]"
        for c, tun in r.tunings:
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
        edge = any(t.edges for _, t in r.tunings)
        q[f"{p}.design_points_interior"] = "no" if edge else "yes"
        q[f"{p}.plant.dc_gain"] = r.dc_gain
        q[f"{p}.plant.time_constant"] = r.time_constant
        if len(r.tunings) == 2:
            _comparison_quantities(q, p, r, edge)
        if r.ppd is not None:
            _cfdl_quantities(q, p, r)
    return q


def _comparison_quantities(q: dict, p: str, r: ReadingResult, edge: bool) -> None:
    """MFAC against PID on a reading with both (``edge``: a chosen point on its grid's edge)."""
    q[f"{p}.verdict"] = None if edge else r.verdict
    q[f"{p}.mfac_wins"] = None if edge else sum(r.main.winner(i) == "MFAC"
                                                for i in OBJECTIVES)

    mf, pf = r.mfac.objectives[r.mfac.front], r.pid.objectives[r.pid.front]
    q[f"{p}.front.pid_dominated"] = dominated_share(mf, pf)
    q[f"{p}.front.mfac_dominated"] = dominated_share(pf, mf)


def _cfdl_quantities(q: dict, p: str, r: ReadingResult) -> None:
    """The CFDL diagnostics of a reading's chosen MFAC run (:mod:`.mfac`)."""
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
    q[f"{p}.frozen.spectral_radius"] = r.frozen_radius
    for k, v in r.sensitivity.items():
        q[f"{p}.sensitivity.{k}"] = finite_or_none(v)
    q[f"{p}.sensitivity.most_sensitive"] = most_sensitive(r.sensitivity)
