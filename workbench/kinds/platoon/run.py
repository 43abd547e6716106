"""Compute a ``platoon`` design: every ``[[runs]]`` entry in the paper's
(ideal) set-up, their metrics, the reaching check of ``[reaching]``, and the
realistic scenario of :mod:`.realism` (V2V link, actuator lag and limits, the
leader's emergency brake, the exact delay margin).

The laws are the design's expressions (:mod:`.laws`), compiled once per
scenario; the trains are stepped by :func:`workbench.sim.platoon.simulate_platoon`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...features.reproducible import window as window_mask
from ...plants.platoon001 import TrainParams, external_force, perturbed
from ...profiles import Profile, build_profile, spec_for_cruise
from ...sim.platoon import PlatoonRun, simulate_platoon
from .laws import compile_expression, compile_law
from .realism import Realism, accel_end, run_realism
from .spec import PlatoonSpec

__all__ = ["Convergence", "PlatoonResult", "RunMetrics", "Scenario", "run", "scenario"]


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
        ``[reaching] sliding_time`` from e(t_reach) to e = 0 (s) (the name is
        paper 001's eq 22, kept for its claims' quantity names).
    slide_band : float or None
        The same to the converge band (s).
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
    spec: PlatoonSpec = field(repr=False, default=None)
    analysis: object = None            # the [analysis] module's result


@dataclass(frozen=True)
class Scenario:
    """Everything a platoon run needs besides the law: seeded true trains and
    external force, the leader's profile."""

    spec: PlatoonSpec
    nominal: TrainParams
    true: TrainParams
    w: np.ndarray
    profile: Profile
    compiled: dict = field(default_factory=dict, compare=False, repr=False)

    def leader_ref(self, t):
        """Leader's target speed (m/s) and acceleration (m/s^2) at times ``t``."""
        p = self.profile
        return np.interp(t, p.t, p.v, right=0.0), np.interp(t, p.t, p.a, right=0.0)

    def law(self, name: str):
        """The followers' law ``law(e, de, u1, a_pred) -> (u, s)`` named ``name``
        in ``[[laws]]`` (compiled once)."""
        if name not in self.compiled:
            spec = self.spec
            i = next(k for k, x in enumerate(spec.laws) if x.name == name)
            self.compiled[name] = compile_law(
                spec.laws[i], spec.constants, {"m": self.nominal.m, "G_w": spec.G_w,
                                               "G_d": spec.G_d}, path=spec.path, index=i)
        return self.compiled[name]

    def common(self) -> dict:
        spec = self.spec
        out = dict(n=spec.n, spacing=spec.D.value, T=spec.T, horizon=spec.horizon, w=self.w,
                   leader_gain=spec.leader_gain, route=spec.route)
        if spec.headway:
            out["headway"] = spec.headway
        return out

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


def run(spec: PlatoonSpec) -> PlatoonResult:
    """Every run of the design, its metrics, the reaching check, the realistic
    scenario and the ``[analysis]`` module's part."""
    sc = scenario(spec)
    runs = {r.name: sc.simulate(r.law, None if r.initial_errors is None
                                else np.array(r.initial_errors)) for r in spec.runs}
    prof = sc.profile
    bound = spec.G_w + spec.G_d
    nom = sc.nominal
    t_acc_end = accel_end(prof)
    t_brk = float(prof.t[np.nonzero(prof.a < 0)[0][0]])
    window = (t_acc_end + 10.0, t_brk)     # settled cruise
    metrics = {k: _metrics(r, window, nom.m, bound) for k, r in runs.items()}
    conv = ()
    if spec.reaching is not None:
        rc = spec.reaching
        slide = compile_expression(rc.sliding_time, {k: q.value for k, q in spec.constants.items()}
                                   | {"e_r": lambda s: s["e_r"], "e_end": lambda s: s["e_end"]},
                                   path=spec.path, key="reaching.sliding_time")
        conv = tuple(_convergence(runs[rc.run], i, e0, rc, slide)
                     for i, e0 in enumerate(spec.run_spec(rc.run).initial_errors))
    res = PlatoonResult(prof, window, runs, metrics, conv, run_realism(sc), spec)
    if getattr(spec.analysis, "run", None) is not None:     # an analysis that computes
        from dataclasses import replace
        res = replace(res, analysis=spec.analysis.run(spec, res))
    return res


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


def _convergence(r: PlatoonRun, i: int, e0: float, rc, slide) -> Convergence:
    k_reach = _first(np.abs(r.s[:, i]) <= rc.reach_band)
    if k_reach is None:
        return Convergence(e0, None, None, None, None, None)
    e_r = float(r.e[k_reach, i])
    outside = np.nonzero(np.abs(r.e[k_reach:, i]) > rc.converge_band)[0]
    k_in = k_reach + (int(outside[-1]) + 1 if outside.size else 0)
    measured = None if k_in >= len(r.t) else float(r.t[k_in] - r.t[k_reach])
    band = float(slide({"e_r": e_r, "e_end": min(abs(e_r), rc.converge_band)}))
    return Convergence(e0, float(r.t[k_reach]), e_r, float(slide({"e_r": e_r, "e_end": 0.0})),
                       band, measured)
