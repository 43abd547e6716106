"""Design tables of a ``tracking`` design and the names of its quantities.

Tables read here: ``[route]`` (the main station pair), ``[profile]`` (limits
of the target curve), ``[train]`` (a ``delay-lag-002`` train of
:mod:`workbench.plants.train002`: static map, delay, lag, Davis resistance,
gravity and command limits, units checked), ``[simulation]`` (control cycle,
plant step), ``[tuning]`` (the four objectives' scales and weights of the
rule that picks one point of each Pareto front, and the peak-jerk comfort
constraint), ``[[plant_readings]]`` (optional: several plant models, each with
its controllers' grids, whose units follow the command's) or else the
controllers' grids at the top level (``[pid]``, ``[mfac]``; one reading named
``nominal``, the ``[train]``), ``[requirements]`` (stop tolerance),
``[[line]]`` (further station pairs) and ``[analysis]`` (a paper's report
module). The computation is in :mod:`.run`, the study object in
:mod:`workbench.kinds.tracking`.
"""
from __future__ import annotations

from dataclasses import dataclass

from ...errors import DesignError, ModelError
from ...plants.train002 import MODELS, PARAMETER_UNITS, FirstOrderTrain002, Train002
from ...profiles import ProfileSpec, build_profile
from ...reader import Quantity, Reader, read_gradients, read_paper_module
from ...sim.tracking import Objectives, Route

__all__ = ["MFAC_KEYS", "OBJECTIVES", "OBJECTIVE_UNITS", "PID_KEYS", "Reading", "Section",
           "TrackingSpec", "load_spec", "quantity_names"]

OBJECTIVES = Objectives.NAMES
OBJECTIVE_UNITS = {"stop_error": "m", "punctuality": "s", "comfort": "m/s^3", "energy": "J/kg"}
MFAC_KEYS = ("eta", "mu", "rho", "lam", "phi1")
PID_KEYS = ("kp", "ki", "kd")
#: units of the first-order reading's parameters (its command is a demanded speed)
FIRST_ORDER_UNITS = {"f": "1", "e": "m/s", "delay": "s", "lag": "s", "a_min": "m/s^2",
                     "a_max": "m/s^2", "u_min": "m/s", "u_max": "m/s"}


@dataclass(frozen=True)
class Section:
    """One station pair: route, planned time and where its data come from."""

    name: str
    route: Route
    run_time: float
    v_limit: float
    source: str


@dataclass(frozen=True)
class Reading:
    """One reading of the lost Table 1: the plant and the two controllers' grids.

    Attributes
    ----------
    name, model, source : str
        Name used in claims, plant model (one of ``MODELS``), where it comes from.
        Without ``[[plant_readings]]`` the one reading is ``nominal``, the ``[train]``.
    train : Train002
        The plant (a :class:`FirstOrderTrain002` for ``"first-order-002"``).
    params : dict[str, Quantity]
        The reading's own parameters as written (empty when they are ``[train]``'s).
    mfac_grid : dict[str, tuple[float, ...]] or None
        eta, mu, rho, lam, phi1 values; every combination is simulated
        (None: no MFAC on this reading).
    epsilon : float or None
        Reset threshold of the MFAC's estimate (in the command's and the PPD's units).
    pid_grid : dict[str, tuple[float, ...]] or None
        kp, ki, kd values (None: no PID on this reading).
    table : str
        Design-file table that holds the controllers' grids (``""``: the top level).
    """

    name: str
    model: str
    source: str
    train: Train002
    params: dict
    mfac_grid: dict | None
    epsilon: float | None
    pid_grid: dict | None
    table: str = "plant_readings"   # where its controller tables are ("": top level)

    @property
    def controllers(self) -> tuple[str, ...]:
        """The controllers tuned on this reading, of ``("mfac", "pid")``."""
        return tuple(c for c, g in (("mfac", self.mfac_grid), ("pid", self.pid_grid))
                     if g is not None)


@dataclass(frozen=True)
class TrackingSpec:
    main: Section
    line: tuple[Section, ...]
    profile: dict           # accel, brake, jerk (m/s^2, m/s^2, m/s^3)
    train: dict             # Quantity per PARAMETER_UNITS key ([train])
    u_limits: tuple[float, float]
    Ts: float
    dt: float
    readings: tuple[Reading, ...]
    scales: dict            # objective -> Quantity
    weights: tuple[float, ...]
    stop_tolerance: Quantity
    peak_jerk: Quantity | None = None   # comfort constraint of the tuning ([tuning]); None: none
    analysis_module: str | None = None  # ``[analysis] module`` (a name: specs stay keyable)

    def profile_spec(self, sec: Section) -> ProfileSpec:
        return ProfileSpec(sec.route.distance, sec.v_limit, self.profile["accel"],
                           self.profile["brake"], self.profile["jerk"], sec.run_time)


def _section(r: Reader, *, with_source: bool) -> Section:
    dist = r.quantity("distance", "m", positive=True)
    T = r.quantity("run_time", "s", positive=True)
    vlim = r.quantity("v_limit", "m/s", positive=True, hi=150.0)
    name = r.string("name")
    g_from, grade = read_gradients(r)
    src = r.string("source") if with_source else dist.source
    r.finish()
    return Section(name, Route(dist.value, g_from, grade), T.value, vlim.value, src)


def _grid(r: Reader, keys, *, positive: bool) -> dict:
    grid = {k: r.numbers(k, positive=positive, what=f"{k} values") for k in keys}
    for k, vals in grid.items():
        if not positive and min(vals) < 0:
            raise r.fail(k, list(vals), "non-negative gains")
        if k in ("rho", "eta") and max(vals) > 1.0:
            raise r.fail(k, list(vals), "values in (0, 1] (paper 002)")
    return grid


def _multiple_of(path, key: str, x: float, dt: float) -> None:
    if abs(round(x / dt) * dt - x) > 1e-9:
        raise DesignError(path, key, x, f"a multiple of simulation.dt = {dt} s")


def _reading(r: Reader, base: dict, u_lim, dt: float) -> Reading:
    name = r.string("name")
    model = r.string("model", choices=MODELS)
    source = r.string("source")
    params: dict = {}
    davis = {k: base[k].value for k in ("c0", "c1", "c2", "g")}
    if model == "delay-lag-002":
        train = Train002(**{k: q.value for k, q in base.items()}, u_min=u_lim[0], u_max=u_lim[1])
    else:
        for k, unit in FIRST_ORDER_UNITS.items():
            kw = {"positive": True} if k in ("f", "delay", "lag", "a_max", "u_max") else {}
            params[k] = r.quantity(k, unit, **kw)
        p = {k: q.value for k, q in params.items()}
        if not p["a_min"] < 0 or not p["u_min"] < p["u_max"]:
            raise r.fail("a_min" if not p["a_min"] < 0 else "u_min",
                         p["a_min"] if not p["a_min"] < 0 else p["u_min"],
                         "a_min < 0 and u_min < u_max")
        train = FirstOrderTrain002(**p, **davis)
    _multiple_of(r.path, r.key("delay") if params else "train.delay", train.delay, dt)
    mgrid, eps, pgrid = _controllers(r)
    r.finish()
    return Reading(name, model, source, train, params, mgrid, eps, pgrid)


def _controllers(r: Reader):
    """(MFAC grid, epsilon, PID grid) of the ``mfac`` and ``pid`` tables of
    ``r`` (each optional, at least one)."""
    if not (r.has("mfac") or r.has("pid")):
        raise r.fail("pid", None, "a controller grid: a pid table (kp, ki, kd) and/or an "
                     "mfac table (eta, mu, rho, lam, phi1, epsilon)")
    mgrid = eps = pgrid = None
    if r.has("mfac"):
        mf = r.table("mfac")
        mgrid = _grid(mf, MFAC_KEYS, positive=True)
        eps = mf.number("epsilon", positive=True)
        mf.finish()
    if r.has("pid"):
        pi = r.table("pid")
        pgrid = _grid(pi, PID_KEYS, positive=False)
        pi.finish()
    return mgrid, eps, pgrid


def _nominal(root: Reader, base: dict, u_lim) -> Reading:
    """The one reading of a design without ``[[plant_readings]]``: the ``[train]``
    and the top-level controller tables."""
    train = Train002(**{k: q.value for k, q in base.items()}, u_min=u_lim[0], u_max=u_lim[1])
    mgrid, eps, pgrid = _controllers(root)
    return Reading("nominal", "delay-lag-002", "[train]", train, {}, mgrid, eps, pgrid, "")


def load_spec(root: Reader) -> TrackingSpec:
    """The validated spec of a ``tracking`` design (see the module docstring)."""
    main = _section(root.table("route"), with_source=False)
    line = tuple(_section(r, with_source=True) for r in root.tables("line", default=[]))
    pr = root.table("profile")
    prof = {"accel": pr.quantity("accel", "m/s^2", positive=True, hi=2.0).value,
            "brake": pr.quantity("brake", "m/s^2", positive=True, hi=2.0).value,
            "jerk": pr.quantity("jerk", "m/s^3", positive=True, hi=5.0).value}
    pr.finish()
    tr = root.table("train")
    tr.string("model", choices=("delay-lag-002",))
    sign = {"e": {}, "c0": {"nonneg": True}, "c1": {"nonneg": True}, "c2": {"nonneg": True}}
    train = {k: tr.quantity(k, unit, **sign.get(k, {"positive": True}))
             for k, unit in PARAMETER_UNITS.items()}
    u_lim = (tr.quantity("u_min", "m/s^2", hi=0.0).value,
             tr.quantity("u_max", "m/s^2", positive=True).value)
    tr.finish()
    sim = root.table("simulation")
    Ts = sim.quantity("Ts", "s", positive=True, hi=2.0).value
    dt = sim.quantity("dt", "s", positive=True, hi=0.1).value
    sim.finish()
    _multiple_of(root.path, "simulation.Ts", Ts, dt)
    if root.has("plant_readings"):
        readings = tuple(_reading(r, train, u_lim, dt) for r in root.tables("plant_readings"))
    else:
        _multiple_of(root.path, "train.delay", train["delay"].value, dt)
        readings = (_nominal(root, train, u_lim),)
    names = [r.name for r in readings]
    if not readings or len(set(names)) != len(names):
        raise DesignError(root.path, "plant_readings", names, "one or more readings with "
                          "distinct names")
    tu = root.table("tuning")
    tu.string("rule", choices=("weighted-sum",))
    scales = {k: tu.quantity(k, OBJECTIVE_UNITS[k], positive=True) for k in OBJECTIVES}
    weights = tu.numbers("weights", min_len=len(OBJECTIVES), what="weights (one per "
                         "objective: " + ", ".join(OBJECTIVES) + ")")
    if len(weights) != len(OBJECTIVES) or min(weights) < 0 or not max(weights) > 0:
        raise tu.fail("weights", list(weights), f"{len(OBJECTIVES)} non-negative weights, "
                      "not all 0")
    peak_jerk = tu.quantity("peak_jerk", "m/s^3", positive=True, hi=10.0, default=None)
    tu.finish()
    req = root.table("requirements")
    tol = req.quantity("stop_tolerance", "m", positive=True, hi=1e4)   # declared range (issue 32)
    req.finish()
    spec = TrackingSpec(main, line, prof, train, u_lim, Ts, dt, readings, scales, weights,
                        tol, peak_jerk, _read_analysis(root))
    for i, sec in enumerate((main, *line)):
        try:
            build_profile(spec.profile_spec(sec), dt=Ts)
        except ModelError as exc:
            key = "route.run_time" if i == 0 else f"line[{i - 1}].run_time"
            raise DesignError(root.path, key, sec.run_time, f"a feasible run time ({exc})") \
                from None
    return spec


def _read_analysis(root: Reader) -> str | None:
    """``[analysis] module = "pNNN.name"``: a paper's module (under
    ``workbench.papers``) with a ``render(design, res)`` for the report."""
    import importlib
    return read_paper_module(
        root, lambda name: importlib.import_module(f"workbench.papers.{name}").render,
        "a module of workbench.papers with a render function")


def quantity_names(spec: TrackingSpec) -> set[str]:
    """Every quantity a claim may name: per reading and controller the chosen
    point's objectives, its front and line; the comparison when a reading has
    both controllers; the CFDL diagnostics when it has an MFAC."""
    names = {"profile.v_cruise", "profile.end_error", "line.sections"}
    for r in spec.readings:
        p = f"reading[{r.name}]"
        ctrls = r.controllers
        for c in ctrls:
            names |= {f"{p}.{c}.{i}" for i in (*OBJECTIVES, "rms_speed_error", "cost")}
            names |= {f"{p}.{c}.front_size", f"{p}.line.{c}.within_tolerance",
                      f"{p}.line.{c}.max_stop_error"}

            names |= {f"{p}.best.{c}.{i}" for i in OBJECTIVES}
            names |= {f"{p}.{c}.{k}" for k in ("peak_jerk", "grid_edge")}
        names.add(f"{p}.design_points_interior")
        names |= {f"{p}.{k}" for k in ("plant.dc_gain", "plant.time_constant")}
        if len(ctrls) == 2:
            names |= {f"{p}.{k}" for k in (
                "verdict", "mfac_wins", "front.pid_dominated", "front.mfac_dominated")}
        if "mfac" in ctrls:
            names |= {f"{p}.{k}" for k in (
                "mfac.reset_rate", "mfac.reset_rate.small_du", "mfac.reset_rate.sign_change",
                "mfac.reset_rate.small_phi", "mfac.reset_rate.at_limit", "mfac.saturated",
                "grid.reset_rate_min", "grid.reset_rate_median", "ppd.phi_min", "ppd.phi_max",
                "ppd.data_sign_agreement", "ppd.data_median", "ppd.data_p95",
                "ppd.median_to_dc_gain", "frozen.spectral_radius",
                "sensitivity.most_sensitive")}
            names |= {f"{p}.sensitivity.{k}" for k in ("eta", "mu", "rho", "lam")}
    return names
