"""Study ``stop-accuracy``: station stops of a braking plant under named
controllers, with disturbances, faults and the stop-error statistics
(issue 35, item 1).

Each controller brakes the plant from every initial speed to the stopping
point D; the stop error is the standstill position minus D (+ = overshoot).

Tables::

    [plant]        model = "brake-000" and its parameters, SI units
                   (:func:`.pipeline.read_brake_plant`; why a named model: see there)
    [target]       speeds_kmh = [...], tolerance = { value, unit = "m" },
                   c_max = { value, unit = "m/s^2" } (full service; commands clip to [0, c_max]),
                   traction_max = { value, unit = "m/s^2" } (optional: clip to
                   [-traction_max, c_max], a law may call for traction),
                   and the stopping point: distance = { value, unit = "m" }, or
                   command = { value, unit = "m/s^2" } (D = the nominal stopping distance
                   of that command held, as paper 004 section 1)
    [constants]    name = { value, unit, source }  (numbers the laws use)
    [[controllers]] name, law = "expression" (brake command, m/s^2),
                   definitions = { name = "expression", ... } (in order, optional),
                   pid = { error = "expression", kp = "constant", ki = ..., kd = ...,
                   limited = true } (optional: the named module ``pid`` adds a sampled PID
                   of the error, :class:`workbench.controllers.pid.BatchPID`, to the law;
                   its output limited to ±c_max unless ``limited = false``),
                   or smarc = { c = "constant", ... } (the named module ``smarc``: the whole
                   law), compensation = { predictor = true, terminal = true,
                   gain_correction = true } (optional, with [compensation]; :mod:`.modules`),
                   deceleration_loop = { e_switch = "constant", ..., axles = 4 } (optional:
                   the named module closes a loop on the deceleration measured from the
                   axle speeds, the law being its target; :mod:`.decel_loop`),
                   levels = 7 (optional: a command channel of that many levels above 0,
                   the command rounded to the nearest multiple of c_max / levels)
    [reference]    model = "ato-trapezoid", v_max, a_acc, a_dec (optional: the target a
                   tracking law follows; laws see x_d, v_d, a_d; runs start where it starts
                   braking, [target] has no speeds_kmh and distance is the section length)
    [compensation] d_terminal (m), gain_tau (s), gain_bounds = [lo, hi] (the named modules
                   predictor and terminal, :mod:`.modules`)
    [disturbances] name = { effect = "scale", parameters = ["T1", ...] } | { effect =
                   "gradient" } (permille) | { effect = "force_error" } | { effect = "mass_ratio" }
                   (the factors, in this order: a Monte Carlo draw's stream is its position)
    [[faults]]     name, parameters = { brake parameter = value }, speed_ratio (the speed
                   the law sees / the true speed), disturbance = { factor = value },
                   axles = "fffo" (the axle sensors' states, with a deceleration_loop)
    [grid]         factor = [values, ...]  (every combination, in the order written: the
                   corners of an error grid, as paper 004 section 1.3), feasible_with =
                   "controller" (optional: a corner is feasible where that controller, e.g.
                   full service held, stops at least the tolerance short of D)
    [[sections]]   name, length = { value, unit = "m", source }, with [repeats] count, seed, ranges = { factor
                   = [lo, hi] } (with [reference]: every controller's repeats on every
                   section, paper 000 Tables 3-4; :mod:`.sections`)
    [montecarlo]   samples, seed, distributions = { factor = { dist = ... } }
                   (:mod:`workbench.features.montecarlo`)
    [convergence]  (no keys: every nominal and fault stop error at dt, dt/2, dt/4,
                   :mod:`workbench.features.convergence`)
    [sim]          dt, dt_ctrl, t_end (s)
    [analysis]     module = "pNNN.name" (optional: a paper's module under
                   ``workbench.papers`` with an ``ANALYSIS`` object that reads the paper's
                   own tables, runs the design through this kind's simulation and names
                   the claims' quantities and the report; its findings are refined at
                   dt/2 and dt/4, :mod:`workbench.features.refinement`)

A law sees ``x`` (m since braking began), ``v`` (the measured speed, m/s),
``decel`` (the measured deceleration, m/s^2, >= 0), ``d_go = D - x`` (m),
``D`` (m), ``v0`` (m/s), ``t`` (s), the constants and its definitions; it is
parsed by :mod:`workbench.expr` (never evaluated as Python) and must have the
unit m/s^2 (pint). A controller with internal state is not an expression:
an integrator is the one named module a design may reference (``pid``: its
gains are constants of the design, unit-checked as ``kp*error``,
``ki*error*t`` and ``kd*error/t`` in m/s^2; the PID output is limited to
±c_max with conditional integration, or unlimited). Paper 000's SMARC, the
Smith predictor and the predictive terminal law are named modules too
(:mod:`.modules`, which says why each is not an expression), and so is paper
004's fuzzy/PID command generator on the axle sensors (``deceleration_loop``,
:mod:`.decel_loop`).
"""
from __future__ import annotations

from dataclasses import dataclass

from ...reader import Quantity, Reader
from .pipeline import EFFECTS, LAW_NAMES, Factor, read_brake_plant

__all__ = ["Controller", "Fault", "STUDY", "StopAccuracySpec", "LAW_NAMES"]

#: Most Monte Carlo runs of one design (samples x speeds x controllers): one batch.
MAX_RUNS = 20000
#: Most Monte Carlo runs x integration steps.
MAX_WORK = 2e9
#: Refinement levels of ``[convergence]``: dt / 2**k.
LEVELS = (0, 1, 2)


@dataclass(frozen=True)
class Controller:
    name: str
    law: str | None                                  # None: the named module smarc
    definitions: tuple[tuple[str, str], ...] = ()
    pid: tuple[str, str, str, str] | None = None     # (error, kp, ki, kd constant names)
    smarc: object = None                             # modules.SmarcGains
    predictor: bool = False                          # compensation = { predictor = true }
    terminal: bool = False                           # ... terminal = true
    gain_correction: bool = True                     # ... gain_correction = false: none
    pid_limited: bool = True                         # pid = { limited = false }: no limit
    loop: object = None                              # decel_loop.LoopGains
    levels: int = 0                                  # command channel levels (0: analogue)


@dataclass(frozen=True)
class Fault:
    name: str
    parameters: dict
    speed_ratio: float = 1.0
    disturbance: dict | None = None
    axles: str | None = None       # axle-sensor states (module deceleration_loop)


@dataclass(frozen=True)
class StopAccuracySpec:
    path: str
    params: dict                   # name -> Quantity
    speeds_kmh: tuple[float, ...]
    tolerance: float
    c_max: float
    distance: float | None         # m, or None: from ``command``
    command: float | None          # m/s^2
    constants: dict                # name -> Quantity
    controllers: tuple[Controller, ...]
    factors: tuple[Factor, ...]
    faults: tuple[Fault, ...]
    dt: float
    dt_ctrl: float
    t_end: float
    montecarlo: object = None      # MonteCarloSpec
    convergence: bool = False
    grid: tuple = ()               # ((factor, (values, ...)), ...)
    reference: object = None       # modules.Reference ([reference])
    compensation: object = None    # modules.Compensation ([compensation])
    c_min: float = 0.0             # m/s^2: -traction_max (the law may call for traction)
    sections: object = None        # sections.Repeats ([[sections]], [repeats])
    grid_feasible: str | None = None   # [grid] feasible_with: the controller that decides
    analysis: str | None = None    # [analysis] module (a name: specs stay keyable)
    paper: object = None           # what that module read of the paper's own tables

    def base(self) -> dict:
        return {k: q.value for k, q in self.params.items()}


def _name(t: Reader, key: str, taken) -> str:
    from ..delay_feedback import NAME_PATTERN
    name = t.string(key)
    if not NAME_PATTERN.match(name) or name in taken:
        raise t.fail(key, name, "a new name of letters, digits and _ (not " + ", ".join(
            sorted(taken)) + ")")
    return name


def _constants(root: Reader, taken: set) -> dict:
    from ..delay_feedback.units import parse_unit
    out = {}
    if not root.has("constants"):
        return out
    t = root.table("constants")
    for k in list(t.data):
        if k in taken or not isinstance(t.data[k], dict):
            raise t.fail(k, t.data[k], "a new name with { value, unit, source }")
        sub = t.table(k)
        unit = sub.string("unit")
        parse_unit(unit, root.path, t.key(k) + ".unit")
        out[k] = Quantity(sub.number("value", lo=-1e12, hi=1e12), unit, sub.string("source"))
        sub.finish()
    t.finish()
    return out


def _controllers(root: Reader, names: set, constants) -> tuple[Controller, ...]:
    from ...expr import check_expression
    tables = root.tables("controllers")
    if not tables:
        raise root.fail("controllers", [], "at least one [[controllers]] table")
    out, seen = [], set()
    for t in tables:
        name = _name(t, "name", seen)
        seen.add(name)
        defs, known = [], set(names)
        dt = t.table("definitions", default=None)
        for k in list(dt.data):
            if k in known:
                raise dt.fail(k, dt.data[k], "a new name (not a law name or constant)")
            text = dt.raw(k)
            check_expression(text, known, path=root.path, key=dt.key(k))
            defs.append((k, text))
            known.add(k)
        dt.finish()
        smarc, law = None, None
        if t.has("smarc"):
            from .modules import read_smarc
            if t.has("law") or t.has("pid") or defs:
                raise t.fail("smarc", t.raw("smarc"), "a smarc table without law, "
                             "definitions or pid (the module is the whole law)")
            if "x_d" not in names:
                raise t.fail("smarc", t.raw("smarc"), "a [reference] for SMARC to track")
            smarc = read_smarc(t, constants)
        else:
            law = t.raw("law")
            check_expression(law, known, path=root.path, key=t.key("law"))
        limited = True
        comp = t.table("compensation", default=None)
        flags = (comp.boolean("predictor", default=False), comp.boolean("terminal", default=False),
                 comp.boolean("gain_correction", default=True))
        comp.finish()
        if (flags[0] or flags[1]) and not root.has("compensation"):
            raise t.fail("compensation", t.raw("compensation"), "a [compensation] table "
                         "(d_terminal, gain_tau, gain_bounds) for the predictor's model")
        pid = None
        loop = None
        if t.has("deceleration_loop"):
            from .decel_loop import read_loop
            if law is None or t.has("pid"):
                raise t.fail("deceleration_loop", t.raw("deceleration_loop"), "a law (the "
                             "target deceleration) and no pid (the loop has its own)")
            loop = read_loop(t, constants)
        levels = t.number("levels", default=None, integer=True, lo=1, hi=1024,
                          what="count of command levels above 0")
        levels = 0 if levels is None else int(levels)
        if t.has("pid"):
            pt = t.table("pid")
            err = pt.raw("error")
            check_expression(err, known, path=root.path, key=pt.key("error"))
            if not constants:
                raise pt.fail("kp", pt.raw("kp", None), "a constant of [constants] (none)")
            gains = tuple(pt.string(k, choices=sorted(constants)) for k in ("kp", "ki", "kd"))
            limited = pt.boolean("limited", default=True)
            pt.finish()
            pid = (err, *gains)
        t.finish()
        out.append(Controller(name, law, tuple(defs), pid, smarc, *flags, limited, loop,
                              levels))
    return tuple(out)


def _factors(root: Reader, params: dict) -> tuple[Factor, ...]:
    if not root.has("disturbances"):
        return ()
    t, out = root.table("disturbances"), []
    for k in list(t.data):
        sub = t.table(k)
        effect = sub.string("effect", choices=EFFECTS)
        ps = ()
        if effect == "scale":
            ps = sub.raw("parameters")
            if (not isinstance(ps, list) or not ps or any(p not in params for p in ps)
                    or len(set(ps)) < len(ps)):
                raise sub.fail("parameters", ps, "brake parameters of [plant], each once")
        unit = "permille" if effect == "gradient" else "1"
        out.append(Factor(k, effect, tuple(ps), sub.string("what", default=k), unit))
        sub.finish()
    t.finish()
    if sum(f.effect in ("force_error", "mass_ratio") for f in out) > 1:
        raise root.fail("disturbances", list(t.data), "at most one factor on the load-weighing "
                        "gain (force_error or mass_ratio)")
    if sum(f.effect == "gradient" for f in out) > 1:
        raise root.fail("disturbances", list(t.data), "at most one gradient factor")
    return tuple(out)


def _faults(root: Reader, params: dict, factors, controllers=()) -> tuple[Fault, ...]:
    out, seen = [], set()
    for t in root.tables("faults", default=[]):
        name = _name(t, "name", seen)
        seen.add(name)
        pt = t.table("parameters", default=None)
        over = {}
        for k in list(pt.data):
            if k not in params:
                raise pt.fail(k, pt.data[k], "a brake parameter of [plant]")
            over[k] = pt.number(k, nonneg=True, hi=1e6)
        pt.finish()
        dt = t.table("disturbance", default=None)
        dist = {}
        for k in list(dt.data):
            if k not in {f.name for f in factors}:
                raise dt.fail(k, dt.data[k], "a factor of [disturbances]")
            positive = next(f.positive for f in factors if f.name == k)
            dist[k] = dt.number(k, lo=-1e3, hi=1e3, positive=positive)
        dt.finish()
        ratio = t.number("speed_ratio", default=1.0, lo=0.0, hi=2.0)
        from .decel_loop import read_axles
        axles = read_axles(t, controllers)
        t.finish()
        out.append(Fault(name, over, ratio, dist, axles))
    return tuple(out)


def _grid(root: Reader, factors, controllers=()) -> tuple:
    """((factor, values), ...) of ``[grid]`` and its ``feasible_with`` (or None)."""
    if not root.has("grid"):
        return (), None
    t, out, corners = root.table("grid"), [], 1
    feasible = t.string("feasible_with", default=None, choices=[c.name for c in controllers])
    for k in list(t.data):
        if k == "feasible_with":
            continue
        if k not in {f.name for f in factors}:
            raise t.fail(k, t.data[k], "a factor of [disturbances]")
        positive = next(f.positive for f in factors if f.name == k)
        vals = t.numbers(k, lo=-1e3, hi=1e3, what="values")
        if not vals or len(set(vals)) < len(vals) or positive and min(vals) <= 0:
            raise t.fail(k, list(vals), "distinct values" + (" above 0 (a ratio)" if positive
                                                             else ""))
        effect = next(f.effect for f in factors if f.name == k)
        if effect == "force_error" and not all(abs(x) < 0.9 for x in vals):
            raise t.fail(k, list(vals), "force errors in (-0.9, 0.9) (kappa = 1 + error)")
        out.append((k, tuple(vals)))
        corners *= len(vals)
    t.finish()
    if not out or corners > 10000:
        raise root.fail("grid", {k: list(v) for k, v in out}, "1 to 10000 corners")
    return tuple(out), feasible


def _check_units(path: str, constants: dict, controllers, law_names=LAW_NAMES) -> None:
    """Every law in m/s^2 and every definition of consistent units (pint,
    :func:`workbench.kinds.delay_feedback.units.check_expression_units`)."""
    import sympy as sp
    from types import SimpleNamespace as NS

    from ...errors import DesignError
    from ...expr import parse_expression
    from ..delay_feedback.units import check_expression_units
    units = dict(law_names) | {k: q.unit for k, q in constants.items()} | {
        "brake_command": "m/s^2"}          # not a law name: the unit a law must have
    plant = NS(path=path, states=(), inputs=(),
               parameters={k: NS(unit=u) for k, u in units.items()})
    for i, c in enumerate(controllers):
        syms, items = {k: sp.Symbol(k, real=True) for k in units}, []
        for k, text in c.definitions:
            key = f"controllers[{i}].definitions.{k}"
            syms[k] = parse_expression(text, syms, path=path, key=key)
            items.append((key, text, syms[k], None))
        if c.law is not None:
            items.append((f"controllers[{i}].law", c.law,
                          parse_expression(c.law, syms, path=path, key=f"controllers[{i}].law"),
                          "brake_command"))
        if c.pid is not None:
            err, kp, ki, kd = c.pid
            key = f"controllers[{i}].pid.error"
            e = parse_expression(err, syms, path=path, key=key)
            items.append((key, err, e, None))
            t = syms["t"]
            for k, g, term in (("kp", kp, e), ("ki", ki, e * t), ("kd", kd, e / t)):
                items.append((f"controllers[{i}].pid.{k}", g, syms[g] * term, "brake_command"))
        for key, text, e, _ in items:
            if e.has(sp.I, sp.zoo, sp.oo, -sp.oo, sp.nan):
                raise DesignError(path, key, text, "a real, finite expression (this one has "
                                  "a complex, infinite or undefined constant)")
        check_expression_units(plant, items)


def paper_analysis(name: str):
    """The ``ANALYSIS`` object of the paper module ``name`` ("pNNN.name")."""
    import importlib
    return importlib.import_module(f"workbench.papers.{name}").ANALYSIS


class StopAccuracy:
    """The ``stop-accuracy`` study (see the module docstring)."""

    kind = "stop-accuracy"
    uses_solver = False
    #: numerical step of a design with [analysis], refined (dt/2, dt/4) for its findings
    refine_field, refine_unit = "dt", "s"

    def refines(self, spec: StopAccuracySpec) -> bool:
        """Whether ``spec``'s findings are run again at dt/2, dt/4 ([analysis])."""
        return spec.analysis is not None

    def load(self, root: Reader) -> StopAccuracySpec:
        from dataclasses import replace

        from ...reader import read_paper_module
        analysis = read_paper_module(root, paper_analysis, "a module of workbench.papers with "
                                     "an ANALYSIS object")
        spec = self._load(root)
        if analysis is None:
            return spec
        spec = replace(spec, analysis=analysis)
        return replace(spec, paper=paper_analysis(analysis).load(root, spec))

    def _load(self, root: Reader) -> StopAccuracySpec:
        from .modules import REFERENCE_NAMES, read_compensation, read_reference
        params = read_brake_plant(root)
        reference = read_reference(root)
        tg = root.table("target")
        tol = tg.quantity("tolerance", "m", positive=True, hi=10.0).value
        c_max = tg.quantity("c_max", "m/s^2", positive=True, hi=3.0).value
        traction = tg.quantity("traction_max", "m/s^2", positive=True, hi=3.0, default=None)
        dist = tg.quantity("distance", "m", positive=True, hi=1e5, default=None)
        cmd = tg.quantity("command", "m/s^2", positive=True, hi=3.0, default=None)
        if (dist is None) == (cmd is None) or reference is not None and dist is None:
            raise tg.fail("distance", None if dist is None else dist.value,
                          "the section length (m) with [reference]" if reference else
                          "exactly one of distance (m) and command (m/s^2)")
        if reference is None:
            speeds = tg.numbers("speeds_kmh", positive=True, what="speeds (km/h)")
            if not speeds or any(s > 400 for s in speeds) or len(set(speeds)) < len(speeds):
                raise tg.fail("speeds_kmh", list(speeds), "distinct speeds in (0, 400] km/h")
        elif tg.has("speeds_kmh"):
            raise tg.fail("speeds_kmh", tg.raw("speeds_kmh"), "no speeds with [reference] "
                          "(a run starts where the target starts braking)")
        else:
            speeds = (reference.start(dist.value)[1] * 3.6,)
        tg.finish()
        law_names = LAW_NAMES | (REFERENCE_NAMES if reference else {})
        constants = _constants(root, set(law_names) | {"brake_command"})
        controllers = _controllers(root, set(law_names) | set(constants), constants)
        compensation = read_compensation(root)
        factors = _factors(root, params)
        faults = _faults(root, params, factors, controllers)
        from .sections import read_sections
        sections = read_sections(root, factors, reference, controllers)
        mc = None
        if root.has("montecarlo"):
            if not factors:
                raise root.fail("disturbances", None, "the factors [montecarlo] draws")
            from ...features.montecarlo import load_montecarlo
            mc = load_montecarlo(root, {f.name: f.positive for f in factors}, max_samples=5000)
            work = mc.samples * len(speeds) * len(controllers)
            if work > MAX_RUNS:
                raise root.fail("montecarlo.samples", mc.samples, f"at most {MAX_RUNS} runs in "
                                f"all (samples x speeds x controllers = {work})")
        grid, feasible = _grid(root, factors, controllers)
        convergence = root.has("convergence")
        if convergence:
            root.table("convergence").finish()
        sim = root.table("sim")
        dt = sim.number("dt", positive=True, hi=0.05, what="step (s)")
        dt_ctrl = sim.number("dt_ctrl", positive=True, hi=1.0, what="control period (s)")
        k = dt_ctrl / dt
        if abs(k - round(k)) > 1e-9 * k:
            raise sim.fail("dt_ctrl", dt_ctrl, f"a whole multiple of dt = {dt:g} s")
        t_end = sim.number("t_end", positive=True, hi=3600.0, what="horizon (s)")
        if t_end / dt * (4 if convergence else 1) > 2_000_000:
            raise sim.fail("t_end", t_end, "at most 2e6 steps (at dt/4 with [convergence])")
        sim.finish()
        if mc is not None and mc.samples * len(speeds) * len(controllers) * t_end / dt > MAX_WORK:
            raise root.fail("montecarlo.samples", mc.samples, f"at most {MAX_WORK:g} runs x "
                            "steps (a Monte Carlo of hours is a study, not a check)")
        if sections is not None:
            runs = len(sections.sections) * sections.count * len(
                sections.controllers or controllers)
            if runs > MAX_RUNS or runs * t_end / dt > MAX_WORK:
                raise root.fail("repeats.count", sections.count, f"at most {MAX_RUNS} runs and "
                                f"{MAX_WORK:g} runs x steps (sections x count x controllers = "
                                f"{runs})")
        _check_units(root.path, constants, controllers, law_names)
        return StopAccuracySpec(root.path, params, tuple(speeds), tol, c_max,
                                None if dist is None else dist.value,
                                None if cmd is None else cmd.value, constants, controllers,
                                factors, faults, dt, dt_ctrl, t_end, mc, convergence, grid,
                                reference, compensation,
                                0.0 if traction is None else -traction.value, sections,
                                feasible)

    def quantity_names(self, spec: StopAccuracySpec) -> set[str]:
        from ...features.quantities import names
        from .quantities import TABLE
        if spec.analysis is not None:
            return paper_analysis(spec.analysis).quantity_names(spec)
        return names(TABLE, spec)

    def quantity_units(self, spec: StopAccuracySpec) -> dict[str, str]:
        from ...features.quantities import units
        from .quantities import TABLE
        if spec.analysis is not None:   # a paper's module declares its own (or none)
            return getattr(paper_analysis(spec.analysis), "quantity_units", lambda _: {})(spec)
        return units(TABLE, spec)

    def run(self, design):
        from .run import run
        if design.spec.analysis is not None:
            return paper_analysis(design.spec.analysis).run(design.spec)
        return run(design.spec, design.claims)

    def quantities(self, res) -> dict:
        from ...features.quantities import values
        from .quantities import TABLE
        if res.spec.analysis is not None:
            return paper_analysis(res.spec.analysis).quantities(res)
        return values(TABLE, res.spec, res)

    def unconverged(self, res) -> dict[str, str]:
        """claim id -> reason, for the claims on a stop error that did not
        converge over dt, dt/2, dt/4 (``[convergence]``)."""
        if res.spec.analysis is not None:   # refined by running again (refine_field)
            return {}
        return {r.claim_id: r.reason for r in res.refinement if not r.converged}


STUDY = StopAccuracy()
