"""Paper 000's names for the controllers of designs/stopping-line5.toml (a
``stop-accuracy`` configuration with ``[analysis] module =
"p000.station_stopping"``) and the paper's own table ``[[published]]``.

The laws, their gains, the plant, the uncertainty and the runs are the
kind's (:mod:`workbench.kinds.stop_accuracy`); this module keeps what is
paper 000's alone: which controller is which row of the report (its label
and group, the nominal ablation, the PIDs whose damping is analysed) and the
printed Tables 3-4, read for comparison.
"""
from __future__ import annotations

from dataclasses import dataclass

from ...kinds.stop_accuracy.loop_damping import pid_gains
from ...kinds.stop_accuracy.needs import require

#: Paper name -> (the design's controller, label in the report). The first
#: four are the controllers of the per-section tables: paper 000's three, then
#: SMARC with the discontinuous sgn of eq 22 as printed (no boundary layer), to
#: show the chattering the layer removes.
VARIANTS = {
    "pid": ("pid", "PID"),
    "smc": ("smc", "SMC"),
    "smarc": ("smarc", "SMARC"),
    "smarc-sgn": ("smarc_sgn", "SMARC (sgn)"),
    "pid-damped": ("pid_damped", "PID, ζ ≥ 0.7"),
    "pid-comp": ("pid_comp", "PID, ζ ≥ 0.7 + compensation"),
    "smc-comp": ("smc_comp", "SMC + compensation"),
    "smarc-comp": ("smarc_comp", "SMARC + compensation"),
    "smarc-comp-nogain": ("smarc_comp_nogain", "SMARC + compensation, no gain correction"),
    # nominal-plant ablation: one part of the compensation at a time
    "pid-damped+predictor": ("pid_damped_predictor", "PID, ζ ≥ 0.7 + predictor"),
    "pid-damped+terminal": ("pid_damped_terminal", "PID, ζ ≥ 0.7 + terminal"),
    "smc+predictor": ("smc_predictor", "SMC + predictor"),
    "smc+terminal": ("smc_terminal", "SMC + terminal"),
    "smarc+predictor": ("smarc_predictor", "SMARC + predictor"),
    "smarc+terminal": ("smarc_terminal", "SMARC + terminal"),
}
CONTROLLERS = ("pid", "smc", "smarc", "smarc-sgn")
PAPER_CONTROLLERS = CONTROLLERS[:3]
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


def label(name: str) -> str:
    """The report's label of the paper name ``name``."""
    return VARIANTS[name][1]


@dataclass(frozen=True)
class Line5:
    """What the analysis reads besides the kind's tables.

    Attributes
    ----------
    published : tuple
        ``[[published]]``: (section, smarc, smc, pid, smarc mean, smarc var,
        source) per row, the printed Tables 3-4 (data for comparison, never
        an input).
    zeta_min : float
        ``[constants] zeta_min``: the damping ratio the retuned PIDs meet.
    """

    published: tuple = ()
    zeta_min: float = 0.7


def gains(spec, name: str) -> dict:
    """kp, ki, kd of the PID of the paper name ``name`` (the named module ``pid``)."""
    return pid_gains(spec, VARIANTS[name][0])


def load(root, spec) -> Line5:
    """Check that ``spec`` has the controllers the paper's rows name (with a
    [reference], [[sections]] and [montecarlo]) and read ``[[published]]``."""
    require(root, spec, "p000.station_stopping", controllers=[v for v, _ in VARIANTS.values()],
            pids=[VARIANTS[k][0] for k in DAMPING], constants=("zeta_min",),
            tables=("reference", "sections", "montecarlo"))
    zeta = spec.constants["zeta_min"].value
    if not 0 < zeta <= 1:
        raise root.fail("constants.zeta_min", zeta, "a damping ratio in (0, 1]")
    pub = []
    ns = len(spec.sections.sections)
    for r in root.tables("published", default=[]):
        k = r.number("section", integer=True, lo=1, hi=ns)
        pub.append((k, *(r.number(c, nonneg=True) for c in PAPER_CONTROLLERS[::-1]),
                    r.number("smarc_mean", default=None),
                    r.number("smarc_var", default=None, nonneg=True), r.string("source")))
        r.finish()
    return Line5(tuple(pub), zeta)
