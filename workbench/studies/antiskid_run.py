"""Study ``antiskid-run``: the full runs of paper 003, section 4, in the time
domain (acceleration, cruise, braking with input delay), with the cruise
gain from the certified synthesis, a step-halving convergence check of every
reported metric, checks of the state at every phase switch, and linear
cross-checks of the LMI delay bound.

Design tables: ``[plant]`` (as ``antiskid-cruise``, plus ``mass_factor``
applied to the plant only: the controller keeps the nominal model),
``[scenario]``, ``[controller]`` (+ ``[controller.profile]``, eqs 76-78),
``[numerics]``, ``[[cases]]`` (named variants of controller 75),
``[linear_check]`` and, optionally, ``[montecarlo]``: the ranges of the
``workbench sweep`` robustness study plus ``samples``, ``seed``, ``workers``
and ``chunk`` of a reduced sample that the study runs (in a process pool,
while the cases run) and reports as ``montecarlo.*`` quantities.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..controllers.antiskid003 import (BRAKE_IN, PARAM_ORDER, ControllerSettings, Mesh, CreepSpeedProfile,
                                       RunSettings, model_functions, simulate_antiskid)
from ..design import Reader
from ..errors import DesignError, ModelError
from ..margins import DelayMargin, delay_margin_eig
from ..plants.adhesion import PARAMETER_UNITS, NumericAdhesion
from ..sim.delay import SimResult, envelope_ratio, simulate_linear_dde, step_halving
from ..symbolic.linearise import linearise_cruise

#: Metrics of a case, each checked for convergence under step halving.
METRICS = ("t_cruise", "lam_max_traction", "lam_max_over_opt", "v_max", "v_err_at_brake",
           "lam_err_at_brake", "braking_duration", "omega3_after_brake", "lam_min_brake",
           "evs_max_tracking", "evs_last", "t_diverged")


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
    finite_gain: tuple
    factors: tuple
    far_delays: tuple
    periods: float
    montecarlo: object = None      # workbench.sim.montecarlo.SweepSpec or None


@dataclass(frozen=True)
class SwitchCheck:
    """Frozen linearisation of the cruise loop at the state where cruise starts.

    ``abscissa``: spectral abscissa of A_loc + A_d (delay-free);
    ``margin``: exact delay margin of x' = A_loc x + A_d x(t - h).
    """

    v: float
    lam: float
    dmu_dlam: float
    A_loc: np.ndarray
    abscissa: float
    margin: DelayMargin


@dataclass(frozen=True)
class CaseResult:
    case: Case
    metrics: dict            # at dt / 2 (reported)
    metrics_coarse: dict     # at dt
    converged: dict          # metric -> bool
    run: SimResult           # recorded at dt / 2
    switch: SwitchCheck | None


@dataclass(frozen=True)
class LinearCheck:
    A: np.ndarray
    B: np.ndarray
    K_paper: tuple
    K_finite: tuple
    finite_margin: DelayMargin
    ratios_finite: tuple      # (factor, h, envelope ratio)
    paper_margin: DelayMargin
    ratios_paper: tuple       # (h, envelope ratio)
    runs: tuple               # SimResult per finite factor (for the figure)
    halving: tuple = ()       # HalvingRow of x' = -x(t - 0.7) against the exact solution


@dataclass(frozen=True)
class RunResult:
    lambda_opt: float
    lambda_d: float
    K: tuple
    K_how: str
    h_certified: float | None
    cases: tuple
    linear: LinearCheck
    dt: float
    montecarlo: object = None   # workbench.sim.montecarlo.SweepResult or None
    halving: object = None      # workbench.sim.montecarlo.HalvingCheck or None

    def case(self, name: str) -> CaseResult:
        return next(c for c in self.cases if c.case.name == name)

    def to_json(self) -> dict:
        return {"lambda_opt": self.lambda_opt, "lambda_d": self.lambda_d, "K": list(self.K),
                "cases": {c.case.name: c.metrics for c in self.cases}}


def _plant_values(spec: RunSpec, mass_factor: float = 1.0) -> dict:
    v = {k: q.value for k, q in spec.params.items()}
    v["m"] *= mass_factor
    return v


def _nominal_cruise(spec: RunSpec):
    """(nominal plant, lambda_d, cruise linearisation) the controller is built on."""
    nominal = NumericAdhesion.from_dict(_plant_values(spec))
    v_d = spec.scenario["v_d"]
    lam_d = nominal.cruise_lambda(v_d)
    return nominal, lam_d, linearise_cruise(nominal, v_d, lam_d)


def controller_settings(spec: RunSpec, K, case: Case) -> ControllerSettings:
    """Controller (75) data for one case (plain data: picklable)."""
    nominal, lam_d, lin = _nominal_cruise(spec)
    v_d = spec.scenario["v_d"]
    prof = CreepSpeedProfile(t_brake=spec.scenario["t_brake"], **spec.profile)
    lam_opt = nominal.lambda_opt()
    vals = _plant_values(spec)
    u_peak = float(nominal.mu(lam_opt)) * vals["m"] * vals["g"] * vals["r"]
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
    neutral (see :class:`~workbench.controllers.antiskid003.Mesh`); None for
    the others, where the predictor's rollout and the plant share the
    fixed step's discretization (a refined mesh there costs h / step model
    steps per step and gave the same metrics: braking 86.29 s against
    86.25 s at dt / 2 on dry rail)."""
    if case.compensate or spec.mesh_levels == 0:
        return None
    return Mesh(spec.dt, spec.mesh_courant, spec.mesh_levels)


def run_settings(spec: RunSpec, cs: ControllerSettings) -> RunSettings:
    sc = spec.scenario
    plant = tuple(_plant_values(spec, spec.mass_factor)[k] for k in PARAM_ORDER)
    return RunSettings(plant, cs, sc["h"], (sc["v0"], sc["lambda0"]), sc["u_init"], sc["t_end"])


def case_metrics(m, cs: ControllerSettings, t_brake: float) -> dict:
    """Plain floats (NaN: not reached) of the online metrics of one run."""
    f = lambda x: float(x)
    out = {"t_cruise": f(m.t_cruise), "lam_max_traction": f(m.lam_max_traction),
           "lam_max_over_opt": f(m.lam_max_traction) / cs.lambda_opt, "v_max": f(m.v_max),
           "v_err_at_brake": f(m.v_err_at_brake), "lam_err_at_brake": f(m.lam_err_at_brake),
           "braking_duration": f(m.t_stop) - t_brake,
           "omega3_after_brake": f(m.t_omega3) - t_brake,
           "lam_min_brake": f(m.lam_min_brake) if math.isfinite(m.lam_min_brake) else math.nan,
           "evs_max_tracking": f(m.evs_max_tracking), "evs_last": f(m.evs_last),
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


def _agree(a: float, b: float, rtol: float, atol: float) -> bool:
    if math.isnan(a) and math.isnan(b):
        return True
    return abs(a - b) <= atol + rtol * max(abs(a), abs(b))


def switch_check(cs: ControllerSettings, v: float, lam: float) -> SwitchCheck:
    """Frozen linearisation of the cruise loop (eq 61 on the traction form)
    at (v, lambda), by central differences of the lambdified model."""
    fn = model_functions("math")["traction"]
    p, c = cs.params, cs.lin

    def rhs(x):
        vv, ll = x
        y1, y2, y3, *_ = fn(vv, ll, *p)
        den = c["d4"] * (vv - cs.v_d) + c["d5"] * (ll - cs.lambda_d) + c["d6"]
        return np.array([y1, y2 - y3 / den * c["d3"]]), y3 / den

    x0 = np.array([v, lam])
    A = np.zeros((2, 2))
    for j, step in enumerate((1e-4 * max(v, 1.0), 1e-7)):
        e = np.zeros(2)
        e[j] = step
        A[:, j] = (rhs(x0 + e)[0] - rhs(x0 - e)[0]) / (2 * step)
    gain = rhs(x0)[1]
    Ad = gain * np.array([[0.0], [1.0]]) @ np.array([cs.K])
    mdl_dmu = _dmu(cs.params)
    return SwitchCheck(v, lam, float(mdl_dmu(lam)), A,
                       float(np.max(np.linalg.eigvals(A + Ad).real)), delay_margin_eig(A, Ad))


def _dmu(params):
    import sympy as sp
    from ..plants.adhesion import adhesion_model
    mdl = adhesion_model()
    vals = dict(zip(PARAM_ORDER, params))
    return sp.lambdify(mdl.lam, mdl.substitute(sp.diff(mdl.mu_traction, mdl.lam), vals), "math")


def linear_check(spec: RunSpec, A, B, K) -> LinearCheck:
    """E' = A E + B K E(t - h) simulated (Heun, :func:`simulate_linear_dde`)."""
    E0 = np.array([1.0, 0.01])
    Kf = np.array([spec.finite_gain])
    fin = delay_margin_eig(A, B @ Kf)
    ratios_f, runs = [], []
    if math.isfinite(fin.h) and fin.h > 0:
        period = 2 * math.pi / fin.omega
        for fac in spec.factors:
            h = fac * fin.h
            r = simulate_linear_dde(A, B @ Kf, h, E0, spec.periods * period,
                                    min(period, h) / 50)
            ratios_f.append((fac, h, envelope_ratio(r, period)))
            runs.append(r)
    Kp = np.array([K])
    pm = delay_margin_eig(A, B @ Kp)
    ratios_p = []
    rate = max(abs(np.linalg.eigvals(A)).max(), 1.0)
    slow = abs(np.max(np.linalg.eigvals(A + B @ Kp).real))
    for h in spec.far_delays:
        window = max(10 * h, 3 / slow)
        r = simulate_linear_dde(A, B @ Kp, h, E0, 3 * window, min(h, 1 / rate) / 5)
        ratios_p.append((h, envelope_ratio(r, window)))
    halving = step_halving(1.0, 0.7, 10.0, (0.1, 0.05, 0.025, 0.0125))
    return LinearCheck(A, B, tuple(K), tuple(spec.finite_gain), fin, tuple(ratios_f), pm,
                       tuple(ratios_p), tuple(runs), halving)


def _range(t: Reader, key: str, **kw) -> tuple[float, float]:
    lo_hi = t.numbers(key, min_len=2, what="[low, high]")
    if len(lo_hi) != 2 or not lo_hi[0] <= lo_hi[1]:
        raise t.fail(key, list(lo_hi), "a range [low, high] with low <= high")
    for x in lo_hi:
        if kw.get("positive") and not x > 0 or "lo" in kw and x < kw["lo"] or \
                "hi" in kw and x > kw["hi"]:
            raise t.fail(key, list(lo_hi), f"a range within the allowed values ({kw})")
    return lo_hi


#: gain_for's answers in this process, keyed by what they depend on (the
#: sweep, the halving check and the cases of a design all ask for the same K).
_GAINS: dict = {}


def gain_for(spec: RunSpec) -> tuple[tuple, str, float | None]:
    """(K, how it was obtained, h_certified or None): from the certified
    synthesis of problem (60) at the design's eps on the nominal cruise
    linearisation, or the design's table gain (each synthesis once per
    process: the answer depends on the nominal plant, v_d and eps only)."""
    if spec.gain == "table":
        return tuple(spec.K_table), spec.K_source, None
    from ..memo import spec_key
    key = spec_key((spec.params, spec.scenario["v_d"], spec.eps))
    if key is None or key not in _GAINS:
        from ..synthesis import synthesize_delay_bound
        _, _, lin = _nominal_cruise(spec)
        row = synthesize_delay_bound(lin.A, lin.B, (spec.eps,))[0]
        if row.K is None:
            raise ModelError(f"synthesis at eps = {spec.eps} certified no gain")
        out = (row.K, f"synthesis, problem (60) at eps = {spec.eps:g}", row.h_certified)
        if key is None:
            return out
        _GAINS[key] = out
    return _GAINS[key]


def simulate_design(design, case_name: str | None, dt: float | None) -> dict:
    """One case of an ``antiskid-run`` design at one step (for ``workbench
    simulate``): metrics, wall time and the real-time factor."""
    import time
    spec: RunSpec = design.spec
    names = [c.name for c in spec.cases]
    name = case_name or names[0]
    if name not in names:
        raise DesignError("<cli>", "--case", name, "one of " + ", ".join(names))
    dt = dt or spec.dt
    if not (dt > 0 and (dt <= spec.scenario["h"] or spec.scenario["h"] == 0)):
        raise DesignError("<cli>", "--dt", dt, "a positive step no larger than the delay (s)")
    case = next(c for c in spec.cases if c.name == name)
    K, how, _ = gain_for(spec)
    cs = controller_settings(spec, K, case)
    t0 = time.perf_counter()
    run, m = simulate_antiskid(run_settings(spec, cs), dt, record_dt=None,
                               mesh=case_mesh(spec, case))
    wall = time.perf_counter() - t0
    metrics = case_metrics(m, cs, spec.scenario["t_brake"])
    end = m.t_stop if math.isfinite(m.t_stop) else (
        m.t_diverged if math.isfinite(m.t_diverged) else spec.scenario["t_end"])
    return {"design": design.name, "case": name, "dt": dt, "K": list(K), "K_source": how,
            "metrics": metrics, "simulated_s": float(end), "wall_s": wall,
            "realtime_factor": float(end) / wall}


def simulate_command(path: str, *, case: str | None, dt: float | None, as_json: bool) -> int:
    """``workbench simulate``: print the metrics of one case; exit 0."""
    import json

    from ..design import load_design
    from ..report.markdown import fmt, md_table
    design = load_design(path)
    if design.kind != STUDY.kind:
        raise DesignError(design.path, "design.kind", design.kind, f'"{STUDY.kind}"')
    out = simulate_design(design, case, dt)
    if as_json:
        print(json.dumps(out, indent=2, default=lambda x: None))
        return 0
    print(f"{out['design']} / {out['case']}: dt = {fmt(out['dt'])} s, K = {out['K']} "
          f"({out['K_source']})")
    print(md_table(["metric", "value"], [[k, fmt(v, 6)] for k, v in out["metrics"].items()
                                         if not (isinstance(v, float) and math.isnan(v))], "lr"))
    print(f"simulated {fmt(out['simulated_s'], 4)} s in {out['wall_s']:.2f} s wall: "
          f"{out['realtime_factor']:.0f}x real time")
    return 0


class AntiskidRun:
    kind = "antiskid-run"

    def load(self, root: Reader) -> RunSpec:
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
                "t_brake": sc.quantity("t_brake", "s", positive=True).value,
                "t_end": sc.quantity("t_end", "s", positive=True, hi=5000.0).value}
        sc.finish()
        if not scen["t_end"] > scen["t_brake"]:
            raise DesignError(root.path, "scenario.t_end", scen["t_end"], "a time after t_brake")
        ct = root.table("controller")
        gain = ct.string("gain", choices=("synthesis", "table"))
        eps = ct.number("eps", positive=True)
        K_table = ct.numbers("K_table", min_len=2, what="gain entries")
        if len(K_table) != 2:
            raise ct.fail("K_table", list(K_table), "two gain entries [k1, k2]")
        K_source = ct.string("K_source")
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
        rtol = nu.number("convergence_rtol", positive=True, hi=0.1)
        atol_t = nu.table("convergence_atol")
        atol = {k: atol_t.number(k, nonneg=True) for k in list(atol_t.data)}
        for k in atol:
            if k not in METRICS:
                raise atol_t.fail(k, atol[k], "a metric name: " + ", ".join(METRICS))
        atol_t.finish()
        nu.finish()
        if scen["h"] < dt and scen["h"] > 0:
            raise DesignError(root.path, "numerics.dt", dt, f"a step no larger than h = {scen['h']}")
        cases = []
        for cr in root.tables("cases"):
            cases.append(Case(cr.string("name"), cr.string("description"),
                              cr.boolean("compensate"),
                              cr.string("cruise_entry", choices=("speed", "creep")),
                              cr.string("brake_entry", choices=("time", "creep")),
                              cr.string("predictor", default="rollout",
                                        choices=("rollout", "recursive"))))
            cr.finish()
        names = [c.name for c in cases]
        if not cases or len(set(names)) != len(names):
            raise DesignError(root.path, "cases", names, "at least one case, distinct names")
        lc = root.table("linear_check")
        fg = lc.numbers("finite_gain", min_len=2)
        factors = lc.numbers("factors", positive=True)
        far = lc.numbers("far_delays", positive=True)
        periods = lc.number("periods", positive=True, hi=200.0)
        lc.finish()
        mc = None
        if root.has("montecarlo"):
            from ..sim.montecarlo import SweepSpec
            mt = root.table("montecarlo")
            rng = lambda k, **kw: _range(mt, k, **kw)
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
                           mt.number("dt", default=None, positive=True, hi=0.05))
            if mc.halving > mc.samples:
                raise mt.fail("halving_samples", mc.halving,
                              f"at most samples = {mc.samples} (the check re-runs the first runs)")
            mt.finish()
        vals = {k: q.value for k, q in params.items()}
        try:
            NumericAdhesion.from_dict(vals).cruise_lambda(scen["v_d"])
        except ModelError as exc:
            raise DesignError(root.path, "scenario.v_d", scen["v_d"],
                              f"a speed with a creep-region equilibrium ({exc})") from None
        return RunSpec(rail, params, mass_factor, scen, gain, eps, K_table, K_source, k_ac, k_de,
                       profile, dt, v_stop, band, torque_range, mesh_courant, mesh_levels, rtol, atol, tuple(cases), tuple(fg),
                       factors, far, periods, mc)

    def quantity_names(self, spec: RunSpec) -> set[str]:
        names = {"operating_point.lambda_opt", "operating_point.lambda_d", "gain.K1", "gain.K2",
                 "gain.h_certified", "linear.finite.h_star", "linear.paper.exact_margin",
                 "linear.paper.max_envelope_ratio"}
        names |= {f"linear.finite.ratio[{f:g}]" for f in spec.factors}
        for c in spec.cases:
            b = f"cases[{c.name}]"
            names |= {f"{b}.{m}" for m in METRICS}
            names |= {f"{b}.diverged", f"{b}.stopped", f"{b}.converged",
                      f"{b}.switch.abscissa", f"{b}.switch.margin", f"{b}.switch.dmu_dlam"}
        if spec.montecarlo is not None:
            from ..sim.montecarlo import halving_quantity_names, montecarlo_quantity_names
            names |= montecarlo_quantity_names()
            if spec.montecarlo.halving:
                names |= halving_quantity_names()
        return names

    def start(self, design):
        """Start the Monte Carlo part of :meth:`run` (its process pools) now,
        so that it overlaps whatever the caller does next; returns the
        handle :meth:`run` takes as ``started`` (None: nothing to start)."""
        spec: RunSpec = design.spec
        if spec.montecarlo is None:
            return None
        from ..sim.montecarlo import start_halving, start_sweep
        K = gain_for(spec)[0]
        ms = spec.montecarlo
        pending = start_sweep(design, ms.samples, ms.seed, workers=ms.workers,
                              chunk=ms.chunk, pool=True, K=K)
        halving = None
        if ms.halving:    # its dt side is the sweep's first runs
            halving = start_halving(design, ms.halving, K=K, pool=True, coarse=False)
        return pending, halving

    def run(self, design, started=None) -> RunResult:
        """The cases, the linear checks and the Monte Carlo part (its chunks
        run in a pool while the cases run here; ``started``: the handle of
        :meth:`start` if it was started already)."""
        spec: RunSpec = design.spec
        nominal, lam_d, lin = _nominal_cruise(spec)
        K, how, h_cert = gain_for(spec)
        if started is None:
            started = self.start(design)
        pending, halving = started or (None, None)
        try:
            cases = self._cases(spec, K)
            lc = linear_check(spec, lin.A, lin.B, K)
        except BaseException:
            for p in (pending, halving):
                if p is not None:
                    p.cancel()
            raise
        mc = None if pending is None else pending.result()
        hc = None if halving is None else halving.result()(mc)
        return RunResult(nominal.lambda_opt(), lam_d, tuple(K), how, h_cert, tuple(cases), lc,
                         spec.dt, mc, hc)

    def _cases(self, spec: RunSpec, K) -> list[CaseResult]:
        cases = []
        for case in spec.cases:
            cs = controller_settings(spec, K, case)
            rs = run_settings(spec, cs)
            t_b = spec.scenario["t_brake"]
            mesh = case_mesh(spec, case)
            _, m1 = simulate_antiskid(rs, spec.dt, record_dt=None, mesh=mesh)
            run2, m2 = simulate_antiskid(rs, spec.dt / 2, record_dt=0.05, mesh=mesh)
            coarse, fine = case_metrics(m1, cs, t_b), case_metrics(m2, cs, t_b)
            conv = {k: _agree(coarse[k], fine[k], spec.conv_rtol, spec.conv_atol.get(k, 0.0))
                    for k in METRICS}
            sw = None   # state where the cruise law (61) takes over
            key = "handover" if case.cruise_entry == "creep" else "cruise"
            if math.isfinite(fine[f"lam_at_{key}"]):
                sw = switch_check(cs, fine[f"v_at_{key}"], fine[f"lam_at_{key}"])
            cases.append(CaseResult(case, fine, coarse, conv, run2, sw))
        return cases

    def quantities(self, res: RunResult) -> dict:
        nan2none = lambda x: None if x is None or (isinstance(x, float) and math.isnan(x)) else x
        q = {"operating_point.lambda_opt": res.lambda_opt, "operating_point.lambda_d": res.lambda_d,
             "gain.K1": res.K[0], "gain.K2": res.K[1], "gain.h_certified": res.h_certified,
             "linear.finite.h_star": res.linear.finite_margin.h,
             "linear.paper.exact_margin": res.linear.paper_margin.h,
             "linear.paper.max_envelope_ratio": max(r for _, r in res.linear.ratios_paper)}
        for fac, _, r in res.linear.ratios_finite:
            q[f"linear.finite.ratio[{fac:g}]"] = r
        for c in res.cases:
            b = f"cases[{c.case.name}]"
            for k in METRICS:
                q[f"{b}.{k}"] = nan2none(c.metrics[k])
            q[f"{b}.diverged"] = "no" if math.isnan(c.metrics["t_diverged"]) else "yes"
            q[f"{b}.stopped"] = "yes" if math.isfinite(c.metrics["braking_duration"]) else "no"
            q[f"{b}.converged"] = "yes" if all(c.converged.values()) else "no"
            sw = c.switch
            q[f"{b}.switch.abscissa"] = None if sw is None else sw.abscissa
            q[f"{b}.switch.margin"] = None if sw is None else sw.margin.h
            q[f"{b}.switch.dmu_dlam"] = None if sw is None else sw.dmu_dlam
        if res.montecarlo is not None:
            from ..sim.montecarlo import halving_quantities, montecarlo_quantities
            q.update(montecarlo_quantities(res.montecarlo))
            if res.halving is not None:
                q.update(halving_quantities(res.halving))
        return q

    def render(self, design, res: RunResult):
        from .antiskid_run_render import render
        return render(design, res)


STUDY = AntiskidRun()
