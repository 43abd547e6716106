"""Compute a ``delay-feedback`` design: linearise, synthesise, check, simulate.

Every step calls the shared public functions: the synthesis of
:mod:`workbench.synthesis` (paper 003's problem (60) over eps, the canonical
gain of :mod:`workbench.lmi.gain`), :func:`workbench.lmi.tight_synthesis.
synthesize_tight` (Wirtinger synthesis, gain checked by the Bessel-Legendre
analysis of order N), :func:`workbench.lmi.robust.synthesize_robust` (one
gain over polytope vertices), :func:`workbench.margins.exact_margin` and
:func:`~workbench.margins.stability_windows` (exact, independent of the
LMIs) and :func:`workbench.sim.delay.simulate_closed_loop` (the nonlinear
plant with the input delay, at dt and dt/2).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...jsonable import OMIT, json_method
from .model import OperatingPoint, PlantModel, linearise, solve_operating_point


def nominal_point(spec, vertex=None):
    """(model, parameter values, operating point, A, B) of the design (or of a vertex)."""
    model = PlantModel(spec.plant)
    values = spec.plant.values(None if vertex is None else vertex.values)
    key = "operating_point" if vertex is None else f"vertices[{vertex.name}]"
    model.check_finite(values, "parameters" if vertex is None else key)
    op = solve_operating_point(model, values, key=key)
    A, B = linearise(model, values, op)
    return model, values, op, A, B


@dataclass(frozen=True)
class SynthesisOutcome:
    """The synthesis of a design, whatever the method.

    Attributes
    ----------
    method : str
    h_certified, h_refuted : float
        Bracket (s) of the synthesis LMI (problem (60): the best eps row).
    K : numpy.ndarray or None
        Canonical gain (m x n), u = u_op + K (x - x_ref).
    h_gain : float or None
        Delay the rounded gain certifies on its own (same LMI, K fixed).
    status : str
        ``certified`` / ``inconclusive`` / ``refuted`` (closed set of
        :class:`workbench.lmi.core.Outcome`).
    eps : float or None
        eps of the reported row (problem (60)) or of the automatic search.
    h_analysis : float or None
        Bessel-Legendre order-N analysis bound with K (Wirtinger, robust).
    all_delays : bool
        True: the certificate proves stability for every constant delay in
        [0, h]; False: at h only (Wirtinger).
    rows, tight, robust :
        The method's own result objects.
    """

    method: str
    h_certified: float
    h_refuted: float
    K: np.ndarray | None
    h_gain: float | None
    status: str
    eps: float | None
    h_analysis: float | None
    all_delays: bool
    at_cap: bool
    rows: tuple = ()
    tight: object = field(default=None, repr=False)
    robust: object = field(default=None, repr=False)
    required: float | None = None      # the design's largest delay (s)
    h_cap: float | None = None         # the synthesis search cap (s)
    requirements: object = field(default=None, repr=False)   # RequirementResult

    @property
    def reason(self) -> str:
        """Why the status is not ``certified``, or why the certificate cannot
        reach the design's delay (empty otherwise)."""
        if self.required is not None and self.h_cap is not None and self.h_cap < self.required:
            return (f"search cap below the required delay: h_max = {self.h_cap:g} s < "
                    f"{self.required:g} s")
        if self.status == "certified":
            return ""
        own = (self.tight if self.tight is not None else
               self.requirements if self.requirements is not None else
               self.robust[0] if self.robust is not None else
               max(self.rows, key=lambda r: r.h_certified, default=None))
        return getattr(own, "reason", "") or "no reason recorded"


@dataclass(frozen=True)
class ScenarioResult:
    """One scenario: metrics at dt/2 (reported), at dt, and their agreement;
    with ``[convergence]`` also at dt/4."""

    scenario: object
    metrics: dict
    metrics_coarse: dict
    converged: bool
    run: object = field(repr=False)     # SimResult at dt/2
    metrics_fine: dict | None = None    # at dt/4 ([convergence])


@dataclass(frozen=True)
class DelayFeedbackResult:
    """Everything a ``delay-feedback`` design computes (see :func:`run`)."""

    op: OperatingPoint
    A: np.ndarray
    B: np.ndarray
    synthesis: SynthesisOutcome
    exact: object              # ExactMargin of x' = A x + B K x(t-h), or None
    windows: tuple
    range_stable: bool | None
    vertex_checks: tuple = ()
    scenarios: tuple = ()
    vertex_points: tuple = ()
    delay: object = None       # DelaySpec of the design
    names: tuple = ()          # state names, then input names
    basin: object = None       # delay_feedback_basin.DelayFeedbackBasin or None
    implementation: object = None   # delay_feedback_implementation.DesignImplementation
    spec: object = None        # DelayFeedbackSpec (indexes the declared quantities)
    montecarlo: tuple | None = None   # montecarlo.MonteCarloScenario per drawn scenario
    refinement: tuple = ()     # refinement.RefinementRow per claim on a metric ([convergence])
    gain_tables: object = None  # gain_tables.GainTablesResult or None

    #: The JSON of the result (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"A": "A", "B": "B", "x_op": "op.x", "u_op": "op.u",
                   "method": "synthesis.method", "h_certified": "synthesis.h_certified",
                   "h_refuted": "synthesis.h_refuted", "K": "synthesis.K",
                   "status": "synthesis.status", "reason": "synthesis.reason",
                   "exact_margin": "exact.h", "windows": "windows",
                   "scenarios": lambda r: {s.scenario.name: s.metrics for s in r.scenarios},
                   "requirements": lambda r: (
                       OMIT if r.synthesis.requirements is None
                       else r.synthesis.requirements.as_dict()["requirements"]),
                   "refinement": lambda r: ({x.claim_id: x.outcome for x in r.refinement}
                                            if r.spec is not None and r.spec.convergence
                                            else OMIT)}
    to_json = json_method


def synthesise(spec, A, B, points=()) -> SynthesisOutcome:
    """Run the design's synthesis choice on (A, B) (or on the vertex points)."""
    syn, st = spec.synthesis, spec.synthesis.settings
    if syn.method == "free-weighting-003":
        from ...synthesis import synthesize_delay_bound
        rows = synthesize_delay_bound(A, B, syn.eps, st)
        best = max(rows, key=lambda r: r.h_certified)
        K = None if best.K is None else np.array(best.K).reshape(B.shape[1], -1)
        return SynthesisOutcome(syn.method, best.h_certified, best.h_refuted, K, best.h_gain,
                                best.status.value, best.eps, None, True,
                                best.h_certified >= st.h_max, rows=rows)
    if points:
        from ...crosscheck import check_gain
        from ...lmi.robust import synthesize_robust
        r = synthesize_robust(list(points), alpha=syn.decay_rate, eps_grid=syn.grid,
                              h_hi=st.h_max,
                              rel_tol=max(st.rel_tol, 1e-3), margin=st.margin,
                              gain_fraction=st.gain_fraction, gain_digits=st.gain_digits)
        ok = r.bracket.outcome.value == "certified" and r.gain is not None and \
            r.gain.outcome.value == "certified"
        checks = () if r.K is None else check_gain(list(points), r.K, N=syn.order,
                                                    margin=st.margin, h_hi=st.h_max)
        h_an = min(c.h_certified for c in checks) if checks else None
        return SynthesisOutcome("robust-descriptor", r.bracket.h_certified, r.bracket.h_refuted,
                                r.K, None if r.gain is None else r.gain.h_certified,
                                "certified" if ok else _failed(r.bracket), r.eps, h_an,
                                syn.decay_rate == 0, r.bracket.h_certified >= st.h_max,
                                robust=(r, checks))
    from ...crosscheck import check_tight
    from ...lmi.tight_synthesis import synthesize_tight
    t = synthesize_tight(A, B, eps_grid=syn.grid, h_max=st.h_max,
                         margin=st.margin, rel_tol=max(st.rel_tol, 1e-3),
                         gain_fraction=st.gain_fraction, gain_digits=st.gain_digits)
    ok = t.bracket.outcome.value == "certified" and t.gain is not None and \
        t.gain.outcome.value == "certified"
    check = None if t.K is None else check_tight(A, B, t.K, N=syn.order, margin=st.margin,
                                                 h_hi=st.h_max).check
    return SynthesisOutcome(syn.method, t.h_certified, t.bracket.h_refuted, t.K,
                            None if t.gain is None else t.gain.h_certified,
                            "certified" if ok else _failed(t.bracket), t.eps,
                            None if check is None else check.h_certified, False,
                            t.at_cap, tight=t)


def _failed(bracket) -> str:
    """``infeasible`` when a diagnosis stopped the synthesis, else ``inconclusive``."""
    return "infeasible" if bracket.outcome.value == "infeasible" else "inconclusive"


def synthesise_requirements(spec, model, values, op, A, B, points=()):
    """The design's synthesis when it has ``[requirements]``: a
    :class:`~.run.SynthesisOutcome` whose delay fields are
    the gain's own certified cap (every delay in [0, H] at the required
    decay rate, gain and input limit)."""
    from .requirements import run_requirements
    res = run_requirements(spec, spec.requirements, model, values, op, A, B, points)
    d, c = res.design, res.design.certificate
    h = None if c is None else c.h_certified
    ok = h is not None and h >= spec.requirements.delay[1]
    refuted = math.inf if c is None else c.delay.h_refuted
    return SynthesisOutcome("requirements", h or 0.0, refuted, res.K, h,
                            "certified" if ok else "inconclusive", d.eps, None, True, False,
                            requirements=res)


def delay_range_stable(windows, h_min: float, h_max: float) -> bool:
    """True when one exact stability window contains every delay in [h_min, h_max]."""
    return any(a < h_min and h_max < b for a, b in windows)


def design_synthesis(spec, model, values, op, A, B, points=()) -> SynthesisOutcome:
    """The design's own synthesis: to its ``[requirements]`` when it has them
    (:func:`synthesise_requirements`), else the method of ``[synthesis]``
    with the design's delay and search cap attached (for the reason).

    Computed once per process and run (:func:`workbench.memo.computed_once`,
    keyed by the exact spec, which determines every other argument): the
    study, ``simulate``, ``sweep`` and the tests share one synthesis."""
    from ...memo import computed_once, spec_key
    key = spec_key(spec)
    compute = lambda: _design_synthesis(spec, model, values, op, A, B, points)  # noqa: E731
    return compute() if key is None else computed_once("design_synthesis", key, compute)


def _design_synthesis(spec, model, values, op, A, B, points=()) -> SynthesisOutcome:
    if spec.synthesis.method == "requirements":
        return synthesise_requirements(spec, model, values, op, A, B, points)
    return replace(synthesise(spec, A, B, points), required=spec.delay.h_max,
                   h_cap=spec.synthesis.settings.h_max)


def designed_gain(design, spec=None, what: str = "to do"):
    """(model, values, op, A, B, synthesis) of a design's own synthesis for a
    command, or None after printing that no gain was certified (``what``:
    what the command then does not do)."""
    spec = design.spec if spec is None else spec
    model, values, op, A, B = nominal_point(spec)
    points = tuple(nominal_point(spec, v)[3:] for v in spec.vertices)
    s = design_synthesis(spec, model, values, op, A, B, points)
    if s.K is None:
        print(f"{design.name}: no gain was certified; nothing {what}")
        return None
    return model, values, op, A, B, s


def run(spec) -> DelayFeedbackResult:
    """Compute a design (see the module docstring)."""
    from ...margins import exact_margin, stability_windows
    model, values, op, A, B = nominal_point(spec)
    points = tuple(nominal_point(spec, v)[3:] for v in spec.vertices)
    syn = design_synthesis(spec, model, values, op, A, B, points)
    exact, windows, stable = None, (), None
    checks = ()
    if syn.K is not None:
        Ad = B @ syn.K
        exact = exact_margin(A, Ad)
        windows = stability_windows(A, Ad, spec.window_horizon)
        stable = delay_range_stable(windows, spec.delay.h_min, spec.delay.h_max)
        if syn.robust is not None:
            from ...margins import SpectrumNotConverged, spectral_abscissa
            ab = []
            for A_i, B_i in points:    # decay-rate certificate vs the spectrum, at h_gain
                try:
                    ab.append(spectral_abscissa(A_i, B_i @ syn.K, syn.h_gain)
                              if syn.h_gain else None)
                except SpectrumNotConverged:
                    ab.append(None)
            checks = tuple(zip(spec.vertices, syn.robust[1], ab))
    scen = tuple(simulate_scenario(spec, model, values, op, syn.K, s)
                 for s in spec.scenarios) if syn.K is not None else ()
    basin = None
    if spec.basin is not None and syn.K is not None:
        from ...features.basin import run_basin
        basin = run_basin(spec.basin, spec, model, values, op, syn.K)
    impl = None
    if spec.implementation is not None and syn.K is not None:
        from ...features.sampled import run_implementation
        impl = run_implementation(spec.implementation, spec.delay, A, B, syn.K)
    mc = None
    if spec.montecarlo is not None and syn.K is not None:
        from .montecarlo import run_montecarlo
        mc = run_montecarlo(spec, model, values, op, syn.K, reference, predict)
    rows = ()
    if spec.convergence:
        from ...features.convergence import claim_rows
        rows = tuple(x for s in scen for x in claim_rows(
            spec.claims, s.scenario.name, (s.metrics_coarse, s.metrics, s.metrics_fine),
            reported=1))
    from .gain_tables import run_gain_tables
    tables = run_gain_tables(spec.gain_tables, A, B, syn, spec.synthesis, points)
    return DelayFeedbackResult(op, A, B, syn, exact, tuple(windows), stable, checks, scen,
                               points, spec.delay,
                               spec.plant.state_names + spec.plant.input_names, basin, impl,
                               spec, mc, rows, tables)


# -- simulation -----------------------------------------------------------------------
def reference(spec, op: OperatingPoint, scenario):
    """x_ref(t) -> (n,) array: the operating point, with the scenario's set-point steps."""
    names = spec.plant.state_names
    base = op.x.copy()
    steps = [(names.index(k), np.array([t for t, _ in v]), np.array([x for _, x in v]))
             for k, v in scenario.setpoint.items()]

    def ref(t: float) -> np.ndarray:
        r = base.copy()
        for i, ts, xs in steps:
            r[i] = xs[np.searchsorted(ts, t + 1e-12, side="right") - 1]
        return r
    return ref


def predict(f, x, pieces, dt: float) -> np.ndarray:
    """x(t + h) predicted from x(t) by integrating the plant model over the
    inputs already sent, [t - h, t) (``pieces``: (value, duration) oldest
    first), with Runge-Kutta 4 steps of at most ``dt``: the predictor of
    paper 003, Lemma 1 (eq 2), X(t + h) = X(t) + int_{t-h}^{t} f(X(s + h), U(s)) ds."""
    x = np.asarray(x, float)
    for u, d in pieces:
        if not d > 0:
            continue
        u = np.atleast_1d(u)
        n = max(int(np.ceil(d / dt - 1e-9)), 1)
        s = d / n
        for _ in range(n):
            k1 = f(x, u)
            k2 = f(x + 0.5 * s * k1, u)
            k3 = f(x + 0.5 * s * k2, u)
            k4 = f(x + s * k3, u)
            x = x + s / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


def simulate(spec, model, values, op, K, scenario, dt: float):
    """The nonlinear closed loop u = u_op + K (x - x_ref(t)) with the input
    delay h, classical Runge-Kutta 4 per step with the delayed ZOH input held
    (its exact step average, :class:`workbench.sim.history.DelayLine`). With
    ``scenario.predictor`` the law acts on the predicted state instead,
    u = u_op + K (x_hat(t + h) - x_ref(t + h)) (:func:`predict`)."""
    from ...sim.delay import simulate_closed_loop
    f0 = model.rhs(values)
    sched = scenario.parameters or {}
    pieces = {}

    def f_at(t: float):
        """The plant with the scenario's parameter schedule at t (cached per value set)."""
        key = tuple(vs[np.searchsorted([a for a, _ in vs], t + 1e-12, side="right") - 1][1]
                    for vs in sched.values())
        if key not in pieces:
            pieces[key] = model.rhs(values | dict(zip(sched, key)))
        return pieces[key]
    ref = reference(spec, op, scenario)
    names = spec.plant.state_names
    x0 = op.x.copy()
    for k, v in scenario.x0.items():
        x0[names.index(k)] = v
    K = np.atleast_2d(K)
    scale = 1e6 * (1.0 + np.abs(op.x) + np.abs(x0))

    def step(x, ua, t, h):
        x = np.asarray(x, float)
        ua = np.atleast_1d(ua)
        f = f_at(t) if sched else f0
        k1 = f(x, ua)
        k2 = f(x + 0.5 * h * k1, ua)
        k3 = f(x + 0.5 * h * k2, ua)
        k4 = f(x + h * k3, ua)
        return tuple(x + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))

    def control(t, x, line):
        if scenario.predictor:
            xp = predict(f_at(t) if sched else f0, x, line.pieces(), dt)
            return op.u + K @ (xp - ref(t + scenario.h)), 0
        return op.u + K @ (np.asarray(x, float) - ref(t)), 0

    def done(t, x, phase):
        e = np.abs(np.asarray(x, float) - ref(t))
        return not (np.all(np.isfinite(e)) and np.all(e < scale))

    with np.errstate(all="ignore"):
        r = simulate_closed_loop(step, control, tuple(x0), h=scenario.h, dt=dt,
                                 t_end=scenario.t_end, u_init=op.u.copy(), done=done)
    return r


def metrics(spec, op, scenario, r) -> dict:
    """peak/final |x - x_ref| per state, peak |u - u_op| per input, diverged (0/1);
    with a parameter schedule also the signed min of x - x_ref per state."""
    ref = reference(spec, op, scenario)
    R = np.array([ref(t) for t in r.t]).T
    E = np.abs(r.x - R)
    diverged = bool(r.t[-1] < scenario.t_end - 0.5 * r.dt) or not np.all(np.isfinite(E))
    out = {}
    for i, k in enumerate(spec.plant.state_names):
        out[f"peak_error.{k}"] = math.nan if diverged else float(np.max(E[i]))
        out[f"final_error.{k}"] = math.nan if diverged else float(E[i, -1])
        if scenario.parameters:
            out[f"min_error.{k}"] = math.nan if diverged else float(np.min(r.x[i] - R[i]))
    du = np.abs(input_history(r, op.u.size) - op.u.reshape(-1, 1))
    for i, k in enumerate(spec.plant.input_names):
        out[f"peak_input_dev.{k}"] = math.nan if diverged else float(np.max(du[i]))
    out["diverged"] = 1.0 if diverged else 0.0
    return out


def input_history(r, m: int) -> np.ndarray:
    """Controller outputs of a run as an (m, K) array (the loop records
    array-valued inputs one row per sample)."""
    U = np.atleast_2d(np.asarray(r.u, float))
    return U if U.shape[0] == m and U.shape[1] == r.t.size else U.reshape(r.t.size, m).T


def agree(coarse: dict, fine: dict, rtol: float) -> bool:
    """Every metric at dt within rtol of dt/2 (:func:`workbench.features.
    convergence.agree`, absolute floor: rtol x the state's peak error, so a
    final error near zero compares on that scale)."""
    from ...features.convergence import agree as agree_value
    return all(agree_value(coarse[k], b, rtol, rtol * abs(
        fine.get(f"peak_error.{k.split('.', 1)[-1]}", b)) + 1e-15) for k, b in fine.items())


def simulate_scenario(spec, model, values, op, K, scenario) -> ScenarioResult:
    """The scenario at dt and dt/2 (and dt/4 with ``[convergence]``); metrics
    of the dt/2 run are reported."""
    r1 = simulate(spec, model, values, op, K, scenario, scenario.dt)
    r2 = simulate(spec, model, values, op, K, scenario, scenario.dt / 2)
    m1, m2 = metrics(spec, op, scenario, r1), metrics(spec, op, scenario, r2)
    m4 = None
    if spec.convergence:
        m4 = metrics(spec, op, scenario, simulate(spec, model, values, op, K, scenario,
                                                  scenario.dt / 4))
    return ScenarioResult(scenario, m2, m1, agree(m1, m2, scenario.rtol), r2, m4)


# -- quantities ---------------------------------------------------------------------------
def quantities(res: DelayFeedbackResult) -> dict:
    """Values of the claimable quantities (None: not determined), read as
    :data:`~workbench.kinds.delay_feedback.quantities.TABLE` declares them."""
    from ...features.quantities import values
    from .quantities import TABLE
    return values(TABLE, res.spec, res)
