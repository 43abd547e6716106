"""Study ``switched-run``: a plant written as text equations, driven by named
phases, each with its own control law, switch guards, an optional predictor
over a constant input delay, and scenarios (issue 35, item 1).

The plant tables are those of ``delay-feedback`` (read by its own reader,
:func:`workbench.kinds.delay_feedback.read_plant`, without an operating point);
everything is parsed by :mod:`workbench.expr` (:mod:`ast` against a
whitelist, never evaluated) and unit-checked with pint
(:func:`workbench.kinds.delay_feedback.units.check_units`).

Tables::

    [states] [inputs] [parameters] [definitions] [equations]   (as delay-feedback)
    [delay]       h = { value, unit = "s", source }  (>= 0, a multiple of every dt),
                  predictor = true | false  (the law sees x predicted h ahead)
    [[phases]]    name, law = { input = "expression" } (one per input),
                  next = [{ to = "phase", when = "expression" }]   (switch when >= 0;
                  the first that holds, in order), terminal = true, until = "expression"
    [[scenarios]] name, x0 = { state = value } (every state), t_end, dt, phase (initial),
                  parameters = { p = value } (overrides), target = { state = value },
                  max_switch_rate (1/s, default 10: more switches within 1 s is chattering)
    [comfort]     speed = "state"          (optional: peak |acceleration| and |jerk|),
                  a_max, jerk_max = { value, unit = speed unit / s, / s^2, source }
                  (optional: the time above each; :mod:`workbench.features.comfort`)
    [montecarlo]  samples, seed, distributions = { parameter = { dist = ... } }
    [sampled]     period (s, a multiple of dt), quantisation = { state = step }
    [convergence] (no keys: every scenario metric at dt, dt/2, dt/4)

Laws, guards and ``until`` use states, parameters and the definitions that
do not depend on an input. The controller (laws, guards, predictor) uses the
design's parameter values with the scenario's overrides; Monte Carlo draws
change the plant only (the controller does not know them).

The design tables are read here (light: no sympy, no numpy);
:mod:`.simulate` runs, :mod:`.study` assembles, :mod:`.render` renders.
"""
from __future__ import annotations

import ast
from dataclasses import dataclass

from ...reader import Reader
from ...features.convergence import LEVELS, ClaimTarget, claim_targets, load_convergence
from ...features.quantities import DeclaredQuantities
from ...features.spec_readers import keyed_numbers, named_tables
from ..delay_feedback import NAME_PATTERN as _NAME
from ..delay_feedback import read_plant
from ..delay_feedback.spec import PlantSpec
from .quantities import TABLE

__all__ = ["Phase", "Scenario", "SwitchedRunSpec", "STUDY", "MAX_STEPS", "whole_steps"]

#: Most integration steps of one run (t_end / dt, at the finest level).
MAX_STEPS = 2_000_000
#: Most Monte Carlo runs times steps (one batch).
MAX_WORK = 2e9


@dataclass(frozen=True)
class Phase:
    """A named phase: a law per input, guards, and whether the run may end there."""

    name: str
    law: tuple[str, ...]                 # expression per input, in input order
    next: tuple[tuple[str, str], ...]    # (to, when)
    terminal: bool = False
    until: str | None = None


@dataclass(frozen=True)
class Scenario:
    """One run: initial state, horizon, step, initial phase, overrides, targets."""

    name: str
    x0: tuple[float, ...]
    t_end: float
    dt: float
    phase: str
    parameters: dict
    target: dict
    max_switch_rate: float = 10.0


@dataclass(frozen=True)
class SampledSpec:
    """``[sampled]``: control period (s) and quantisation step per state."""

    period: float
    quantisation: dict


@dataclass(frozen=True)
class SwitchedRunSpec:
    plant: PlantSpec
    h: float
    h_source: str
    predictor: bool
    phases: tuple[Phase, ...]
    scenarios: tuple[Scenario, ...]
    speed: str | None = None
    montecarlo: object = None          # workbench.features.montecarlo.MonteCarloSpec
    sampled: SampledSpec | None = None
    convergence: bool = False
    claims: tuple[ClaimTarget, ...] = ()
    usable: tuple[str, ...] = ()       # definitions a law may use (no input in them)
    comfort: object = None             # workbench.features.comfort.ComfortLimits ([comfort])


def _names_in(tree) -> set[str]:
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}


def _controller_names(plant: PlantSpec) -> tuple[set[str], tuple[str, ...]]:
    """Names a law or guard may use: states, parameters and the definitions
    free of inputs (a definition using an input cannot be a controller's)."""
    from ...expr import check_expression
    inputs = set(plant.input_names)
    uses_input: set[str] = set()
    for name, text in plant.definitions:
        used = _names_in(check_expression(text, _all(plant), path=plant.path, key=name))
        if used & (inputs | uses_input):
            uses_input.add(name)
    usable = tuple(n for n, _ in plant.definitions if n not in uses_input)
    return set(plant.state_names) | set(plant.parameters) | set(usable), usable


def _all(plant: PlantSpec) -> set[str]:
    return (set(plant.state_names) | set(plant.input_names) | set(plant.parameters)
            | {n for n, _ in plant.definitions})


def _phases(root: Reader, plant: PlantSpec, names: set[str]) -> tuple[Phase, ...]:
    from ...expr import check_expression
    named = named_tables(root, "phases", _NAME)   # every name first: a guard may point ahead
    known, out = [name for _, name in named], []
    for t, name in named:
        lt = t.table("law")
        laws = []
        for u in plant.input_names:
            text = lt.raw(u)
            check_expression(text, names, path=root.path, key=lt.key(u))
            laws.append(text)
        lt.finish()
        nxt = []
        for g in t.tables("next", default=[]):
            to = g.string("to")
            if to not in known or to == name:
                raise g.fail("to", to, "another phase: " + ", ".join(
                    str(k) for k in known if k != name))
            nxt.append((to, g.raw("when")))
            check_expression(nxt[-1][1], names, path=root.path, key=g.key("when"))
            g.finish()
        terminal = t.boolean("terminal", default=False)
        until = None
        if terminal:
            until = t.raw("until")
            check_expression(until, names, path=root.path, key=t.key("until"))
        t.finish()
        out.append(Phase(name, tuple(laws), tuple(nxt), terminal, until))
    return tuple(out)


def whole_steps(value: float, dt: float) -> bool:
    """``value`` is a whole number (>= 1) of steps ``dt`` (to 1e-9 relative)."""
    k = value / dt
    return round(k) >= 1 and abs(k - round(k)) <= 1e-9 * max(k, 1.0)   # 1e-300 s: 0 steps


def _multiple(r: Reader, key: str, value: float, dt: float, what: str) -> None:
    if not whole_steps(value, dt):
        raise r.fail(key, dt, f"a step of which {what} is a whole multiple (>= 1) "
                     f"(found {value / dt:.6g} steps)")


def _scenarios(root: Reader, spec_plant: PlantSpec, phases, h: float, convergence: bool,
               sampled) -> tuple[Scenario, ...]:
    out = []
    states, phase_names = spec_plant.state_names, [p.name for p in phases]
    finest = 2 ** LEVELS[-1] if convergence else 1
    for r, name in named_tables(root, "scenarios", _NAME):
        xt = r.table("x0")
        x0 = []
        for s in states:
            x0.append(xt.number(s, lo=-1e12, hi=1e12, what=f"number ({s})"))
        xt.finish()
        t_end = r.number("t_end", positive=True, hi=1e5, what="number (s)")
        dt = r.number("dt", positive=True, hi=t_end / 10, what="number (s)")
        if t_end / dt * finest > MAX_STEPS:
            raise r.fail("dt", dt, f"at most {MAX_STEPS:g} steps over t_end"
                         + (" at dt/4 ([convergence])" if convergence else ""))
        if h:          # a multiple of dt is one of dt/2 and dt/4 too ([convergence])
            _multiple(r, "dt", h, dt, f"the delay h = {h:g} s")
        if sampled is not None:
            _multiple(r, "dt", sampled.period, dt, f"the control period {sampled.period:g} s")
        phase = r.string("phase", choices=phase_names)
        over = keyed_numbers(r.table("parameters", default=None), spec_plant.parameters,
                              "a parameter of [parameters]", lo=-1e15, hi=1e15)
        target = keyed_numbers(r.table("target", default=None), states,
                                "a state: " + ", ".join(states), lo=-1e12, hi=1e12)
        rate = r.number("max_switch_rate", default=10.0, positive=True, hi=1e6,
                        what="number of switches per second")
        r.finish()
        out.append(Scenario(name, tuple(x0), t_end, dt, phase, over, target, rate))
    return tuple(out)


def _sampled(root: Reader, plant: PlantSpec) -> SampledSpec | None:
    if not root.has("sampled"):
        return None
    t = root.table("sampled")
    period = t.number("period", positive=True, hi=1e3, what="control period (s)")
    q = keyed_numbers(t.table("quantisation", default=None), plant.state_names,
                       "a state: " + ", ".join(plant.state_names), positive=True, hi=1e12,
                       what="quantisation step")
    t.finish()
    return SampledSpec(period, q)


def _check_law_units(plant: PlantSpec, model, phases, usable) -> None:
    """Each law in its input's unit; guards and ``until`` of consistent units
    (pint, :func:`workbench.kinds.delay_feedback.units.check_expression_units`)."""
    from ...expr import parse_expression
    from ..delay_feedback.units import check_expression_units
    names = dict(zip(plant.state_names, model.x)) | dict(model.p)
    names |= {k: model.definitions[k] for k in usable}
    items = []
    for i, ph in enumerate(phases):
        texts = [(f"phases[{i}].law.{u}", t, u) for u, t in zip(plant.input_names, ph.law)]
        texts += [(f"phases[{i}].next[{j}].when", w, None) for j, (_, w) in enumerate(ph.next)]
        texts += [(f"phases[{i}].until", ph.until, None)] if ph.terminal else []
        items += [(key, t, parse_expression(t, names, path=plant.path, key=key), want)
                  for key, t, want in texts]
    check_expression_units(plant, items)


class SwitchedRun(DeclaredQuantities):
    """The ``switched-run`` study (see the module docstring); its claimable
    quantities are :data:`.quantities.TABLE`."""

    kind = "switched-run"
    TABLE = TABLE
    uses_solver = False

    def load(self, root: Reader) -> SwitchedRunSpec:
        plant = read_plant(root, operating_point=False)
        names, usable = _controller_names(plant)
        d = root.table("delay")
        hq = d.quantity("h", "s", nonneg=True, hi=1e3)
        predictor = d.boolean("predictor", default=False)
        d.finish()
        if predictor and not hq.value > 0:
            raise root.fail("delay.predictor", True, "false when h = 0 (nothing to predict)")
        phases = _phases(root, plant, names)
        sampled = _sampled(root, plant)
        convergence = load_convergence(root)
        scenarios = _scenarios(root, plant, phases, hq.value, convergence, sampled)
        speed = comfort = None
        if root.has("comfort"):
            from ...features.comfort import read_limits
            ct = root.table("comfort")
            speed = ct.string("speed", choices=plant.state_names)
            unit = next(v.unit for v in plant.states if v.name == speed)
            comfort = read_limits(ct, unit, required=False, window=False)
            ct.finish()
        mc = None
        if root.has("montecarlo"):
            from ...features.montecarlo import load_montecarlo
            mc = load_montecarlo(root, {k: False for k in plant.parameters}, max_samples=5000)
            steps = max(s.t_end / s.dt for s in scenarios)
            if mc.samples * steps > MAX_WORK:
                raise root.fail("montecarlo.samples", mc.samples, f"at most {MAX_WORK:g} "
                                "samples x steps (a Monte Carlo of hours is a study, not a check)")
        from ..delay_feedback.model import PlantModel
        from ..delay_feedback.units import check_units
        model = PlantModel(plant)
        check_units(model)
        model.check_finite(plant.values(), "parameters")
        _check_law_units(plant, model, phases, usable)
        spec = SwitchedRunSpec(plant, hq.value, hq.source, predictor, phases, scenarios, speed,
                               mc, sampled, convergence, (), usable, comfort)
        from .quantities import scenario_metrics
        known = {s.name for s in scenarios}
        claims = claim_targets(root, "scenario.", lambda s: scenario_metrics(spec, s)
                               if s in known else set())
        from dataclasses import replace
        return replace(spec, claims=claims)

    def run(self, design):
        from .study import run
        return run(design.spec)

    def unconverged(self, res) -> dict[str, str]:
        """claim id -> reason, for the claims whose metric did not converge
        over dt, dt/2, dt/4 (``[convergence]``; used by :mod:`workbench.verify`)."""
        from ...features.convergence import unconverged
        return unconverged(res.refinement)


STUDY = SwitchedRun()
