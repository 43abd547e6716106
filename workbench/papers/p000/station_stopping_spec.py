"""Design tables of the ``station-stopping`` study (paper 000): the spec, the
controller variants, the uncertain factors.

Study ``station-stopping``: PID, SMC and SMARC station stops of paper 000.

Every run starts where the ATO target curve starts braking (cruise speed of
the section) and tracks the target x_d(t) to the stopping point through the
electro-pneumatic brake plant of :mod:`workbench.plants.brake000`. Each
repeat draws an uncertain plant (load-weighing / mass error, Davis
resistance, transmission delays, lags, air-brake gain, station gradient)
from seeded uniform ranges; all controllers meet the same draws (common
random numbers). The logs of the paper are not public: these stops are
synthetic.

Two groups of controllers (:data:`VARIANTS`):

* *as in paper 000*: the laws act on the measured state (no delay
  compensation), as the paper's; plus the speed PID retuned so that its
  linearised loop is damped (:mod:`workbench.tuning.pid`);
* *with known-delay compensation*: the same laws fed with the state one
  dead time ahead (Smith predictor in state form) and, from ``d_terminal``
  metres before the stopping point, the predictive terminal stopping law
  (:mod:`workbench.controllers.stop_predictor`).

Besides the per-section repeats of the paper's tables, every controller is
run once on the nominal plant (no uncertainty) and over a Monte Carlo of
continuous distributions (:mod:`workbench.features.montecarlo`).

Design tables: ``[plant]`` (brake parameters, SI), ``[uncertainty]``,
``[target]``, ``[[sections]]``, ``[controllers.pid|pid_damped|sliding|smarc]``,
``[compensation]``, ``[montecarlo]``, ``[sim]``.
"""
from __future__ import annotations

from dataclasses import dataclass, replace


from ...controllers.smc import SlidingGains
from ...features.montecarlo import MonteCarloSpec, load_montecarlo
from ...kinds.stop_accuracy.modules import Compensation   # [compensation]: the kind's modules
from ...kinds.stop_accuracy.pipeline import Factor, read_brake_plant
from ...kinds.stop_accuracy.sections import Section   # [[sections]]: the kind's
from ...reader import Quantity, Reader

#: Paper 000's three controllers, then SMARC with the discontinuous sgn of eq 22
#: as printed (no boundary layer), to show the chattering the layer removes:
#: the controllers of the per-section tables.
CONTROLLERS = ("pid", "smc", "smarc", "smarc-sgn")
PAPER_CONTROLLERS = CONTROLLERS[:3]
#: Uncertain factors of the repeats: name -> (what, unit)
UNCERTAIN = {
    "mass_ratio": ("true / estimated mass (load-weighing error)", "1"),
    "resistance": ("factor on the Davis coefficients", "1"),
    "delay": ("factor on the transmission delays T1, T3", "1"),
    "lag": ("factor on the lags T2, T4", "1"),
    "air_gain": ("factor on K1 (air-brake gain)", "1"),
    "gradient": ("station gradient theta (+ uphill)", "permille"),
}
#: Factors of the Monte Carlo in draw order (a factor's stream is its position), and
#: how each acts on the plant (:mod:`workbench.kinds.stop_accuracy.pipeline`)
MC_FACTORS = {f.name: f for f in (
    Factor("delay", "scale", ("T1", "T3"), "factor on the transmission delays T1, T3"),
    Factor("lag", "scale", ("T2", "T4"), "factor on the lags T2, T4"),
    Factor("mass_ratio", "mass_ratio", (), "true / estimated mass (load-weighing error)"),
    Factor("brake_gain", "scale", ("K1", "P1"),
           "factor on the brake gains P1 and K1 (both stages)"),
    Factor("resistance", "scale", ("d0", "d1", "d2"), "factor on the Davis coefficients"),
    Factor("gradient", "gradient", (), "station gradient theta (+ uphill)", "permille"))}
#: Every factor of the repeats and the Monte Carlo in the order they act: K1 is
#: base * air_gain * brake_gain.
FACTORS = (MC_FACTORS["delay"], MC_FACTORS["lag"],
           Factor("air_gain", "scale", ("K1",), "factor on K1 (air-brake gain)"),
           *(MC_FACTORS[k] for k in ("brake_gain", "resistance", "gradient", "mass_ratio")))
NOMINAL = {f.name: f.nominal for f in (*MC_FACTORS.values(), FACTORS[2])}


@dataclass(frozen=True)
class Variant:
    """One controller as run: its law, PID gain set, and compensation.

    Attributes
    ----------
    law : {"pid", "smc", "smarc", "smarc-sgn"}
    gains : {"pid", "pid_damped", "pid_compensated", ""}
        PID gain table of the design ("" for the sliding laws).
    predictor : bool
        The law acts on the state one dead time ahead (Smith predictor).
    terminal : bool
        The predictive terminal stopping law takes over at ``d_terminal``.
    label : str
    gain_correction : bool
        The controller's brake model is corrected by the measured deceleration.
    """

    law: str
    gains: str
    predictor: bool
    terminal: bool
    label: str
    gain_correction: bool = True


VARIANTS = {
    "pid": Variant("pid", "pid", False, False, "PID"),
    "smc": Variant("smc", "", False, False, "SMC"),
    "smarc": Variant("smarc", "", False, False, "SMARC"),
    "smarc-sgn": Variant("smarc-sgn", "", False, False, "SMARC (sgn)"),
    "pid-damped": Variant("pid", "pid_damped", False, False, "PID, ζ ≥ 0.7"),
    "pid-comp": Variant("pid", "pid_compensated", True, True, "PID, ζ ≥ 0.7 + compensation"),
    "smc-comp": Variant("smc", "", True, True, "SMC + compensation"),
    "smarc-comp": Variant("smarc", "", True, True, "SMARC + compensation"),
    "smarc-comp-nogain": Variant("smarc", "", True, True,
                                 "SMARC + compensation, no gain correction", False),
    # nominal-plant ablation: one part of the compensation at a time
    "pid-damped+predictor": Variant("pid", "pid_compensated", True, False,
                                    "PID, ζ ≥ 0.7 + predictor"),
    "pid-damped+terminal": Variant("pid", "pid_damped", False, True, "PID, ζ ≥ 0.7 + terminal"),
    "smc+predictor": Variant("smc", "", True, False, "SMC + predictor"),
    "smc+terminal": Variant("smc", "", False, True, "SMC + terminal"),
    "smarc+predictor": Variant("smarc", "", True, False, "SMARC + predictor"),
    "smarc+terminal": Variant("smarc", "", False, True, "SMARC + terminal"),
}
#: Uncompensated and compensated controllers of the nominal row and the Monte Carlo.
UNCOMPENSATED = ("pid", "pid-damped", "smc", "smarc")
COMPENSATED = ("pid-comp", "smc-comp", "smarc-comp")
#: the compensation without its brake-gain correction (what the measured deceleration adds)
PARTIAL = ("smarc-comp-nogain",)
MC_CONTROLLERS = UNCOMPENSATED + COMPENSATED + PARTIAL
ABLATION = tuple(k for k in VARIANTS if "+" in k)
#: law -> (as in paper, + predictor only, + terminal phase only, + both): the nominal ablation
ABLATION_LAWS = {
    "PID, ζ ≥ 0.7": ("pid-damped", "pid-damped+predictor", "pid-damped+terminal", "pid-comp"),
    "SMC": ("smc", "smc+predictor", "smc+terminal", "smc-comp"),
    "SMARC": ("smarc", "smarc+predictor", "smarc+terminal", "smarc-comp"),
}
#: PID variants whose linearised loop is analysed: with the dead time T1 (+ half a
#: control period), or, behind the Smith predictor, half a control period only.
DAMPING = ("pid", "pid-damped", "pid-comp")


@dataclass(frozen=True)
class StopSpec:
    params: dict            # name -> Quantity
    ranges: dict            # name -> (lo, hi)
    v_max: Quantity
    a_acc: Quantity
    a_dec: Quantity
    sections: tuple[Section, ...]
    pid: dict
    sliding: SlidingGains
    smarc: dict
    dt: float
    dt_ctrl: float
    repeats: int
    seed: int
    c_max: float
    c_min: float
    published: tuple = ()   # (section, smarc, smc, pid, smarc mean, smarc var, source): data
    pid_damped: dict | None = None       # kp, ki, kd of the damped PID
    pid_compensated: dict | None = None  # ... and of the damped PID behind the predictor
    zeta_min: float = 0.7                # its damping requirement
    tolerance: Quantity | None = None    # platform tolerance (m)
    compensation: Compensation | None = None
    montecarlo: MonteCarloSpec | None = None

    def gains(self, name: str) -> dict:
        """PID gain table ``name`` ("pid", "pid_damped" or "pid_compensated")."""
        return {"pid": self.pid, "pid_damped": self.pid_damped,
                "pid_compensated": self.pid_compensated}[name]


def load_stop_spec(root: Reader) -> StopSpec:
    params = read_brake_plant(root)
    unc = root.table("uncertainty")
    ranges = {}
    for k in UNCERTAIN:
        b = unc.numbers(k, what="bounds [lo, hi]")
        if len(b) != 2 or not b[0] <= b[1]:
            raise unc.fail(k, list(b), "two bounds [lo, hi] with lo <= hi")
        if k != "gradient" and not b[0] > 0:
            raise unc.fail(k, list(b), "positive factors")
        ranges[k] = (b[0], b[1])
    unc.finish()
    tg = root.table("target")
    v_max = tg.quantity("v_max", "m/s", positive=True, hi=40.0)
    a_acc = tg.quantity("a_acc", "m/s^2", positive=True, hi=2.0)
    a_dec = tg.quantity("a_dec", "m/s^2", positive=True, hi=2.0)
    tol = tg.quantity("tolerance", "m", positive=True, hi=10.0)
    tg.finish()
    sections = []
    for s in root.tables("sections"):
        sections.append(Section(s.string("name"), s.number("length", positive=True),
                                s.string("source")))
        s.finish()
    if not sections:
        raise root.fail("sections", [], "at least one [[sections]] entry")
    ctl = root.table("controllers")
    p = ctl.table("pid")
    pid = {k: p.number(k, nonneg=True) for k in ("kp", "ki", "kd")}
    p.finish()
    p = ctl.table("pid_damped")
    pid_damped = {k: p.number(k, nonneg=True) for k in ("kp", "ki", "kd")}
    zeta_min = p.number("zeta_min", positive=True, hi=1.0)
    p.finish()
    p = ctl.table("pid_compensated")
    pid_comp = {k: p.number(k, nonneg=True) for k in ("kp", "ki", "kd")}
    p.finish()
    s = ctl.table("sliding")
    sliding = SlidingGains(c=s.number("c", positive=True), k_s=s.number("k_s", positive=True),
                           eta=s.number("eta", nonneg=True), phi=s.number("phi", nonneg=True))
    s.finish()
    a = ctl.table("smarc")
    smarc = {"lam": a.number("lam", positive=True),
             "theta_min": a.number("theta_min", positive=True),
             "theta_max": a.number("theta_max", positive=True)}
    if not smarc["theta_min"] < 1.0 < smarc["theta_max"]:
        raise a.fail("theta_max", smarc["theta_max"], "bounds with theta_min < 1 < theta_max")
    a.finish()
    ctl.finish()
    cp = root.table("compensation")
    b = cp.numbers("gain_bounds", positive=True, what="bounds [lo, hi] (-)")
    if len(b) != 2 or not b[0] <= 1.0 <= b[1]:
        raise cp.fail("gain_bounds", list(b), "two bounds [lo, hi] with lo <= 1 <= hi")
    comp = Compensation(cp.number("d_terminal", positive=True, hi=500.0),
                        cp.number("gain_tau", nonneg=True, hi=60.0), (b[0], b[1]))
    cp.finish()
    mc = load_montecarlo(root, {k: f.positive for k, f in MC_FACTORS.items()})
    sim = root.table("sim")
    spec = StopSpec(params, ranges, v_max, a_acc, a_dec, tuple(sections), pid, sliding, smarc,
                    dt=sim.number("dt", positive=True, hi=0.05),
                    dt_ctrl=sim.number("dt_ctrl", positive=True, hi=1.0),
                    repeats=sim.number("repeats", integer=True, lo=2, hi=10000),
                    seed=sim.number("seed", integer=True, lo=0),
                    c_max=sim.number("c_max", positive=True, hi=2.0),
                    c_min=-sim.number("traction_max", positive=True, hi=2.0))
    sim.finish()
    pub = []
    for r in root.tables("published", default=[]):
        k = r.number("section", integer=True, lo=1, hi=len(sections))
        row = (k, *(r.number(c, nonneg=True) for c in PAPER_CONTROLLERS[::-1]),
               r.number("smarc_mean", default=None), r.number("smarc_var", default=None, nonneg=True),
               r.string("source"))
        pub.append(row)
        r.finish()
    return replace(spec, published=tuple(pub), pid_damped=pid_damped, pid_compensated=pid_comp,
                   zeta_min=zeta_min,
                   tolerance=tol, compensation=comp, montecarlo=mc)
