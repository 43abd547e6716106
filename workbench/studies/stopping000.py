"""Study ``station-stopping``: PID, SMC and SMARC station stops of paper 000.

Every run starts where the ATO target curve starts braking (cruise speed of
the section) and tracks the target x_d(t) to the stopping point through the
electro-pneumatic brake plant of :mod:`workbench.plants.brake000`. Each
repeat draws an uncertain plant (load-weighing / mass error, Davis
resistance, transmission delays, lags, air-brake gain, station gradient)
from seeded uniform ranges; all three controllers meet the same draws
(common random numbers). The logs of the paper are not public: these stops
are synthetic.

Design tables: ``[plant]`` (brake parameters, SI), ``[uncertainty]``,
``[target]``, ``[[sections]]``, ``[controllers.pid|sliding|smarc]``, ``[sim]``.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..controllers.pid import PID
from ..controllers.smarc import AdaptiveSlidingModeController
from ..controllers.smc import SlidingGains, SlidingModeController
from ..plants.brake000 import PARAMETER_UNITS
from ..reader import Quantity, Reader
from ..sim.stopping import TargetCurve, batch_params, simulate

#: Paper 000's three controllers, then SMARC with the discontinuous sgn of eq 22
#: as printed (no boundary layer), to show the chattering the layer removes.
CONTROLLERS = ("pid", "smc", "smarc", "smarc-sgn")
PAPER_CONTROLLERS = CONTROLLERS[:3]
#: Uncertain factors: name -> (what, unit)
UNCERTAIN = {
    "mass_ratio": ("true / estimated mass (load-weighing error)", "1"),
    "resistance": ("factor on the Davis coefficients", "1"),
    "delay": ("factor on the transmission delays T1, T3", "1"),
    "lag": ("factor on the lags T2, T4", "1"),
    "air_gain": ("factor on K1 (air-brake gain)", "1"),
    "gradient": ("station gradient theta (+ uphill)", "permille"),
}


@dataclass(frozen=True)
class Section:
    name: str
    length: float
    source: str


@dataclass(frozen=True)
class StopSpec:
    params: dict            # name -> Quantity
    ranges: dict            # name -> (lo, hi)
    v_max: Quantity
    a_acc: Quantity
    a_dec: Quantity
    sections: tuple[Section, ...]
    pid: dict
    sliding: SlidingGains
    smarc: dict
    dt: float
    dt_ctrl: float
    repeats: int
    seed: int
    c_max: float
    c_min: float
    published: tuple = ()   # (section, smarc, smc, pid, smarc mean, smarc var, source): data


def load_plant(root: Reader) -> dict:
    """The ``[plant]`` table: every brake parameter with its SI unit."""
    plant = root.table("plant")
    plant.string("model", choices=("brake-000",))
    params = {k: plant.quantity(k, u, nonneg=k in ("v_ho", "d1", "d2"), positive=k not in
                                ("v_ho", "d1", "d2")) for k, u in PARAMETER_UNITS.items()}
    plant.finish()
    return params


def load_stop_spec(root: Reader) -> StopSpec:
    params = load_plant(root)
    unc = root.table("uncertainty")
    ranges = {}
    for k in UNCERTAIN:
        lo, hi = unc.numbers(k, what="bounds [lo, hi]")
        if len((lo, hi)) != 2 or not lo <= hi:
            raise unc.fail(k, [lo, hi], "two bounds [lo, hi] with lo <= hi")
        if k != "gradient" and not lo > 0:
            raise unc.fail(k, [lo, hi], "positive factors")
        ranges[k] = (lo, hi)
    unc.finish()
    tg = root.table("target")
    v_max = tg.quantity("v_max", "m/s", positive=True, hi=40.0)
    a_acc = tg.quantity("a_acc", "m/s^2", positive=True, hi=2.0)
    a_dec = tg.quantity("a_dec", "m/s^2", positive=True, hi=2.0)
    tg.finish()
    sections = []
    for s in root.tables("sections"):
        sections.append(Section(s.string("name"), s.number("length", positive=True),
                                s.string("source")))
        s.finish()
    if not sections:
        raise root.fail("sections", [], "at least one [[sections]] entry")
    ctl = root.table("controllers")
    p = ctl.table("pid")
    pid = {k: p.number(k, nonneg=True) for k in ("kp", "ki", "kd")}
    p.finish()
    s = ctl.table("sliding")
    sliding = SlidingGains(c=s.number("c", positive=True), k_s=s.number("k_s", positive=True),
                           eta=s.number("eta", nonneg=True), phi=s.number("phi", nonneg=True))
    s.finish()
    a = ctl.table("smarc")
    smarc = {"lam": a.number("lam", positive=True),
             "theta_min": a.number("theta_min", positive=True),
             "theta_max": a.number("theta_max", positive=True)}
    if not smarc["theta_min"] < 1.0 < smarc["theta_max"]:
        raise a.fail("theta_max", smarc["theta_max"], "bounds with theta_min < 1 < theta_max")
    a.finish()
    ctl.finish()
    sim = root.table("sim")
    spec = StopSpec(params, ranges, v_max, a_acc, a_dec, tuple(sections), pid, sliding, smarc,
                    dt=sim.number("dt", positive=True, hi=0.05),
                    dt_ctrl=sim.number("dt_ctrl", positive=True, hi=1.0),
                    repeats=sim.number("repeats", integer=True, lo=2, hi=10000),
                    seed=sim.number("seed", integer=True, lo=0),
                    c_max=sim.number("c_max", positive=True, hi=2.0),
                    c_min=-sim.number("traction_max", positive=True, hi=2.0))
    sim.finish()
    pub = []
    for r in root.tables("published", default=[]):
        k = r.number("section", integer=True, lo=1, hi=len(sections))
        row = (k, *(r.number(c, nonneg=True) for c in PAPER_CONTROLLERS[::-1]),
               r.number("smarc_mean", default=None), r.number("smarc_var", default=None, nonneg=True),
               r.string("source"))
        pub.append(row)
        r.finish()
    return replace(spec, published=tuple(pub))


@dataclass(frozen=True)
class CellStats:
    """Stop statistics of one controller on one section (cm, cm^2, m/s^3, s)."""

    mean_abs: float
    mean: float
    var: float
    max_abs: float
    jerk_mean: float
    jerk_max: float
    run_time: float
    command_rate: float     # mean |dc/dt| of the brake command while moving (m/s^3)
    errors: tuple[float, ...]


@dataclass(frozen=True)
class StopResult:
    sections: tuple[Section, ...]
    planned_time: tuple[float, ...]       # braking phase, s
    stats: dict                           # (controller, section index) -> CellStats
    example: dict                         # controller -> (t, x - x_stop, v, v_d) of one run
    theta_hat_final: tuple[float, float]  # SMARC estimate range at the end

    def overall(self, ctl: str) -> float:
        """Mean over sections of the per-section mean |stop error| (cm)."""
        return float(np.mean([self.stats[ctl, i].mean_abs for i in range(len(self.sections))]))


def draw_plants(spec: StopSpec, n_sections: int) -> dict:
    """Uncertain factors per (section, repeat), seeded per section."""
    seqs = np.random.SeedSequence(spec.seed).spawn(n_sections)
    out = {k: np.empty((n_sections, spec.repeats)) for k in UNCERTAIN}
    for i, sq in enumerate(seqs):
        rng = np.random.default_rng(sq)
        for k in UNCERTAIN:
            out[k][i] = rng.uniform(*spec.ranges[k], spec.repeats)
    return out


def run_station_stops(spec: StopSpec, *, batch: str = "all") -> StopResult:
    """Simulate every controller x section x repeat.

    Parameters
    ----------
    batch : {"all", "per-section"}
        One batched simulation of all runs, or one per section (the
        benchmark's baseline); results are identical.
    """
    ns, R = len(spec.sections), spec.repeats
    draws = draw_plants(spec, ns)
    if batch == "all":
        return _collect(spec, [_simulate_block(spec, draws, list(range(ns)))])
    return _collect(spec, [_simulate_block(spec, draws, [i]) for i in range(ns)])


def _simulate_block(spec: StopSpec, draws: dict, secs: list[int]):
    R, nc = spec.repeats, len(CONTROLLERS)
    ci = np.repeat(np.arange(nc), len(secs) * R)              # controller of each run
    si = np.tile(np.repeat(secs, R), nc)                      # section of each run
    ri = np.tile(np.arange(R), nc * len(secs))                # repeat of each run
    n = ci.size
    d = {k: v[si, ri] for k, v in draws.items()}
    base = {k: q.value for k, q in spec.params.items()}
    p = batch_params(base, n, {
        "T1": base["T1"] * d["delay"], "T3": base["T3"] * d["delay"],
        "T2": base["T2"] * d["lag"], "T4": base["T4"] * d["lag"], "K1": base["K1"] * d["air_gain"],
        "d0": base["d0"] * d["resistance"], "d1": base["d1"] * d["resistance"],
        "d2": base["d2"] * d["resistance"]})
    lengths = np.array([spec.sections[i].length for i in si])
    tc = TargetCurve.build(lengths, v_max=spec.v_max.value, a_acc=spec.a_acc.value,
                           a_dec=spec.a_dec.value)
    tb = tc.t_brake
    x0, v0, _ = tc.at(tb)
    smc = SlidingModeController(spec.sliding)
    smarc = AdaptiveSlidingModeController(spec.sliding, dt=spec.dt_ctrl, theta0=np.ones(n),
                                          **spec.smarc)
    smarc_sgn = AdaptiveSlidingModeController(replace(spec.sliding, phi=0.0), dt=spec.dt_ctrl,
                                              theta0=np.ones(n), **spec.smarc)
    is_pid = np.flatnonzero(ci == 0)
    pids = [PID(**spec.pid, dt=spec.dt_ctrl) for _ in is_pid]

    def policy(t, obs):
        xd, vd, ad = tc.at(t + tb)
        e, de = obs.x - xd, obs.v - vd
        c = np.select([ci == 1, ci == 2],
                      [-smc.step(e, de, ad), -smarc.step(e, de, ad, adapt=ci == 2)],
                      -smarc_sgn.step(e, de, ad, adapt=ci == 3))
        c[is_pid] = -ad[is_pid] + np.array([pid.step(err) for pid, err in zip(pids, de[is_pid])])
        return c

    t_end = float((tc.t_final - tb).max()) + 30.0
    tr = simulate(p, policy, n=n, t_end=t_end, dt=spec.dt, dt_ctrl=spec.dt_ctrl,
                  dt_rec=spec.dt_ctrl, x0=x0, v0=v0, theta=d["gradient"],
                  kappa=1.0 / d["mass_ratio"], c_init=0.0, t_arm=0.0, c_min=spec.c_min,
                  c_max=spec.c_max)
    return ci, si, tr, lengths, tc.t_final - tb, smarc.theta_hat[ci == 2], tc, tb


def _collect(spec: StopSpec, blocks) -> StopResult:
    stats, example, planned, th = {}, {}, {}, []
    for ci, si, tr, lengths, t_plan, theta_hat, tc, tb in blocks:
        err_cm = (tr.x_stop - lengths) * 100.0
        jerk = np.abs(np.diff(tr.a, axis=0)) / spec.dt_ctrl
        crate = np.abs(np.diff(tr.c, axis=0)) / spec.dt_ctrl
        moving = tr.t[1:, None] <= tr.t_stop[None, :]
        th.extend(theta_hat.tolist())
        for s in np.unique(si):
            planned[int(s)] = float(t_plan[si == s][0])
            for c, name in enumerate(CONTROLLERS):
                m = (ci == c) & (si == s)
                e = err_cm[m]
                jm = np.where(moving[:, m], jerk[:, m], np.nan)
                stats[name, int(s)] = CellStats(
                    float(np.mean(np.abs(e))), float(np.mean(e)), float(np.var(e, ddof=1)),
                    float(np.max(np.abs(e))), float(np.nanmean(jm)), float(np.nanmax(jm)),
                    float(np.mean(tr.t_stop[m])),
                    float(np.nanmean(np.where(moving[:, m], crate[:, m], np.nan))),
                    tuple(float(x) for x in e))
                if int(s) == 0:
                    j = int(np.flatnonzero(m)[0])
                    one = TargetCurve.build(lengths[j:j + 1], v_max=spec.v_max.value,
                                            a_acc=spec.a_acc.value, a_dec=spec.a_dec.value)
                    xd, vd, _ = one.at(tr.t + tb[j])
                    example[name] = (tr.t, tr.x[:, j] - lengths[j], tr.v[:, j],
                                     xd - lengths[j], vd)
    return StopResult(spec.sections, tuple(planned[i] for i in range(len(spec.sections))),
                      stats, example, (float(np.min(th)), float(np.max(th))))


def within_rate(errors, tol: float, z: float = 1.959963984540054):
    """(k, n, k/n, lo, hi): stops with |error| <= ``tol`` and the Wilson score
    interval of that proportion (95 % for the default z). Wilson's interval
    stays inside [0, 1] and is sound at k = 0 or k = n, where the normal
    approximation collapses to a point."""
    import math
    e = [abs(x) for x in errors]
    n, k = len(e), sum(x <= tol for x in e)
    if n == 0:
        return 0, 0, math.nan, math.nan, math.nan
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return k, n, p, max(0.0, mid - half), min(1.0, mid + half)


class StationStopping:
    kind = "station-stopping"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader) -> StopSpec:
        return load_stop_spec(root)

    def quantity_names(self, spec: StopSpec) -> set[str]:
        names = {"order", "best"}
        for c in CONTROLLERS:
            names |= {f"{c}.mean_abs_cm", f"{c}.worst_section_mean_abs_cm",
                      f"{c}.worst_section_var_cm2",
                      f"{c}.best_section_mean_abs_cm", f"{c}.jerk_mean"}
            for i in range(len(spec.sections)):
                names |= {f"{c}.sections[{i + 1}].mean_abs_cm", f"{c}.sections[{i + 1}].var_cm2"}
        return names

    def run(self, design) -> StopResult:
        return run_station_stops(design.spec)

    def quantities(self, res: StopResult) -> dict:
        q = {}
        ns = len(res.sections)
        for c in CONTROLLERS:
            per = [res.stats[c, i].mean_abs for i in range(ns)]
            q[f"{c}.mean_abs_cm"] = res.overall(c)
            q[f"{c}.worst_section_mean_abs_cm"] = max(per)
            q[f"{c}.worst_section_var_cm2"] = max(res.stats[c, i].var for i in range(ns))
            q[f"{c}.best_section_mean_abs_cm"] = min(per)
            q[f"{c}.jerk_mean"] = float(np.mean([res.stats[c, i].jerk_mean for i in range(ns)]))
            for i in range(ns):
                q[f"{c}.sections[{i + 1}].mean_abs_cm"] = res.stats[c, i].mean_abs
                q[f"{c}.sections[{i + 1}].var_cm2"] = res.stats[c, i].var
        order = sorted(PAPER_CONTROLLERS, key=res.overall)
        q["order"] = "<".join(order)
        q["best"] = order[0]
        return q


STUDY = StationStopping()
