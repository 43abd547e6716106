"""Study ``delay-feedback``: the user's own plant, written as text equations,
through the whole pipeline.

A design declares states, inputs and parameters (each with unit and source),
the nonlinear plant x_i' = f_i(x, u, p) as safe text expressions
(:mod:`workbench.expr`: parsed with :mod:`ast` against a whitelist, never
evaluated), an operating point (given, or solved from f = 0 within stated
ranges), the input delay (constant or a range), the synthesis (paper 003's
free-weighting problem (60) over eps, or the Wirtinger synthesis with a
Bessel-Legendre order-N check of its gain), optionally polytope vertices for
a robust gain, simulation scenarios and claims. The pipeline:
Jacobians -> A, B -> certified delay bound with the canonical gain -> exact
margin and stability windows -> nonlinear closed-loop simulation with the
delay at dt and dt/2 -> claims -> report.

Tables (see ``designs/antiskid-cruise-dry-generic.toml`` for a full file)::

    [states]       name = { unit, source, description }
    [inputs]       name = { unit, source, description }
    [parameters]   name = { value, unit, source }
    [definitions]  name = "expression"          (optional, in order)
    [equations]    state = "expression"         (one per state)
    [operating_point]  name = { value, unit, source } | { solve = [lo, hi], guess };
                   trim = false: a given point need not be an equilibrium
    [delay]        h = { value, unit = "s", source } | min = {...}, max = {...}
    [synthesis]    method = "free-weighting-003" | "wirtinger" | "bessel-legendre"
    [[vertices]]   name, source, parameter = value ...   (optional: robust gain)
    [[scenarios]]  name, t_end, dt, x0 = {...}, setpoint = {...}, h, rtol, predictor,
                   parameters = { p = [[t, value], ...] }  (piecewise-constant schedule;
                   adds the signed min_error.<state> metric),
                   plot = ["definition", ...] (extra panels of the figure),
                   lines = { name = { value, label } } (reference line on a panel)
    [basin]        enabled, domain = {...}, plane, seed     (optional: region of attraction,
                   :mod:`workbench.features.basin`)
    [implementation] sampling, network_delay, hold   (optional: digital implementation,
                   :mod:`workbench.features.sampled`)
    [montecarlo]   samples, seed, distributions   (optional: the scenarios with drawn
                   plant parameters, :mod:`.montecarlo`)
    [convergence]  (no keys; optional: every scenario also at dt/4, and every claim on
                   a scenario metric refined over dt, dt/2, dt/4,
                   :mod:`workbench.features.convergence`)
    [[synthesis.published]] eps, h_m, K, source; [[other_gains]] name, K, source;
                   [eps_sweep] (no keys)   (optional: printed rows vs ours, gains designed
                   elsewhere on this loop, the eps sweep's table and figures; :mod:`.gain_tables`)

The design tables are read here (light: no sympy until the operating point
is solved); :mod:`.run` computes, :mod:`.render` renders.
"""
from __future__ import annotations

import keyword
import re
from dataclasses import dataclass

from ...reader import Reader
from .spec import OperatingEntry, PlantSpec, Variable

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
METHODS = ("free-weighting-003", "wirtinger", "bessel-legendre")
#: Metrics of every scenario (per state / input where marked).
SIM_METRICS = ("peak_error", "final_error", "peak_input_dev", "diverged")


@dataclass(frozen=True)
class DelaySpec:
    """Input delay: constant (h_min = h_max) or a range, in seconds."""

    h_min: float
    h_max: float
    source: str

    @property
    def constant(self) -> bool:
        return self.h_min == self.h_max


@dataclass(frozen=True)
class SynthesisChoice:
    """``[synthesis]``: method, eps (problem 60) or grid (Wirtinger), N, settings."""

    method: str
    eps: tuple[float, ...]
    grid: tuple[float, ...]
    order: int
    settings: object   # workbench.synthesis.SynthesisSettings
    decay_rate: float = 0.0   # 1/s, robust-descriptor only
    published: tuple = ()     # [[synthesis.published]] (.gain_tables)


@dataclass(frozen=True)
class Vertex:
    """A polytope vertex: parameter overrides (SI values of the design's units)."""

    name: str
    values: dict
    source: str


@dataclass(frozen=True)
class Scenario:
    """A simulation: absolute initial state, piecewise-constant set-points."""

    name: str
    x0: dict
    setpoint: dict          # state -> ((t, value), ...)
    t_end: float
    dt: float
    h: float
    rtol: float
    predictor: bool = False
    parameters: dict = None  # parameter -> ((t, value), ...): piecewise-constant schedule
    plot: tuple = ()         # definitions drawn as extra panels (issue 33, item 7)
    lines: dict = None       # state or plotted definition -> (value, label): reference line


@dataclass(frozen=True)
class DelayFeedbackSpec:
    plant: PlantSpec
    delay: DelaySpec
    synthesis: SynthesisChoice
    vertices: tuple[Vertex, ...]
    scenarios: tuple[Scenario, ...]
    window_horizon: float
    basin: object = None     # delay_feedback_basin.BasinSettings or None ([basin] table)
    requirements: object = None   # delay_feedback_requirements.RequirementsSpec or None
    implementation: object = None   # delay_feedback_implementation.ImplementationSettings
    montecarlo: object = None   # features.montecarlo.MonteCarloSpec ([montecarlo], .montecarlo)
    convergence: bool = False   # [convergence]: dt, dt/2, dt/4 (features.convergence)
    claims: tuple = ()          # ClaimTarget (features.convergence) per claim on a scenario metric
    gain_tables: object = None  # .gain_tables.GainTables (printed rows, other gains, eps sweep)


def _variables(root: Reader, table: str, taken: set[str], min_len: int = 1
               ) -> tuple[Variable, ...]:
    t = root.table(table)
    if len(t.data) < min_len:
        raise root.fail(table, t.data, f"a table of at least {min_len} entries")
    out = []
    for name in list(t.data):
        _check_name(t, name, taken)
        v = t.table(name)
        out.append(Variable(name, v.string("unit"), v.string("source"),
                            v.string("description", default="")))
        v.finish()
    t.finish()
    return tuple(out)


def _check_name(t: Reader, name: str, taken: set[str]) -> None:
    from ...expr import FUNCTIONS
    if not _NAME.match(name) or keyword.iskeyword(name) or name.startswith("__"):
        raise t.fail(name, "<name>", "a name of letters, digits and _ starting with a letter "
                     "(not a Python keyword)")
    if name in FUNCTIONS:
        raise t.fail(name, "<name>", "a name that is not a function (" + ", ".join(FUNCTIONS)
                     + ")")
    if name in taken:
        raise t.fail(name, "<name>", "a name not already declared")
    taken.add(name)


def _plant(root: Reader, *, operating_point: bool = True) -> PlantSpec:
    """The plant tables; ``operating_point=False``: a kind that simulates only
    (``switched-run``) reads no ``[operating_point]``."""
    from ...expr import check_expression
    taken: set[str] = set()
    states = _variables(root, "states", taken)
    inputs = _variables(root, "inputs", taken)
    pt = root.table("parameters", default=None)     # a plant may have none
    params = {}
    for name in list(pt.data):
        _check_name(pt, name, taken)
        q = pt.raw(name)
        unit = q.get("unit") if isinstance(q, dict) else None
        params[name] = pt.quantity(name, unit if isinstance(unit, str) else "<unit>")
    pt.finish()
    defs = []
    dt_ = root.table("definitions", default=None)
    for name in list(dt_.data):
        _check_name(dt_, name, taken)
        defs.append((name, dt_.raw(name)))
    dt_.finish()
    # a definition may use the states, inputs, parameters and earlier definitions
    seen = {v.name for v in states + inputs} | set(params)
    for name, text in defs:
        check_expression(text, seen, path=root.path, key=f"definitions.{name}")
        seen.add(name)
    eq = root.table("equations")
    texts = []
    for s in states:
        text = eq.raw(s.name)
        check_expression(text, taken, path=root.path, key=eq.key(s.name))
        texts.append(text)
    eq.finish()
    if not operating_point:
        return PlantSpec(root.path, states, inputs, params, tuple(defs), tuple(texts))
    op = root.table("operating_point")
    entries = []
    for v in states + inputs:
        e = op.table(v.name)
        if e.has("solve"):
            lo, hi = e.numbers("solve", min_len=2, what="range ends")
            if len(e.data["solve"]) != 2 or not lo < hi:
                raise e.fail("solve", e.data["solve"], "a range [lo, hi] with lo < hi")
            guess = e.number("guess", default=None, lo=lo, hi=hi)
            entries.append(OperatingEntry(v.name, None, lo, hi, guess, e.string("source",
                                                                                  default="")))
        else:
            val = e.number("value", what=f"number ({v.unit})")
            u = e.string("unit")
            if u != v.unit:
                raise e.fail("unit", u, f'"{v.unit}" (the unit declared for {v.name})')
            entries.append(OperatingEntry(v.name, val, source=e.string("source")))
        e.finish()
    trim = op.boolean("trim", default=True)
    op.finish()
    n_solved = sum(e.solved for e in entries)
    if n_solved not in (0, len(states)):
        raise root.fail("operating_point", f"<{n_solved} solved>",
                        f"as many entries with solve = [lo, hi] as equations ({len(states)}), "
                        "or none (a given point)")
    return PlantSpec(root.path, states, inputs, params, tuple(defs), tuple(texts),
                     tuple(entries), trim)


#: The plant tables' reader and the name pattern, shared with ``switched-run``.
read_plant, NAME_PATTERN = _plant, _NAME


def _delay(root: Reader) -> DelaySpec:
    d = root.table("delay")
    if d.has("h"):
        q = d.quantity("h", "s", positive=True, hi=1e3)
        d.finish()
        return DelaySpec(q.value, q.value, q.source)
    lo = d.quantity("min", "s", positive=True, hi=1e3)
    hi = d.quantity("max", "s", positive=True, hi=1e3)
    if not lo.value < hi.value:
        raise d.fail("max", hi.value, f"a delay larger than delay.min = {lo.value:g} s")
    d.finish()
    return DelaySpec(lo.value, hi.value, lo.source if lo.source == hi.source
                     else f"{lo.source}; {hi.source}")


def _synthesis(root: Reader, delay: DelaySpec, n: int) -> SynthesisChoice:
    from ...features.eps_sweep import read_eps, read_grid, read_settings
    req = root.has("requirements")
    s = root.table("synthesis", default=None) if req else root.table("synthesis")
    method = s.string("method", choices=METHODS + ("robust-descriptor", "requirements"),
                      **({"default": "requirements"} if req else {}))
    if (method == "requirements") != req:
        raise s.fail("method", method, '"requirements" exactly when [requirements] is given')
    if method != "requirements" and (method == "robust-descriptor") != root.has("vertices"):
        raise s.fail("method", method, '"robust-descriptor" exactly when [[vertices]] are given')
    eps = grid = ()
    if method == "free-weighting-003":
        eps = read_eps(s)
    elif method != "requirements":
        grid = read_grid(s)
    order = int(s.number("order", default=2, integer=True, lo=0, hi=8, what="integer N"))
    alpha = 0.0
    if method == "robust-descriptor":
        alpha = s.number("decay_rate", default=0.0, nonneg=True, hi=10.0,
                         what="decay rate (1/s)")
    settings = read_settings(s, rel_tol=1e-4 if method == METHODS[0] else 1e-3,
                             h_max=max(100.0 if method == METHODS[0] else 10.0,
                                       4 * delay.h_max))
    if settings.h_max < delay.h_max:
        raise s.fail("h_max", settings.h_max, f"a search cap at least the design's delay, "
                     f"delay.max = {delay.h_max:g} s")
    from ...features.published_rows import load_published
    published = load_published(s, n)
    s.finish()
    return SynthesisChoice(method, eps, grid, order, settings, alpha, published)


def _vertices(root: Reader, plant: PlantSpec) -> tuple[Vertex, ...]:
    out = []
    for v in root.tables("vertices", default=[]):
        name = v.string("name")
        values = {}
        for k in list(v.data):
            if k in ("name", "source"):
                continue
            if k not in plant.parameters:
                raise v.fail(k, v.data[k], "a parameter of [parameters] (or name, source)")
            values[k] = v.number(k, what=f"number ({plant.parameters[k].unit})")
        out.append(Vertex(name, values, v.string("source")))
        v.finish()
    if len(out) == 1:
        raise root.fail("vertices", "<1 vertex>", "two or more vertices (or none)")
    return tuple(out)


def _scenarios(root: Reader, plant: PlantSpec, delay: DelaySpec) -> tuple[Scenario, ...]:
    out, names = [], set()
    states = plant.state_names
    for r in root.tables("scenarios", default=[]):
        name = r.string("name")
        if not _NAME.match(name) or name in names:
            raise r.fail("name", name, "a new name of letters, digits and _")
        names.add(name)
        x0t = r.table("x0", default=None)
        x0 = {}
        for k in list(x0t.data):
            if k not in states:
                raise x0t.fail(k, x0t.data[k], "a state: " + ", ".join(states))
            x0[k] = x0t.number(k, lo=-1e12, hi=1e12)
        x0t.finish()
        spt = r.table("setpoint", default=None)
        sp = {}
        for k in list(spt.data):
            if k not in states:
                raise spt.fail(k, spt.data[k], "a state: " + ", ".join(states))
            steps = spt.raw(k)
            ok = (isinstance(steps, list) and steps and all(
                isinstance(p, list) and len(p) == 2 and all(
                    isinstance(z, (int, float)) and not isinstance(z, bool) for z in p)
                for p in steps))
            times = [p[0] for p in steps] if ok else []
            if not ok or times != sorted(times) or times[0] != 0:
                raise spt.fail(k, steps, "a list of [t (s), value] pairs, times increasing "
                               "from 0")
            sp[k] = tuple((float(t), float(v)) for t, v in steps)
        spt.finish()
        t_end = r.number("t_end", positive=True, hi=1e5, what="number (s)")
        dt = r.number("dt", positive=True, hi=t_end / 10, what="number (s)")
        if t_end / dt > 2e6:
            raise r.fail("dt", dt, "at most 2e6 steps over t_end")
        h = r.number("h", default=delay.h_max, positive=True, hi=t_end, what="number (s)")
        rtol = r.number("rtol", default=1e-3, positive=True, hi=0.5)
        predictor = r.boolean("predictor", default=False)
        pt = r.table("parameters", default=None)
        sched = {}
        for k in list(pt.data):
            if k not in plant.parameters:
                raise pt.fail(k, pt.data[k], "a parameter of [parameters]")
            sched[k] = _steps(pt, k, t_end)
        pt.finish()
        plot, lines = _figure_keys(r, plant)
        if plot and sched:      # a definition is drawn with the nominal parameter values
            raise r.fail("plot", list(plot), "no plotted definition in a scenario with a "
                         "parameter schedule (definitions are drawn at the nominal values)")
        r.finish()
        out.append(Scenario(name, x0, sp, t_end, dt, h, rtol, predictor, sched or None,
                            plot, lines or None))
    return tuple(out)


def _figure_keys(r: Reader, plant: PlantSpec) -> tuple[tuple[str, ...], dict]:
    """A scenario's ``plot`` (definitions drawn as extra panels) and ``lines``
    (a labelled reference value on a state's or a plotted definition's panel)."""
    defs = [n for n, _ in plant.definitions]
    plot = r.raw("plot", default=[])
    if (not isinstance(plot, list) or len(set(map(str, plot))) != len(plot)
            or any(not isinstance(n, str) or n not in defs for n in plot)):
        raise r.fail("plot", plot, "a list of distinct names of [definitions]: "
                     + (", ".join(defs) or "(none)"))
    lt = r.table("lines", default=None)
    lines = {}
    for k in list(lt.data):
        if k not in plant.state_names and k not in plot:
            raise lt.fail(k, lt.data[k], "a state or a name of `plot`")
        one = lt.table(k)
        lines[k] = (one.number("value", lo=-1e12, hi=1e12), one.string("label"))
        one.finish()
    lt.finish()
    return tuple(plot), lines


def _steps(t: Reader, k: str, t_end: float) -> tuple[tuple[float, float], ...]:
    """A list of [t (s), value] pairs, times increasing from 0 (a schedule)."""
    steps = t.raw(k)
    ok = (isinstance(steps, list) and steps and all(
        isinstance(p, list) and len(p) == 2 and all(
            isinstance(z, (int, float)) and not isinstance(z, bool) and abs(z) < 1e12
            for z in p) for p in steps))
    times = [p[0] for p in steps] if ok else []
    if not ok or any(b <= a for a, b in zip(times, times[1:])) or times[0] != 0 \
            or times[-1] > t_end:
        raise t.fail(k, steps, "a list of [t (s), value] pairs, times increasing from 0 to "
                     "at most t_end")
    return tuple((float(a), float(b)) for a, b in steps)


def scenario_metrics(plant: PlantSpec, scenario: Scenario) -> set[str]:
    """The numeric metrics of a scenario (``simulation.<scenario>.<metric>``)."""
    out = {f"{m}.{k}" for m in ("peak_error", "final_error") for k in plant.state_names}
    if scenario.parameters:
        out |= {f"min_error.{k}" for k in plant.state_names}
    return out | {f"peak_input_dev.{u}" for u in plant.input_names}


#: Most integration steps of the finest ([convergence]: dt/4) run of a scenario.
MAX_FINE_STEPS = 4e6


def _with_convergence(root: Reader, spec: DelayFeedbackSpec) -> DelayFeedbackSpec:
    """The spec with ``[convergence]`` and the claims it refines
    (:mod:`workbench.features.convergence`)."""
    from dataclasses import replace

    from ...features.convergence import claim_targets, load_convergence
    if not load_convergence(root):
        return spec
    for i, s in enumerate(spec.scenarios):
        if 4 * s.t_end / s.dt > MAX_FINE_STEPS:
            raise root.fail(f"scenarios[{i}].dt", s.dt, f"at most {MAX_FINE_STEPS / 4:g} "
                            "steps over t_end with [convergence] (it runs dt/4 too)")
    by_name = {s.name: s for s in spec.scenarios}
    claims = claim_targets(root, "simulation.", lambda n: scenario_metrics(
        spec.plant, by_name[n]) if n in by_name else set())
    return replace(spec, convergence=True, claims=claims)


class DelayFeedback:
    """The ``delay-feedback`` study (see the module docstring)."""

    kind = "delay-feedback"

    def load(self, root: Reader) -> DelayFeedbackSpec:
        plant = _plant(root)
        delay = _delay(root)
        syn = _synthesis(root, delay, len(plant.states))
        vertices = _vertices(root, plant)
        scenarios = _scenarios(root, plant, delay)
        ex = root.table("exact", default=None)
        horizon = ex.number("window_horizon", default=max(4 * delay.h_max, 1.0),
                            positive=True, hi=1e4, what="number (s)")
        ex.finish()
        from ...features.basin import check_domain, load_basin_settings
        basin = load_basin_settings(root, plant, len(scenarios))
        from .requirements import load_requirements
        req = load_requirements(root, plant, delay)
        from ...features.sampled import load_implementation_settings
        from .gain_tables import load_gain_tables
        from .montecarlo import load_montecarlo_table
        spec = DelayFeedbackSpec(plant, delay, syn, vertices, scenarios, horizon, basin, req,
                                 load_implementation_settings(root),
                                 load_montecarlo_table(root, plant),
                                 gain_tables=load_gain_tables(root, plant, syn))
        spec = _with_convergence(root, spec)
        from .model import PlantModel
        from .run import nominal_point
        from .units import check_units, physical_ranges
        physical_ranges(spec)      # times and masses positive, before any solve
        check_units(PlantModel(plant))
        op = nominal_point(spec)[2]  # no operating point in range is bad input: fail now
        for v in vertices:
            nominal_point(spec, v)
        if basin is not None:
            check_domain(basin, root.path, plant.state_names, op.x, scenarios)
        return spec

    def quantity_names(self, spec: DelayFeedbackSpec) -> set[str]:
        from ...features.quantities import names
        from .quantities import TABLE
        return names(TABLE, spec)

    def quantity_units(self, spec: DelayFeedbackSpec) -> dict[str, str]:
        """name -> unit of every claimable quantity (:mod:`.quantities`)."""
        from ...features.quantities import units
        from .quantities import TABLE
        return units(TABLE, spec)

    def run(self, design):
        from .run import run
        return run(design.spec)

    def quantities(self, res) -> dict:
        from .run import quantities
        return quantities(res)

    def unconverged(self, res) -> dict[str, str]:
        """claim id -> reason, for the claims whose metric did not converge
        over dt, dt/2, dt/4 (``[convergence]``; used by :mod:`workbench.verify`)."""
        from ...features.convergence import unconverged
        return unconverged(res.refinement)


STUDY = DelayFeedback()
