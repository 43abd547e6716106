"""Study ``ntsm-platoon``: paper 001's virtual-coupling platoon under the NTSM law
(eq 13), with a constant-spacing PD baseline.

Design tables read here: ``[plant]`` (nominal train, Table 1), ``[uncertainty]``
(seeded parameter spread and external force, bounds G_w, G_d of eq 6),
``[leader]`` (accelerate - cruise - brake), ``[platoon]`` (n, D, T, horizon),
``[route]`` (gradients), ``[ntsm]`` (eqs 10-13 parameters), ``[pd]`` and
``[convergence]`` (initial spacing errors for the eq 22 check and the bands
that define "reached" and "converged").

Three runs: NTSM from exact spacing (the paper's set-up), NTSM from the
initial errors (reaching and sliding times against eq 22), PD from exact
spacing.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..controllers.ntsm import NTSMGains, convergence_time, ntsm_force, pd_force, surface
from ..plants.platoon001 import PARAMETER_UNITS, TrainParams, external_force, perturbed
from ..profiles import Profile, build_profile, spec_for_cruise
from ..reader import Quantity, Reader
from ..sim.platoon import PlatoonRun, simulate_platoon
from ..sim.tracking import Route
from .tracking002 import read_gradients


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

    def nominal(self) -> TrainParams:
        p = {k: q.value for k, q in self.plant.items()}
        return TrainParams(p["m"], p["c0"], p["c1"], p["c2"], p["g"])


@dataclass(frozen=True)
class Convergence:
    """Reaching and sliding of one follower started off its spacing.

    Attributes
    ----------
    e0 : float
        Initial spacing error (m).
    t_reach : float or None
        First time |s| <= reach band (s).
    e_reach : float or None
        e(t_reach) (m).
    slide_eq22 : float or None
        Eq 22: t_f - t_e to e = 0 (s).
    slide_band : float or None
        The same law integrated to the converge band (s).
    slide_measured : float or None
        Measured time from t_reach until |e| stays within the band (s).
    """

    e0: float
    t_reach: float | None
    e_reach: float | None
    slide_eq22: float | None
    slide_band: float | None
    slide_measured: float | None


@dataclass(frozen=True)
class RunMetrics:
    """Summary of one platoon run (followers only unless said otherwise)."""

    max_abs_e: tuple[float, ...]         # per follower, whole run (m)
    cruise_abs_e: tuple[float, ...]      # per follower, settled cruise window (m)
    cruise_abs_de: tuple[float, ...]     # (m/s)
    chatter: tuple[float, ...]           # (1/t) sum |du|/m (m/s^3)
    sign_rate: tuple[float, ...]         # sign changes of s per second in cruise (Hz)
    lumped_ratio: float                  # max |w + d| / (G_w + G_d) while moving
    lumped_peak_time: float              # when that maximum occurs (s)
    max_speed: tuple[float, ...]         # all trains (m/s)

    @property
    def string_ratio(self) -> float:
        """max_i ||e_{i+1}||_inf / ||e_i||_inf over the followers."""
        e = self.max_abs_e
        return max(e[i + 1] / e[i] for i in range(len(e) - 1))


@dataclass(frozen=True)
class PlatoonResult:
    profile: Profile
    cruise_window: tuple[float, float]
    runs: dict                        # name -> PlatoonRun
    metrics: dict                     # name -> RunMetrics
    convergence: tuple[Convergence, ...]


@dataclass(frozen=True)
class Scenario:
    """Everything a platoon run needs besides the law: seeded true trains and
    external force, the leader's profile."""

    spec: PlatoonSpec
    nominal: TrainParams
    true: TrainParams
    w: np.ndarray
    profile: Profile

    def leader_ref(self, t):
        """Leader's target speed (m/s) and acceleration (m/s^2) at times ``t``."""
        p = self.profile
        return np.interp(t, p.t, p.v, right=0.0), np.interp(t, p.t, p.a, right=0.0)

    def law(self, name: str):
        """The followers' law ``law(e, de, u1, a_pred) -> (u, s)``: "ntsm" or "pd"."""
        spec, m = self.spec, self.nominal.m
        g, bound = spec.gains, spec.G_w + spec.G_d

        def ntsm(e, de, u1, a_pred):
            s = surface(e, de, g)
            return ntsm_force(e, de, s, u1, m, a_pred, bound, g), s

        def pd(e, de, u1, a_pred):
            return pd_force(e, de, u1, m, spec.kp, spec.kd), np.zeros_like(e)

        return {"ntsm": ntsm, "pd": pd}[name]

    def common(self) -> dict:
        spec = self.spec
        return dict(n=spec.n, spacing=spec.D.value, T=spec.T, horizon=spec.horizon, w=self.w,
                    leader_gain=spec.leader_gain, route=spec.route)

    def simulate(self, law: str, initial_errors=None) -> PlatoonRun:
        return simulate_platoon(self.nominal, self.true, self.law(law), self.leader_ref,
                                **self.common(), initial_errors=initial_errors)


def scenario(spec: PlatoonSpec) -> Scenario:
    """Draw the seeded true trains and external force; build the leader's profile."""
    nom = spec.nominal()
    rng = np.random.default_rng(np.random.SeedSequence(spec.seed))
    true = perturbed(nom, spec.n, rng, mass_spread=spec.mass_spread,
                     davis_spread=spec.davis_spread)
    w = external_force(spec.n, int(round(spec.horizon / spec.T)), spec.T, spec.G_w, spec.hold,
                       rng)
    prof = build_profile(spec_for_cruise(spec.v_cruise.value, spec.cruise_time, spec.accel,
                                         spec.brake, spec.jerk), dt=spec.T)
    return Scenario(spec, nom, true, w, prof)


def _odd(r: Reader, name: str) -> int:
    return int(r.number(name, integer=True, positive=True, what="positive odd integer"))


class NTSMPlatoon:
    kind = "ntsm-platoon"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader) -> PlatoonSpec:
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
        pd = root.table("pd")
        kp, kd = pd.number("kp", positive=True), pd.number("kd", positive=True)
        pd.finish()
        cv = root.table("convergence")
        e0 = cv.numbers("initial_errors", what="spacing errors (m)")
        if len(e0) != n - 1 or min(e0) < 0:
            raise cv.fail("initial_errors", list(e0), f"{n - 1} non-negative errors (m), one per "
                          "follower (a follower too close would have to reverse)")
        rb = cv.quantity("reach_band", "m", positive=True).value
        cb = cv.quantity("converge_band", "m", positive=True).value
        cv.finish()
        spec = PlatoonSpec(plant, ms, ds, G_w, G_d, hold, seed, vc, ct, acc, brk, jerk, lg, n, D,
                           T, horizon, Route(1e9, g_from, grade), gains, kp, kd, e0, rb, cb)
        if spec_for_cruise(vc.value, ct, acc, brk, jerk).run_time > horizon:
            raise pt.fail("horizon", horizon, "a horizon longer than the leader's run")
        return spec

    def quantity_names(self, spec: PlatoonSpec) -> set[str]:
        names = set()
        for r in ("ntsm", "ntsm_offset", "pd"):
            names |= {f"{r}.{k}" for k in ("max_abs_e", "cruise_abs_e", "cruise_abs_de",
                                            "chatter", "sign_rate", "lumped_ratio",
                                            "string_ratio", "max_speed")}
        names |= {"pd_over_ntsm.max_abs_e", "convergence.max_reaching_time",
                  "convergence.max_rel_error_band", "convergence.max_ratio_eq22",
                  "leader.v_cruise"}
        for i in range(2, spec.n + 1):
            names |= {f"convergence.train{i}.{k}" for k in
                      ("t_reach", "e_reach", "slide_eq22", "slide_band", "slide_measured")}
        return names

    # -- run -------------------------------------------------------------------
    def run(self, design) -> PlatoonResult:
        spec: PlatoonSpec = design.spec
        sc = scenario(spec)
        runs = {"ntsm": sc.simulate("ntsm"),
                "ntsm_offset": sc.simulate("ntsm", np.array(spec.initial_errors)),
                "pd": sc.simulate("pd")}
        prof = sc.profile
        bound = spec.G_w + spec.G_d
        nom = sc.nominal
        t_acc_end = float(prof.t[np.nonzero(prof.a > 0)[0][-1]])
        t_brk = float(prof.t[np.nonzero(prof.a < 0)[0][0]])
        window = (t_acc_end + 10.0, t_brk)     # settled cruise
        metrics = {k: _metrics(r, window, nom.m, bound) for k, r in runs.items()}
        conv = tuple(_convergence(runs["ntsm_offset"], i, e0, spec)
                     for i, e0 in enumerate(spec.initial_errors))
        return PlatoonResult(prof, window, runs, metrics, conv)

    def quantities(self, res: PlatoonResult) -> dict:
        q = {"leader.v_cruise": res.profile.v_cruise}
        for name, m in res.metrics.items():
            q[f"{name}.max_abs_e"] = max(m.max_abs_e)
            q[f"{name}.cruise_abs_e"] = max(m.cruise_abs_e)
            q[f"{name}.cruise_abs_de"] = max(m.cruise_abs_de)
            q[f"{name}.chatter"] = max(m.chatter)
            q[f"{name}.sign_rate"] = max(m.sign_rate)
            q[f"{name}.lumped_ratio"] = m.lumped_ratio
            q[f"{name}.string_ratio"] = m.string_ratio
            q[f"{name}.max_speed"] = max(m.max_speed)
        q["pd_over_ntsm.max_abs_e"] = q["pd.max_abs_e"] / q["ntsm.max_abs_e"]
        for i, c in enumerate(res.convergence):
            for k in ("t_reach", "e_reach", "slide_eq22", "slide_band", "slide_measured"):
                q[f"convergence.train{i + 2}.{k}"] = getattr(c, k)
        done = [c for c in res.convergence if c.slide_measured is not None]
        ok = len(done) == len(res.convergence) and bool(done)
        q["convergence.max_reaching_time"] = max(c.t_reach for c in done) if ok else None
        q["convergence.max_rel_error_band"] = max(
            abs(c.slide_measured / c.slide_band - 1.0) for c in done) if ok else None
        q["convergence.max_ratio_eq22"] = max(
            c.slide_measured / c.slide_eq22 for c in done) if ok else None
        return q


def _metrics(r: PlatoonRun, window, m: float, bound: float) -> RunMetrics:
    cw = (r.t >= window[0]) & (r.t <= window[1])
    du = np.abs(np.diff(r.u[:, 1:], axis=0)) / m
    span = r.t[-1] - r.t[0]
    sgn = np.sign(r.s[cw])
    flips = (np.abs(np.diff(sgn, axis=0)) > 0).sum(axis=0) / (window[1] - window[0])
    lumped = np.abs(r.lumped) * (r.v > 0.1)          # while moving
    k_peak = np.unravel_index(np.argmax(lumped), lumped.shape)[0]
    return RunMetrics(tuple(np.abs(r.e).max(axis=0)), tuple(np.abs(r.e[cw]).max(axis=0)),
                      tuple(np.abs(r.de[cw]).max(axis=0)), tuple(du.sum(axis=0) / span),
                      tuple(flips),
                      float(lumped.max() / bound), float(r.t[k_peak]),
                      tuple(r.v.max(axis=0)))


def _first(mask: np.ndarray) -> int | None:
    idx = np.nonzero(mask)[0]
    return int(idx[0]) if idx.size else None


def _convergence(r: PlatoonRun, i: int, e0: float, spec: PlatoonSpec) -> Convergence:
    k_reach = _first(np.abs(r.s[:, i]) <= spec.reach_band)
    if k_reach is None:
        return Convergence(e0, None, None, None, None, None)
    e_r = float(r.e[k_reach, i])
    outside = np.nonzero(np.abs(r.e[k_reach:, i]) > spec.converge_band)[0]
    k_in = k_reach + (int(outside[-1]) + 1 if outside.size else 0)
    measured = None if k_in >= len(r.t) else float(r.t[k_in] - r.t[k_reach])
    band = float(convergence_time(e_r, spec.gains, min(abs(e_r), spec.converge_band)))
    return Convergence(e0, float(r.t[k_reach]), e_r, float(convergence_time(e_r, spec.gains)),
                       band, measured)


STUDY = NTSMPlatoon()
