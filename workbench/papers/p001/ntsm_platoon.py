"""Study ``ntsm-platoon``: paper 001's virtual-coupling platoon under the NTSM law
(eq 13), against a constant-spacing PD and a PD with acceleration feed-forward.

The design is read by :mod:`.ntsm_platoon_spec`. Four runs in the paper's
(ideal) set-up — NTSM from exact spacing, NTSM from the initial errors
(reaching and sliding times against eq 22), PD, PD + feed-forward — and the
realistic scenario of :mod:`.ntsm_platoon_realism` (V2V link, actuator lag and
limits, the leader's emergency brake, the exact delay margin).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...controllers.ntsm import (convergence_time, linear_member, ntsm_force, pd_ff_force, pd_force,
                                 surface)
from ...features.reproducible import window as window_mask
from ...plants.platoon001 import TrainParams, external_force, perturbed
from ...profiles import Profile, build_profile, spec_for_cruise
from ...reader import Reader
from ...sim.platoon import PlatoonRun, simulate_platoon
from .ntsm_platoon_realism import (Realism, accel_end, realism_quantities, realism_quantity_names,
                                   run_realism)
from .ntsm_platoon_spec import PlatoonSpec, load_spec

#: The followers' laws of :meth:`Scenario.law`.
LAWS = ("ntsm", "pd", "pd_ff", "linear")


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
    realism: Realism


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
        """The followers' law ``law(e, de, u1, a_pred) -> (u, s)``, one of :data:`LAWS`:
        eq 13, the PD, the PD + acceleration feed-forward, the NTSM's linear member."""
        spec, m = self.spec, self.nominal.m
        g, bound = spec.gains, spec.G_w + spec.G_d
        k_e, k_d = linear_member(g)

        def ntsm(e, de, u1, a_pred):
            s = surface(e, de, g)
            return ntsm_force(e, de, s, u1, m, a_pred, bound, g), s

        def pd(e, de, u1, a_pred):
            return pd_force(e, de, u1, m, spec.kp, spec.kd), np.zeros_like(e)

        def pd_ff(e, de, u1, a_pred):
            return pd_ff_force(e, de, u1, m, a_pred, spec.kp_ff, spec.kd_ff), np.zeros_like(e)

        def linear(e, de, u1, a_pred):
            return pd_ff_force(e, de, u1, m, a_pred, k_e, k_d), np.zeros_like(e)

        return {"ntsm": ntsm, "pd": pd, "pd_ff": pd_ff, "linear": linear}[name]

    def common(self) -> dict:
        spec = self.spec
        return dict(n=spec.n, spacing=spec.D.value, T=spec.T, horizon=spec.horizon, w=self.w,
                    leader_gain=spec.leader_gain, route=spec.route)

    def simulate(self, law: str, initial_errors=None, *, horizon: float | None = None,
                 **realism) -> PlatoonRun:
        """One run of the law ``law``; ``realism``: ``link``, ``actuator``,
        ``leader_brake`` of :func:`~workbench.sim.platoon.simulate_platoon`."""
        common = self.common()
        if horizon is not None:
            common["horizon"] = horizon
        return simulate_platoon(self.nominal, self.true, self.law(law), self.leader_ref,
                                **common, initial_errors=initial_errors, **realism)


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


class NTSMPlatoon:
    kind = "ntsm-platoon"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader) -> PlatoonSpec:
        return load_spec(root)

    def quantity_names(self, spec: PlatoonSpec) -> set[str]:
        names = set()
        for r in ("ntsm", "ntsm_offset", "pd", "pd_ff"):
            names |= {f"{r}.{k}" for k in ("max_abs_e", "cruise_abs_e", "cruise_abs_de",
                                            "chatter", "sign_rate", "lumped_ratio",
                                            "string_ratio", "max_speed")}
        names |= {"pd_over_ntsm.max_abs_e", "pd_ff_over_ntsm.max_abs_e",
                  "pd_over_pd_ff.max_abs_e", "convergence.max_reaching_time",
                  "convergence.max_rel_error_band", "convergence.max_ratio_eq22",
                  "leader.v_cruise"}
        for i in range(2, spec.n + 1):
            names |= {f"convergence.train{i}.{k}" for k in
                      ("t_reach", "e_reach", "slide_eq22", "slide_band", "slide_measured")}
        return names | realism_quantity_names()

    # -- run -------------------------------------------------------------------
    def run(self, design) -> PlatoonResult:
        spec: PlatoonSpec = design.spec
        sc = scenario(spec)
        runs = {"ntsm": sc.simulate("ntsm"),
                "ntsm_offset": sc.simulate("ntsm", np.array(spec.initial_errors)),
                "pd": sc.simulate("pd"), "pd_ff": sc.simulate("pd_ff")}
        prof = sc.profile
        bound = spec.G_w + spec.G_d
        nom = sc.nominal
        t_acc_end = accel_end(prof)
        t_brk = float(prof.t[np.nonzero(prof.a < 0)[0][0]])
        window = (t_acc_end + 10.0, t_brk)     # settled cruise
        metrics = {k: _metrics(r, window, nom.m, bound) for k, r in runs.items()}
        conv = tuple(_convergence(runs["ntsm_offset"], i, e0, spec)
                     for i, e0 in enumerate(spec.initial_errors))
        return PlatoonResult(prof, window, runs, metrics, conv,
                             run_realism(sc))

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
        q["pd_ff_over_ntsm.max_abs_e"] = q["pd_ff.max_abs_e"] / q["ntsm.max_abs_e"]
        q["pd_over_pd_ff.max_abs_e"] = q["pd.max_abs_e"] / q["pd_ff.max_abs_e"]
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
        q.update(realism_quantities(res.realism))
        return q


def _metrics(r: PlatoonRun, window, m: float, bound: float) -> RunMetrics:
    cw = window_mask(r.t, *window)         # ends on sample times: half a step to spare
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
