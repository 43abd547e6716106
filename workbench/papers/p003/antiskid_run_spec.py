"""Design spec of the ``antiskid-run`` study (the full runs of paper 003,
section 4) and what derives from it: the plant values, the controller
settings of each case, the cruise gain (:func:`gain_for`), the run of the
scenario (acceleration, cruise, braking with input delay). The study
itself is :mod:`workbench.papers.p003.antiskid_run`.

Design tables: ``[plant]`` (as ``antiskid-cruise``, plus ``mass_factor``
applied to the plant only: the controller keeps the nominal model),
``[scenario]``, ``[controller]`` (+ ``[controller.profile]``, eqs 76-78),
``[numerics]``, ``[[cases]]`` (named variants of controller 75),
``[linear_check]`` and, optionally, ``[montecarlo]``: the ranges of the
``workbench sweep`` robustness study plus ``samples``, ``seed``, ``workers``
and ``chunk`` of a reduced sample that the study runs (in a process pool,
while the cases run) and reports as ``montecarlo.*`` quantities;
``[basin]``, ``[comfort]`` and ``[sampled]`` (the case's laws as a
sampled-data controller, :mod:`workbench.papers.p003.antiskid_sampled`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ...controllers.antiskid003_settings import BRAKE_IN, ControllerSettings, CreepSpeedProfile
from ...errors import DesignError, ModelError
from ...features.gain_choice import GainChoice, chosen_gain, read_gain_choice
from ...features.linear_delay_check import LinearCheckSpec, load_linear_check
from ...features.spec_readers import (event_time, named_tables, read_range, read_step_tolerances,
                                      sourced_range)
from ...plants.adhesion import PARAMETER_UNITS, NumericAdhesion
from ...reader import Reader
from ...sim.wheel_slip import PARAM_ORDER
from ...symbolic.linearise import linearise_cruise
from .antiskid_scenario import Mesh, RunSettings

#: Metrics of a case (name -> unit), each checked for convergence under step halving.
METRICS = {"t_cruise": "s", "lam_max_traction": "1", "lam_max_over_opt": "1", "v_max": "m/s",
           "v_err_at_brake": "m/s", "lam_err_at_brake": "1", "braking_duration": "s",
           "omega3_after_brake": "s", "lam_min_brake": "1", "evs_max_tracking": "m/s",
           "evs_last": "m/s", "t_diverged": "s"}


@dataclass(frozen=True)
class Case:
    name: str
    description: str
    compensate: bool
    cruise_entry: str
    brake_entry: str
    predictor: str


@dataclass(frozen=True)
class RunSpec:
    rail: str
    params: dict
    mass_factor: float
    scenario: dict
    gain: str
    eps: float
    K_table: tuple
    K_source: str
    k_ac: float
    k_de: float
    profile: dict
    dt: float
    v_stop: float
    handover_band: float
    torque_range: float            # multiple of the peak adhesion torque (see controller_settings)
    mesh_courant: float            # refined mesh of the runs without predictor (see case_mesh)
    mesh_levels: int
    conv_rtol: float
    conv_atol: dict
    cases: tuple
    linear: LinearCheckSpec        # [linear_check]
    montecarlo: object = None      # antiskid_montecarlo.SweepSpec or None
    basin: object = None           # basin_points.GainSweepSettings or None ([basin] table)
    comfort: object = None         # features.comfort.ComfortLimits or None ([comfort] table)
    sampled: object = None         # antiskid_sampled.SampledSpec or None ([sampled] table)


@dataclass(frozen=True)
class SweepSpec:
    """The design's ``[montecarlo]`` table: ranges of the sweep and the run of
    the study (``samples`` runs with ``seed``, ``chunk`` samples per batch,
    ``workers`` processes)."""

    mass: tuple[float, float]
    wet: dict               # a, b, c of the wet curve
    adhesion: tuple[float, float]
    h: tuple[float, float]
    v0: tuple[float, float]
    case: str
    samples: int
    seed: int
    workers: int
    chunk: int | None = None
    halving: int = 0        # first runs re-checked at dt and dt / 2 (:func:`start_halving`)
    dt: float | None = None  # step of the sweep's runs (None: the design's [numerics] dt)
    perturb: SweepPerturbations | None = None   # noise, gradient, varying delay (opt-in)


@dataclass(frozen=True)
class SweepPerturbations:
    """The optional perturbations of ``[montecarlo]`` (issue 17, item 6; see
    :mod:`workbench.sim.perturb`): measurement noise (standard deviations),
    a gradient profile (slope range in per mille, segment length), a delay
    varying inside the ``h`` range (range of the triangle wave's period).
    Each ``None`` or 0 when its key is absent; ``sources``: key -> source."""

    noise_v: float = 0.0            # m/s
    noise_omega: float = 0.0        # rad/s
    gradient: tuple | None = None   # per mille, uphill positive
    segment: float = 1000.0         # m
    delay_period: tuple | None = None   # s
    sources: tuple = ()

    @property
    def noisy(self) -> bool:
        return self.noise_v > 0 or self.noise_omega > 0


def load_perturbations(mt: Reader) -> SweepPerturbations | None:
    """The ``noise_v``, ``noise_omega``, ``gradient`` and ``delay_variation``
    entries of a ``[montecarlo]`` table (None when none is given)."""
    if not any(mt.has(k) for k in ("noise_v", "noise_omega", "gradient", "delay_variation")):
        return None
    src, out = {}, {}
    for k, unit in (("noise_v", "m/s"), ("noise_omega", "rad/s")):
        if mt.has(k):
            q = mt.quantity(k, unit, nonneg=True, hi=10.0)
            out[k], src[k] = q.value, q.source
    if mt.has("gradient"):
        out["gradient"], src["gradient"], g = sourced_range(mt, "gradient", "range", "per mille",
                                                            lo=-100.0, hi=100.0)
        out["segment"] = g.number("segment", positive=True, what="number (m)")
        g.finish()
    if mt.has("delay_variation"):
        out["delay_period"], src["delay_variation"], d = sourced_range(
            mt, "delay_variation", "period", "s", positive=True)
        d.finish()
    return SweepPerturbations(**out, sources=tuple(src.items()))


def plant_values(spec: RunSpec, mass_factor: float = 1.0) -> dict:
    """Plant parameter values of the design (name -> float), mass scaled."""
    v = {k: q.value for k, q in spec.params.items()}
    v["m"] *= mass_factor
    return v


def nominal_cruise(spec: RunSpec):
    """(nominal plant, lambda_d, cruise linearisation) the controller is built on."""
    nominal = NumericAdhesion.from_dict(plant_values(spec))
    v_d = spec.scenario["v_d"]
    lam_d = nominal.cruise_lambda(v_d)
    return nominal, lam_d, linearise_cruise(nominal, v_d, lam_d)


def peak_adhesion_torque(spec: RunSpec) -> float:
    """mu(lambda_opt) m g r of the nominal model (N m): the most torque the
    rail transmits in steady state; ``torque_range`` counts in it."""
    nominal = nominal_cruise(spec)[0]
    vals = plant_values(spec)
    return float(nominal.mu(nominal.lambda_opt())) * vals["m"] * vals["g"] * vals["r"]


def controller_settings(spec: RunSpec, K, case: Case) -> ControllerSettings:
    """Controller (75) data for one case (plain data: picklable)."""
    nominal, lam_d, lin = nominal_cruise(spec)
    v_d = spec.scenario["v_d"]
    prof = CreepSpeedProfile(t_brake=spec.scenario["t_brake"], **spec.profile)
    lam_opt = nominal.lambda_opt()
    vals = plant_values(spec)
    u_peak = peak_adhesion_torque(spec)
    return ControllerSettings(
        params=tuple(vals[k] for k in PARAM_ORDER), v_d=v_d, lambda_d=lam_d,
        lambda_opt=lam_opt, K=tuple(K), lin=dict(lin.coefficients),
        k_ac=spec.k_ac, k_de=spec.k_de, h_model=spec.scenario["h"], profile=prof,
        compensate=case.compensate, predictor=case.predictor, cruise_entry=case.cruise_entry,
        brake_entry=case.brake_entry, handover_band=spec.handover_band, v_stop=spec.v_stop,
        u_range=spec.torque_range * u_peak)


def case_mesh(spec: RunSpec, case: Case) -> Mesh | None:
    """The refined mesh of a case's runs: for the cases without the
    predictor (``compensate = false``), whose loop at low speed is close to
    neutral (see :class:`~workbench.papers.p003.antiskid_scenario.Mesh`); None for
    the others, where the predictor's rollout and the plant share the
    fixed step's discretization (a refined mesh there costs h / step model
    steps per step and gave the same metrics: braking 86.29 s against
    86.25 s at dt / 2 on dry rail)."""
    if case.compensate or spec.mesh_levels == 0:
        return None
    return Mesh(spec.dt, spec.mesh_courant, spec.mesh_levels)


def run_settings(spec: RunSpec, cs: ControllerSettings) -> RunSettings:
    """The run of the design's scenario with controller ``cs`` on the (mass-scaled) plant."""
    sc = spec.scenario
    plant = tuple(plant_values(spec, spec.mass_factor)[k] for k in PARAM_ORDER)
    return RunSettings(plant, cs, sc["h"], (sc["v0"], sc["lambda0"]), sc["u_init"], sc["t_end"])


def sampled_context(spec: RunSpec, K):
    """The :class:`~workbench.papers.p003.antiskid_sampled_kernel.Context` of a
    design's ``[sampled]`` runs: its case's controller with gain ``K``, the
    (mass-scaled) plant, the scenario."""
    import numpy as np

    from .antiskid_sampled_kernel import Context
    case = next(c for c in spec.cases if c.name == spec.sampled.case)
    rs = run_settings(spec, controller_settings(spec, K, case))
    return Context(rs.controller, np.asarray(rs.plant_params, float), rs.h, rs.x0, rs.u_init,
                   spec.scenario["t_brake"], spec.scenario["t_end"], peak_adhesion_torque(spec),
                   spec.sampled.creep_margin)


def case_metrics(m, cs: ControllerSettings, t_brake: float) -> dict:
    """Plain floats (NaN: not reached) of the online metrics of one run."""
    f = lambda x: float(x)
    out = {"t_cruise": f(m.t_cruise), "lam_max_traction": f(m.lam_max_traction),
           "lam_max_over_opt": f(m.lam_max_traction) / cs.lambda_opt, "v_max": f(m.v_max),
           "v_err_at_brake": f(m.v_err_at_brake), "lam_err_at_brake": f(m.lam_err_at_brake),
           "braking_duration": f(m.t_stop) - t_brake,
           "omega3_after_brake": f(m.t_omega3) - t_brake,
           "lam_min_brake": f(m.lam_min_brake) if math.isfinite(m.lam_min_brake) else math.nan,
           "evs_max_tracking": f(m.evs_max_tracking), "evs_last": evs_floor(f(m.evs_last)),
           "t_diverged": f(m.t_diverged), "lam_at_cruise": f(m.lam_at_cruise),
           "v_at_cruise": f(m.v_at_cruise), "t_handover_done": f(m.t_handover_done),
           "phase_diverged": f(m.phase_diverged), "v_at_handover": f(m.v_at_handover),
           "lam_at_handover": f(m.lam_at_handover), "lam_at_brake": f(m.lam_at_brake),
           "t_lam_negative": f(m.t_lam_negative), "t_brake": t_brake,
           "diverged_how": f(m.diverged_how),
           "lock_onset_after_brake": f(m.t_past_peak) - t_brake}
    if not math.isnan(out["t_diverged"]):   # a diverged run has no final error
        out["evs_last"] = math.nan
        # the extremum of lambda over the phase a run diverged in is where the
        # divergence test fired, not a property of the run
        key = "lam_max_traction" if out["phase_diverged"] < BRAKE_IN else "lam_min_brake"
        out[key] = math.nan
        if key == "lam_max_traction":
            out["lam_max_over_opt"] = math.nan
    return out


#: Creep-speed error (m/s) below which the error at the stop is rounding noise.
EVS_FLOOR = 1e-12


def evs_floor(e: float) -> float:
    """The creep-speed error at the stop, 0 when below :data:`EVS_FLOOR`:
    there v_s* has stepped to 0 and e_vs is the creep speed v - omega r of a
    wheel that rolls, a difference of two speeds of about 1 m/s at rounding
    level (9.47e-17 m/s as designed, 9.48e-17 with the inputs moved 3 ulp),
    whose digits change with the last bit of the inputs (our choice: 1e-12
    m/s, 1e4 times eps at 1 m/s)."""
    return 0.0 if abs(e) < EVS_FLOOR else e


def gain_for(spec: RunSpec) -> tuple[tuple, str, float | None]:
    """(K, how it was obtained, h_certified or None): the design's table gain,
    or the certified synthesis of problem (60) at the design's eps on the
    nominal cruise linearisation (:func:`workbench.features.gain_choice.chosen_gain`),
    which depends on the nominal plant, v_d and eps only: it runs once per
    process and run folder (the sweep, the halving check and the cases of a
    design share it; the test session of ``make test`` reads what
    ``workbench check`` computed)."""
    return chosen_gain(GainChoice(spec.gain, spec.eps, spec.K_table, spec.K_source),
                       lambda: nominal_cruise(spec)[2], "antiskid-run-gain",
                       (spec.params, spec.scenario["v_d"], spec.eps),
                       f"synthesis, problem (60) at eps = {spec.eps:g}")


def load_run_spec(root: Reader) -> RunSpec:
    """Validate the tables of an ``antiskid-run`` design (module docstring)."""
    plant = root.table("plant")
    plant.string("model", choices=("adhesion-003",))
    rail = plant.string("rail", choices=("dry", "wet"))
    params = {k: plant.quantity(k, u, positive=True) for k, u in PARAMETER_UNITS.items()}
    mass_factor = plant.number("mass_factor", default=1.0, positive=True, lo=0.5, hi=1.5)
    plant.finish()
    sc = root.table("scenario")
    scen = {"v0": sc.quantity("v0", "m/s", positive=True).value,
            "lambda0": sc.quantity("lambda0", "1", lo=-0.5, hi=0.5).value,
            "u_init": sc.quantity("u_init", "N m").value,
            "h": sc.quantity("h", "s", nonneg=True, hi=1.0).value,
            "v_d": sc.quantity("v_d", "m/s", positive=True, hi=150.0).value,
            # t_brake = 300 s is a step time of dt, dt/2 and dt/4 (see event_time)
            "t_brake": event_time(sc.quantity("t_brake", "s", positive=True).value),
            "t_end": event_time(sc.quantity("t_end", "s", positive=True, hi=5000.0).value)}
    sc.finish()
    if not scen["t_end"] > scen["t_brake"]:
        raise DesignError(root.path, "scenario.t_end", scen["t_end"], "a time after t_brake")
    ct = root.table("controller")
    g = read_gain_choice(ct, 2)
    k_ac = ct.number("k_ac", positive=True)
    k_de = ct.number("k_de", positive=True)
    pr = ct.table("profile")
    profile = {"c0": pr.number("c0"), "c1": pr.number("c1", nonneg=True),
               "lambda_allow": pr.number("lambda_allow", positive=True, hi=1.0),
               "vs_min": pr.number("vs_min", hi=0.0),
               "omega_switch": pr.number("omega_switch", positive=True)}
    pr.string("source")
    pr.finish()
    ct.finish()
    nu = root.table("numerics")
    dt = nu.number("dt", positive=True, hi=0.05)
    v_stop = nu.number("v_stop", positive=True, hi=1.0)
    band = nu.number("handover_band", positive=True, hi=0.05)
    torque_range = nu.number("torque_range", lo=1.0, what="number (multiple of the peak "
                             "adhesion torque, >= 1)")
    mesh_courant = nu.number("mesh_courant", positive=True, hi=100.0)
    mesh_levels = nu.number("mesh_levels", integer=True, lo=0, hi=8,
                            what="integer (halvings of dt, 0 = no refinement)")
    rtol, atol = read_step_tolerances(nu, METRICS)
    nu.finish()
    if scen["h"] < dt and scen["h"] > 0:
        raise DesignError(root.path, "numerics.dt", dt, f"a step no larger than h = {scen['h']}")
    cases = []
    for cr, name in named_tables(root, "cases"):
        cases.append(Case(name, cr.string("description"),
                          cr.boolean("compensate"),
                          cr.string("cruise_entry", choices=("speed", "creep")),
                          cr.string("brake_entry", choices=("time", "creep")),
                          cr.string("predictor", default="rollout",
                                    choices=("rollout", "recursive"))))
        cr.finish()
    names = [c.name for c in cases]
    linear = load_linear_check(root)
    mc = None
    if root.has("montecarlo"):
        mt = root.table("montecarlo")
        rng = lambda k, **kw: read_range(mt, k, **kw)
        wet = {k: mt.quantity(f"wet_{k}", "1", positive=True).value for k in ("a", "b", "c")}
        count = lambda k, **kw: mt.number(k, integer=True, what="integer", **kw)
        mc = SweepSpec(rng("mass_factor", positive=True), wet,
                       rng("adhesion", lo=0.0, hi=1.0), rng("h", lo=0.0, hi=1.0),
                       rng("v0", positive=True),
                       mt.string("case", choices=[c.name for c in cases]),
                       count("samples", lo=1, hi=10**5), count("seed", nonneg=True),
                       count("workers", lo=1, hi=256),
                       count("chunk", default=None, lo=1, hi=10**5),
                       count("halving_samples", default=0, lo=0, hi=10**5),
                       mt.number("dt", default=None, positive=True, hi=0.05),
                       load_perturbations(mt))
        if mc.halving > mc.samples:
            raise mt.fail("halving_samples", mc.halving,
                          f"at most samples = {mc.samples} (the check re-runs the first runs)")
        mt.finish()
    from .antiskid_basin_run import load_basin_settings
    from ...features.comfort import load_comfort
    from .antiskid_sampled import load_sampled
    vals = {k: q.value for k, q in params.items()}
    try:
        NumericAdhesion.from_dict(vals).cruise_lambda(scen["v_d"])
    except ModelError as exc:
        raise DesignError(root.path, "scenario.v_d", scen["v_d"],
                          f"a speed with a creep-region equilibrium ({exc})") from None
    return RunSpec(rail, params, mass_factor, scen, g.gain, g.eps, g.K_table, g.K_source, k_ac, k_de,
                   profile, dt, v_stop, band, torque_range, mesh_courant, mesh_levels, rtol, atol,
                   tuple(cases), linear, mc, load_basin_settings(root), load_comfort(root),
                   load_sampled(root, names))
