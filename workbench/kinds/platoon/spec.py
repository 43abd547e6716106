"""The tables of a ``platoon`` design, read and validated (light: no numpy
beyond the profile, no sympy until the laws are unit-checked).

Tables: ``[plant]`` (the train model, :data:`TRAIN_MODELS`), ``[uncertainty]``
(seeded parameter spread and external force; bounds G_w, G_d), ``[leader]``
(accelerate - cruise - brake), ``[platoon]`` (trains, spacing, step,
horizon; optional ``headway``: the time-headway spacing policy), ``[route]`` (gradients), ``[constants]`` and ``[[laws]]``
(:mod:`.laws`), ``[[runs]]``, ``[reaching]``, ``[figures]``, and the
realistic scenario: ``[v2v]`` (the train-to-train link), ``[actuator]``
(first-order lag, traction and brake limits), ``[emergency]`` (the leader's
emergency brake and the safe braking-distance envelope it is judged
against), ``[delay_margin]`` (the exact margin of a linear law and a
simulated delay sweep) and ``[analysis]`` (a paper's named module).
"""
from __future__ import annotations

from dataclasses import dataclass

from ...plants.platoon001 import PARAMETER_UNITS, TrainParams
from ...profiles import phase_time, spec_for_cruise
from ...reader import Quantity, Reader, read_gradients, read_paper_module
from ...sim.platoon import JITTER, OWN_STATE
from ...sim.tracking import Route
from .laws import SIGNALS, Law, read_constants, read_laws

__all__ = ["ActuatorSpec", "EmergencySpec", "LinkSpec", "MarginSpec", "PlatoonSpec",
           "ReachingSpec", "RunSpec", "TRAIN_MODELS", "load_spec"]

#: ``[plant] model`` -> parameter units: point masses with Davis resistance and
#: gradient (:mod:`workbench.plants.platoon001`, the one platoon train model).
TRAIN_MODELS = {"davis-001": PARAMETER_UNITS}


@dataclass(frozen=True)
class LinkSpec:
    """``[v2v]``: packets every ``period`` (s), delay ``delay`` (s) plus, in the
    random case, a per-packet ``jitter`` (distribution, scale in s) and
    Bernoulli loss ``loss``; ``own_state`` as in :mod:`workbench.sim.platoon`."""

    period: Quantity
    delay: Quantity
    jitter: str
    jitter_scale: Quantity
    loss: float
    own_state: str
    seed: int
    loss_source: str = ""


@dataclass(frozen=True)
class ActuatorSpec:
    """``[actuator]``: lag (s); traction and brake limits as accelerations of
    the nominal mass (m/s^2, both positive)."""

    lag: Quantity
    traction: Quantity
    brake: Quantity


@dataclass(frozen=True)
class EmergencySpec:
    """``[emergency]``: the leader's full brake from ``time`` (s); the
    envelope's reaction time (s) and standstill margin (m); the laws run."""

    time: Quantity
    reaction: Quantity
    margin: Quantity
    laws: tuple[str, ...]


@dataclass(frozen=True)
class RunSpec:
    """``[[runs]]``: a run of the paper's (ideal) set-up under one law.
    ``chatters``: its trace is not reproducible to the last digit (drawn as its
    worst |e| only)."""

    name: str
    law: str
    label: str
    initial_errors: tuple[float, ...] | None = None
    chatters: bool = False


@dataclass(frozen=True)
class ReachingSpec:
    """``[reaching]``: the run started off its spacing, the bands (m), and the
    sliding time the law predicts (an expression of e_r, e_end, the constants)."""

    run: str
    reach_band: float
    converge_band: float
    sliding_time: str
    prediction: str = "predicted"      # its name in the report ("eq 22")


@dataclass(frozen=True)
class MarginSpec:
    """``[delay_margin]``: the linear law whose exact margin is computed, the
    laws of the sweep and its delays (multiples of h*)."""

    law: str
    sweep: tuple[str, ...]
    factors: tuple[float, ...]
    short: str = ""                # the linear law's short name in the sweep figure


@dataclass(frozen=True)
class PlatoonSpec:
    path: str
    plant: dict                 # Quantity per parameter of the train model
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
    constants: dict             # name -> Quantity
    laws: tuple[Law, ...]
    runs: tuple[RunSpec, ...]
    reaching: ReachingSpec | None
    figures: tuple[str, ...]
    captions: dict
    link: LinkSpec
    actuator: ActuatorSpec
    emergency: EmergencySpec
    margin: MarginSpec | None
    analysis_module: str | None = None   # ``[analysis] module`` (a name: specs stay keyable)
    analysis_spec: object = None
    headway: float = 0.0        # s: desired gap D + headway v (0: constant spacing)

    @property
    def analysis(self):
        """The ``[analysis]`` module's ``PLATOON_ANALYSIS`` object, or None."""
        return None if self.analysis_module is None else _analysis(self.analysis_module)

    def nominal(self) -> TrainParams:
        p = {k: q.value for k, q in self.plant.items()}
        return TrainParams(p["m"], p["c0"], p["c1"], p["c2"], p["g"])

    def law(self, name: str) -> Law:
        return next(x for x in self.laws if x.name == name)

    def run_spec(self, name: str) -> RunSpec:
        return next(x for x in self.runs if x.name == name)

    def constant_values(self, keys, needed_as: str) -> tuple[float, ...]:
        """The values of the ``[constants]`` ``keys``; a missing one is bad
        input, expected as ``needed_as`` (what needs it)."""
        missing = [k for k in keys if k not in self.constants]
        if missing:
            from ...errors import DesignError
            raise DesignError(self.path, f"constants.{missing[0]}", "<missing>", needed_as)
        return tuple(self.constants[k].value for k in keys)


def _multiple(r: Reader, name: str, q: Quantity, T: float) -> None:
    k = round(q.value / T)
    if k < 1 or abs(k * T - q.value) > 1e-9 * q.value:
        raise r.fail(name, q.value, f"a positive multiple of the step T = {T} s (s)")


def _read_link(root: Reader, T: float) -> LinkSpec:
    r = root.table("v2v")
    period = r.quantity("period", "s", positive=True, hi=5.0)
    _multiple(r, "period", period, T)
    delay = r.quantity("delay", "s", nonneg=True, hi=60.0)
    jitter = r.string("jitter", choices=JITTER)
    scale = r.quantity("jitter_scale", "s", nonneg=True, hi=60.0)
    loss = r.number("loss", lo=0.0, hi=0.99, what="packet-loss probability")
    own = r.string("own_state", choices=OWN_STATE)
    seed = int(r.number("seed", integer=True, nonneg=True, what="integer seed"))
    loss_source = r.string("loss_source", default="design choice")
    r.finish()
    return LinkSpec(period, delay, jitter, scale, loss, own, seed, loss_source)


def _read_actuator(root: Reader) -> ActuatorSpec:
    r = root.table("actuator")
    lag = r.quantity("lag", "s", nonneg=True, hi=10.0)
    traction = r.quantity("traction", "m/s^2", positive=True, hi=5.0)
    brake = r.quantity("brake", "m/s^2", positive=True, hi=5.0)
    r.finish()
    return ActuatorSpec(lag, traction, brake)


def _law_names(r: Reader, key: str, laws, *, default=None) -> tuple[str, ...]:
    names = [x.name for x in laws]
    val = r.raw(key, default)
    if (not isinstance(val, list) or not val or len(set(map(str, val))) < len(val)
            or any(v not in names for v in val)):
        raise r.fail(key, val, "a list of distinct law names of [[laws]]: " + ", ".join(names))
    return tuple(val)


def _read_emergency(root: Reader, t_brake: float, T: float, laws) -> EmergencySpec:
    r = root.table("emergency")
    time = r.quantity("time", "s", positive=True)
    if not time.value < t_brake:
        raise r.fail("time", time.value, f"a time (s) before the leader's service braking "
                     f"starts ({t_brake:.4g} s)")
    _multiple(r, "time", time, T)
    reaction = r.quantity("reaction", "s", nonneg=True, hi=60.0)
    margin = r.quantity("margin", "m", nonneg=True)
    names = _law_names(r, "laws", laws)
    r.finish()
    return EmergencySpec(time, reaction, margin, names)


def _read_runs(root: Reader, laws, n: int) -> tuple[RunSpec, ...]:
    from ..delay_feedback import NAME_PATTERN
    out, seen = [], set()
    tables = root.tables("runs")
    if not tables:
        raise root.fail("runs", [], "at least one [[runs]] table")
    for t in tables:
        name = t.string("name")
        if not NAME_PATTERN.match(name) or name in seen or "_over_" in name:
            raise t.fail("name", name, "a new run name of letters, digits and _ (without "
                         "'_over_')")
        seen.add(name)
        law = t.string("law", choices=[x.name for x in laws])
        label = t.string("label", default=name)
        e0 = None
        if t.has("initial_errors"):
            e0 = t.numbers("initial_errors", what="spacing errors (m)")
            if len(e0) != n - 1 or min(e0) < 0:
                raise t.fail("initial_errors", list(e0), f"{n - 1} non-negative errors (m), "
                             "one per follower (a follower too close would have to reverse)")
        chatters = t.boolean("chatters", default=False)
        t.finish()
        out.append(RunSpec(name, law, label, e0, chatters))
    return tuple(out)


def _read_reaching(root: Reader, runs, constants) -> ReachingSpec | None:
    if not root.has("reaching"):
        return None
    from ...expr import check_expression
    r = root.table("reaching")
    run = r.string("run", choices=[x.name for x in runs if x.initial_errors is not None])
    rb = r.quantity("reach_band", "m", positive=True).value
    cb = r.quantity("converge_band", "m", positive=True).value
    text = r.raw("sliding_time")
    check_expression(text, set(constants) | {"e_r", "e_end"}, path=root.path,
                     key=r.key("sliding_time"))
    prediction = r.string("prediction", default="predicted")
    r.finish()
    _check_time_unit(root.path, r.key("sliding_time"), text, constants)
    return ReachingSpec(run, rb, cb, text, prediction)


def _check_time_unit(path: str, key: str, text: str, constants) -> None:
    import sympy as sp
    from types import SimpleNamespace as NS

    from ...expr import parse_expression
    from ..delay_feedback.units import check_expression_units
    units = {"e_r": "m", "e_end": "m", "time": "s"} | {k: q.unit for k, q in constants.items()}
    syms = {k: sp.Symbol(k, real=True) for k in units}
    syms |= {k: sp.Rational(q.value) if isinstance(q.value, int) else sp.Float(q.value)
             for k, q in constants.items() if q.unit == "1"}
    plant = NS(path=path, states=(), inputs=(), parameters={k: NS(unit=u) for k, u in units.items()})
    check_expression_units(plant, [(key, text, parse_expression(text, syms, path=path, key=key),
                                    "time")])


def _read_margin(root: Reader, laws) -> MarginSpec | None:
    if not root.has("delay_margin"):
        return None
    r = root.table("delay_margin")
    law = r.string("law", choices=[x.name for x in laws])
    sweep = _law_names(r, "sweep", laws)
    factors = r.numbers("factors", positive=True, what="multiples of h*")
    if len(factors) > 8 or list(factors) != sorted(set(factors)) or max(factors) > 10:
        raise r.fail("factors", list(factors), "at most 8 increasing multiples of h* in (0, 10]")
    short = r.string("short", default=law)
    r.finish()
    return MarginSpec(law, sweep, factors, short)


def _read_analysis(root: Reader):
    """``[analysis] module = "pNNN.name"``: a paper's module (under
    ``workbench.papers``) with a ``PLATOON_ANALYSIS`` object, for what a
    design cannot express (its docstring says why): ``load(root, spec)``,
    ``QUANTITIES`` (:class:`~workbench.features.quantities.Declared` entries
    read from the result), optionally ``run(spec, res)`` and the report hooks
    of :mod:`.render`."""
    return read_paper_module(root, _analysis,
                             "a module of workbench.papers with PLATOON_ANALYSIS")


def _analysis(name: str):
    import importlib
    return importlib.import_module(f"workbench.papers.{name}").PLATOON_ANALYSIS


#: ``[figures]`` captions (drawn in each figure's title) and their defaults.
CAPTIONS = {"speeds": "Speeds of the trains.", "errors": "Spacing errors e_i.",
            "reaching": "Spacing errors and sliding variables from initial errors."}


def _read_figures(root: Reader, runs) -> tuple[tuple[str, ...], dict]:
    r = root.table("figures")
    names = [x.name for x in runs]
    val = r.raw("runs")
    if not isinstance(val, list) or len(val) != 2 or any(v not in names for v in val):
        raise r.fail("runs", val, "two run names of [[runs]] (drawn in the speed and spacing "
                     "figures): " + ", ".join(names))
    captions = {k: r.string(k, default=v) for k, v in CAPTIONS.items()}
    r.finish()
    return tuple(val), captions


def load_spec(root: Reader) -> PlatoonSpec:
    """Read and validate every table of a ``platoon`` design."""
    pl = root.table("plant")
    model = pl.string("model", choices=tuple(TRAIN_MODELS))
    plant = pl.quantities(TRAIN_MODELS[model], positive=True)
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
    hw = pt.quantity("headway", "s", nonneg=True, hi=10.0, default=None)
    headway = 0.0 if hw is None else hw.value
    pt.finish()
    ro = root.table("route")
    g_from, grade = read_gradients(ro)
    ro.finish()
    constants = read_constants(root, set(SIGNALS) | {"force", "time", "e_r", "e_end"})
    laws = read_laws(root, constants)
    runs = _read_runs(root, laws, n)
    reaching = _read_reaching(root, runs, constants)
    figures, captions = _read_figures(root, runs)
    profile = spec_for_cruise(vc.value, ct, acc, brk, jerk)
    if profile.run_time > horizon:
        raise pt.fail("horizon", horizon, "a horizon longer than the leader's run")
    link = _read_link(root, T)
    act = _read_actuator(root)
    t_brake = profile.run_time - phase_time(vc.value, brk, jerk)   # service braking starts
    em = _read_emergency(root, t_brake, T, laws)
    margin = _read_margin(root, laws)
    if margin is not None and headway > 0:
        raise root.fail("delay_margin", {"law": margin.law}, "no [delay_margin] with a time "
                        "headway (platoon.headway > 0): its loop model is that of constant "
                        "spacing")
    analysis = _read_analysis(root)
    spec = PlatoonSpec(root.path, plant, ms, ds, G_w, G_d, hold, seed, vc, ct, acc, brk, jerk,
                       lg, n, D, T, horizon, Route(1e9, g_from, grade), constants, laws, runs,
                       reaching, figures, captions, link, act, em, margin, analysis,
                       headway=headway)
    if margin is not None:
        from .realism import linear_gains
        linear_gains(spec)              # a DesignError when the law is not linear
    if analysis is not None:
        from dataclasses import replace
        spec = replace(spec, analysis_spec=spec.analysis.load(root, spec))
    return spec
