"""Study ``ato-tracking``: paper 002's CFDL-MFAC against PID on ATO speed profiles.

Design tables read here: ``[route]`` (the main station pair), ``[profile]``
(limits of the target curve), ``[train]`` (002 model, units checked),
``[simulation]`` (sample, step), ``[mfac]`` and ``[pid]`` (tuning grids: every
combination is simulated and the one with the smallest RMS speed error is
kept — the same rule for both controllers), ``[sensitivity]`` (MFAC lambda
sweep and one-at-a-time factors) and ``[[line]]`` (further station pairs).
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..controllers.mfac import MFAC, MFACGains
from ..controllers.pid import PID
from ..errors import DesignError, ModelError
from ..plants.train002 import PARAMETER_UNITS, Train002
from ..profiles import Profile, ProfileSpec, build_profile
from ..reader import Quantity, Reader
from ..report.markdown import fmt
from ..sim.tracking import QualityIndices, Route, TrackingRun, quality_indices, simulate_tracking

INDICES = QualityIndices.NAMES
MFAC_KEYS = ("lam", "rho", "eta", "mu", "phi1")
WINNER_DIGITS = 3   # significant digits at which two index values count as a tie


@dataclass(frozen=True)
class Section:
    """One station pair: route, planned time and where its data come from."""

    name: str
    route: Route
    run_time: float
    v_limit: float
    source: str


@dataclass(frozen=True)
class TrackingSpec:
    main: Section
    line: tuple[Section, ...]
    profile: dict           # accel, brake, jerk (m/s^2, m/s^2, m/s^3)
    train: dict             # Quantity per PARAMETER_UNITS key
    u_limits: tuple[float, float]
    Ts: float
    dt: float
    mfac_grid: dict         # key -> tuple of values
    epsilon: float
    pid_grid: dict          # kp, ki, kd -> tuple
    stop_tolerance: Quantity
    lambda_factors: tuple[float, ...]
    oat_factors: tuple[float, ...]

    def train_model(self) -> Train002:
        p = {k: q.value for k, q in self.train.items()}
        return Train002(**p, u_min=self.u_limits[0], u_max=self.u_limits[1])

    def profile_spec(self, sec: Section) -> ProfileSpec:
        return ProfileSpec(sec.route.distance, sec.v_limit, self.profile["accel"],
                           self.profile["brake"], self.profile["jerk"], sec.run_time)


@dataclass(frozen=True)
class Comparison:
    """MFAC and PID on one section: profile, histories and indices (index 0 of each batch)."""

    section: Section
    profile: Profile
    mfac: TrackingRun
    pid: TrackingRun
    mfac_q: QualityIndices
    pid_q: QualityIndices

    def value(self, ctrl: str, index: str) -> float:
        return float(getattr(self.mfac_q if ctrl == "MFAC" else self.pid_q, index)[0])

    def winner(self, index: str) -> str:
        m, p = self.value("MFAC", index), self.value("PID", index)
        if not (np.isfinite(m) and np.isfinite(p)):
            return "undetermined"
        if fmt(m, WINNER_DIGITS) == fmt(p, WINNER_DIGITS):
            return "tie"          # equal at the digits the report prints
        return "MFAC" if m < p else "PID"


@dataclass(frozen=True)
class TrackingResult:
    mfac_gains: dict                 # chosen MFAC parameters
    pid_gains: dict                  # chosen kp, ki, kd
    tuning_counts: tuple[int, int]   # grid sizes (MFAC, PID)
    main: Comparison
    line: tuple[Comparison, ...]
    lambda_sweep: tuple[tuple[float, QualityIndices], ...]   # (lambda, indices of 1 run)
    lambda_runs: TrackingRun
    oat: dict                        # parameter -> max relative change of RMS error
    resets: int                      # PPD resets in the main MFAC run
    stop_tolerance: float            # m


def read_gradients(r: Reader) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``grade_from`` (m, increasing from 0) and ``grade`` (-, |i| <= 0.05) of a table."""
    g_from = r.numbers("grade_from", default=(0.0,), what="positions (m)")
    grade = r.numbers("grade", default=(0.0,), what="gradients (-)")
    if len(g_from) != len(grade) or g_from[0] != 0.0 or list(g_from) != sorted(g_from):
        raise r.fail("grade_from", list(g_from), "increasing positions starting at 0, one per "
                     "entry of grade")
    if any(abs(x) > 0.05 for x in grade):
        raise r.fail("grade", list(grade), "gradients within +/-0.05 (50 permille)")
    return g_from, grade


def _section(r: Reader, *, with_source: bool) -> Section:
    dist = r.quantity("distance", "m", positive=True)
    T = r.quantity("run_time", "s", positive=True)
    vlim = r.quantity("v_limit", "m/s", positive=True, hi=150.0)
    name = r.string("name")
    g_from, grade = read_gradients(r)
    src = r.string("source") if with_source else dist.source
    r.finish()
    return Section(name, Route(dist.value, g_from, grade), T.value, vlim.value, src)


class ATOTracking:
    kind = "ato-tracking"
    uses_solver = False    # no convex solver runs: the report says so

    # -- load ----------------------------------------------------------------
    def load(self, root: Reader) -> TrackingSpec:
        main = _section(root.table("route"), with_source=False)
        line = tuple(_section(r, with_source=True) for r in root.tables("line", default=[]))
        pr = root.table("profile")
        prof = {"accel": pr.quantity("accel", "m/s^2", positive=True, hi=2.0).value,
                "brake": pr.quantity("brake", "m/s^2", positive=True, hi=2.0).value,
                "jerk": pr.quantity("jerk", "m/s^3", positive=True, hi=5.0).value}
        pr.finish()
        tr = root.table("train")
        tr.string("model", choices=("delay-lag-002",))
        sign = {"e": {}, "c0": {"nonneg": True}, "c1": {"nonneg": True}, "c2": {"nonneg": True}}
        train = {k: tr.quantity(k, unit, **sign.get(k, {"positive": True}))
                 for k, unit in PARAMETER_UNITS.items()}
        u_lim = (tr.quantity("u_min", "m/s^2", hi=0.0).value,
                 tr.quantity("u_max", "m/s^2", positive=True).value)
        tr.finish()
        sim = root.table("simulation")
        Ts = sim.quantity("Ts", "s", positive=True, hi=2.0).value
        dt = sim.quantity("dt", "s", positive=True, hi=0.1).value
        sim.finish()
        for name, x in (("Ts", Ts), ("train.delay", train["delay"].value)):
            if abs(round(x / dt) * dt - x) > 1e-9:
                raise DesignError(root.path, name if "." in name else f"simulation.{name}", x,
                                  f"a multiple of simulation.dt = {dt} s")
        mf = root.table("mfac")
        grid = {k: mf.numbers(k, positive=True, what=f"{k} values") for k in MFAC_KEYS}
        for k in ("rho", "eta"):
            if max(grid[k]) > 1.0:
                raise mf.fail(k, list(grid[k]), "values in (0, 1] (paper 002)")
        eps = mf.number("epsilon", positive=True)
        mf.finish()
        pi = root.table("pid")
        pid = {k: pi.numbers(k, what=f"{k} gains") for k in ("kp", "ki", "kd")}
        for k, vals in pid.items():
            if min(vals) < 0:
                raise pi.fail(k, list(vals), "non-negative gains")
        pi.finish()
        req = root.table("requirements")
        tol = req.quantity("stop_tolerance", "m", positive=True)
        req.finish()
        se = root.table("sensitivity")
        lf = se.numbers("lambda_factors", positive=True, min_len=2, what="factors")
        of = se.numbers("oat_factors", positive=True, min_len=1, what="factors")
        se.finish()
        spec = TrackingSpec(main, line, prof, train, u_lim, Ts, dt, grid, eps, pid, tol, lf, of)
        for i, sec in enumerate((main, *line)):
            try:
                build_profile(spec.profile_spec(sec), dt=Ts)
            except ModelError as exc:
                key = "route.run_time" if i == 0 else f"line[{i - 1}].run_time"
                raise DesignError(root.path, key, sec.run_time, f"a feasible run time ({exc})") \
                    from None
        return spec

    def quantity_names(self, spec: TrackingSpec) -> set[str]:
        names = {"profile.v_cruise", "profile.end_error", "mfac.resets", "line.sections",
                 "sensitivity.most_sensitive", "sensitivity.lambda.rms_ratio"}
        for c in ("mfac", "pid"):
            names |= {f"main.{c}.{i}" for i in (*INDICES, "rms_speed_error")}
            names |= {f"line.{c}.max_stop_error", f"line.{c}.within_tolerance"}
        names |= {f"main.winner.{i}" for i in INDICES}
        names |= {f"line.mfac_wins.{i}" for i in INDICES}
        names |= {f"sensitivity.oat.{k}" for k in ("lam", "rho", "eta", "mu")}
        return names

    # -- run -------------------------------------------------------------------
    def run(self, design) -> TrackingResult:
        spec: TrackingSpec = design.spec
        train = spec.train_model()
        main_prof = build_profile(spec.profile_spec(spec.main), dt=spec.Ts)
        # tuning: the whole grid of each controller on the main section, one batch each
        combos = list(itertools.product(*(spec.mfac_grid[k] for k in MFAC_KEYS)))
        cols = np.array(combos).T
        tune_m = _run_mfac(spec, train, spec.main, main_prof, dict(zip(MFAC_KEYS, cols)))
        q = quality_indices(tune_m, spec.main.route.distance, spec.main.run_time)
        best_m = _best(q)
        mg = {k: float(cols[i][best_m]) for i, k in enumerate(MFAC_KEYS)}
        pid_combos = list(itertools.product(spec.pid_grid["kp"], spec.pid_grid["ki"],
                                            spec.pid_grid["kd"]))
        tune_p = _run_pid(spec, train, spec.main, main_prof, pid_combos)
        best_p = _best(quality_indices(tune_p, spec.main.route.distance, spec.main.run_time))
        pg = dict(zip(("kp", "ki", "kd"), pid_combos[best_p]))
        comps = [_compare(spec, train, sec, mg, pg) for sec in (spec.main, *spec.line)]
        # sensitivity: lambda sweep, then each of lam, rho, eta, mu scaled one at a time
        lams = tuple(mg["lam"] * f for f in spec.lambda_factors)
        sweep = _run_mfac(spec, train, spec.main, main_prof, {**mg, "lam": np.array(lams)})
        sq = quality_indices(sweep, spec.main.route.distance, spec.main.run_time)
        sweep_rows = tuple((lam, _take(sq, i)) for i, lam in enumerate(lams))
        oat = _one_at_a_time(spec, train, main_prof, mg)
        return TrackingResult(mg, pg, (len(combos), len(pid_combos)), comps[0][0],
                              tuple(c for c, _ in comps[1:]), sweep_rows, sweep, oat, comps[0][1],
                              spec.stop_tolerance.value)

    def quantities(self, res: TrackingResult) -> dict:
        m = res.main
        q = {"profile.v_cruise": m.profile.v_cruise,
             "profile.end_error": abs(m.profile.s[-1] - m.section.route.distance),
             "mfac.resets": res.resets, "line.sections": len(res.line)}
        for c in ("MFAC", "PID"):
            for i in (*INDICES, "rms_speed_error"):
                q[f"main.{c.lower()}.{i}"] = _finite(m.value(c, i))
        for i in INDICES:
            q[f"main.winner.{i}"] = m.winner(i)
            q[f"line.mfac_wins.{i}"] = sum(c.winner(i) == "MFAC" for c in res.line)
        for c in ("MFAC", "PID"):
            errs = [x.value(c, "stop_error") for x in res.line]
            worst = max(errs, key=lambda e: e if np.isfinite(e) else np.inf) if errs else None
            q[f"line.{c.lower()}.max_stop_error"] = None if worst is None else float(worst)
            q[f"line.{c.lower()}.within_tolerance"] = sum(e <= res.stop_tolerance for e in errs)
        rms = [r.rms_speed_error[0] for _, r in res.lambda_sweep]
        q["sensitivity.lambda.rms_ratio"] = _finite(max(rms) / min(rms))
        for k, v in res.oat.items():
            q[f"sensitivity.oat.{k}"] = _finite(v)
        q["sensitivity.most_sensitive"] = max(res.oat, key=res.oat.get)
        return q


def _finite(x):
    return float(x) if np.isfinite(x) else None


def _best(q: QualityIndices) -> int:
    """Index of the smallest RMS speed error among runs that stopped."""
    score = np.where(np.isfinite(q.stop_error), q.rms_speed_error, np.inf)
    return int(np.argmin(score))


def _take(q: QualityIndices, i: int) -> QualityIndices:
    return QualityIndices(*(np.asarray(getattr(q, f))[i:i + 1] for f in
                            (*INDICES, "rms_speed_error")))


def _sim(spec, train, sec, prof, control, n) -> TrackingRun:
    brake_start = float(prof.t[np.argmax(prof.a < 0)])
    return simulate_tracking(train, sec.route, prof.speed_at, control, n, Ts=spec.Ts, dt=spec.dt,
                             horizon=sec.run_time + 60.0, brake_start=brake_start)


def _mfac(spec, train, gains: dict, n: int) -> MFAC:
    g = MFACGains(**{k: np.asarray(gains[k], float) for k in MFAC_KEYS}, epsilon=spec.epsilon)
    return MFAC(g, n, u_min=train.u_min, u_max=train.u_max)


def _run_mfac(spec, train, sec, prof, gains: dict) -> TrackingRun:
    n = max(np.size(v) for v in gains.values())
    ctl = _mfac(spec, train, gains, n)
    return _sim(spec, train, sec, prof, lambda k, y, yn: ctl.step(y, yn), n)


def _run_pid(spec, train, sec, prof, combos) -> TrackingRun:
    pids = [PID(kp, ki, kd, dt=spec.Ts, u_min=train.u_min, u_max=train.u_max)
            for kp, ki, kd in combos]
    ctl = lambda k, y, yn: np.array([p.step(r - x) for p, r, x in zip(pids, yn, y)])
    return _sim(spec, train, sec, prof, ctl, len(pids))


def _compare(spec, train, sec, mg, pg) -> tuple[Comparison, int]:
    """MFAC (row 0) and PID (row 1) in one batch; also the MFAC's PPD resets."""
    prof = build_profile(spec.profile_spec(sec), dt=spec.Ts)
    mfac = _mfac(spec, train, mg, 1)
    pid = PID(pg["kp"], pg["ki"], pg["kd"], dt=spec.Ts, u_min=train.u_min, u_max=train.u_max)
    ctl = lambda k, y, yn: np.array([mfac.step(y[:1], yn[:1])[0], pid.step(yn[1] - y[1])])
    both = _sim(spec, train, sec, prof, ctl, 2)
    m, p = both.rows(slice(0, 1)), both.rows(slice(1, 2))
    d, T = sec.route.distance, sec.run_time
    return (Comparison(sec, prof, m, p, quality_indices(m, d, T), quality_indices(p, d, T)),
            int(mfac.resets[0]))


def _one_at_a_time(spec, train, prof, mg) -> dict:
    """Largest relative change of the RMS speed error when one of lam, rho, eta,
    mu is multiplied by each factor (rho, eta capped at 1)."""
    keys = ("lam", "rho", "eta", "mu")
    rows = [dict(mg)]
    for k in keys:
        for f in spec.oat_factors:
            val = mg[k] * f
            rows.append({**mg, k: min(val, 1.0) if k in ("rho", "eta") else val})
    gains = {k: np.array([r[k] for r in rows]) for k in MFAC_KEYS}
    run = _run_mfac(spec, train, spec.main, prof, gains)
    rms = quality_indices(run, spec.main.route.distance, spec.main.run_time).rms_speed_error
    base, n_f = rms[0], len(spec.oat_factors)
    return {k: float(np.max(np.abs(rms[1 + i * n_f:1 + (i + 1) * n_f] - base)) / base)
            for i, k in enumerate(keys)}


STUDY = ATOTracking()
