"""Three levels of the sampled plant's mesh (issue 33, item 4): one rate
metric of :mod:`workbench.papers.p003.antiskid_sampled` at plant_step,
plant_step / 2 and plant_step / 4, checked with a Richardson estimate
(:func:`workbench.refinement.guarded_check`)."""
from __future__ import annotations

import math
from dataclasses import dataclass

from ...refinement import guarded_check
from ...sim.convergence import CONVERGED, INCONCLUSIVE, NOT_CONVERGED

__all__ = ["BRAKING_METRICS", "TRACTION_METRICS", "ThreeLevel", "scenarios_of",
           "three_level_check"]

#: Rate metrics of the traction run and of the braking run (the others need both).
TRACTION_METRICS = ("lam_max_over_opt", "time_above", "t_cruise", "traction_ok")
BRAKING_METRICS = ("braking_duration", "stop_distance", "lam_min_brake", "evs_max_tracking",
                   "omega3_after_brake", "braking_ok")


@dataclass(frozen=True)
class ThreeLevel:
    """A claimed rate metric at plant_step, plant_step / 2, plant_step / 4.

    ``values``: (q1, q2, q4); ``tolerance``: the bound of the Richardson
    estimate (:data:`~.antiskid_sampled.MESH_ATOL`, 0 for a metric without
    one; None for an outcome, which converges when the three levels agree);
    ``outcome``: a :mod:`workbench.sim.convergence` outcome; ``estimate``:
    the Richardson estimate of the error of q4 (None for an outcome);
    ``note``: why an estimate was guarded (empty otherwise)."""

    variant: str
    rate: float
    metric: str
    values: tuple
    tolerance: float | None
    outcome: str
    estimate: float | None = None
    note: str = ""

    @property
    def converged(self) -> bool:
        return self.outcome == CONVERGED

    def reason(self) -> str:
        """``not converged: ...`` (empty when converged)."""
        if self.converged:
            return ""
        shown = " / ".join(str(x) if isinstance(x, str) else f"{x:.6g}" for x in self.values)
        est = "" if self.estimate is None else (f", estimate {self.estimate:.2g} > tolerance "
                                                f"{self.tolerance:.2g}")
        return (f"not converged: {self.variant} {self.rate:g} Hz {self.metric} is {shown} at "
                f"plant_step, /2, /4{est}" + (f" ({self.note})" if self.note else ""))


def scenarios_of(metric: str) -> tuple:
    """The scenarios (0 traction, 1 braking) a rate metric is computed from."""
    return (0,) if metric in TRACTION_METRICS else (1,) if metric in BRAKING_METRICS else (0, 1)


def three_level_check(variant: str, rate: float, metric: str, values: tuple,
                      tolerance: float = 0.0) -> ThreeLevel:
    """The three-level check of one rate metric (``values`` at plant_step,
    /2, /4): an outcome converges when the three agree; a number when every
    level is NaN (not reached), or by
    :func:`workbench.refinement.guarded_check` within ``tolerance`` (the
    section's, :data:`~.antiskid_sampled.MESH_ATOL`; 0, rounding only, for
    a metric without one); NaN at some levels only is INCONCLUSIVE."""
    if any(isinstance(x, str) for x in values):
        same = len(set(values)) == 1
        return ThreeLevel(variant, rate, metric, values, None,
                          CONVERGED if same else NOT_CONVERGED)
    nans = sum(math.isnan(x) for x in values)
    if nans:
        return ThreeLevel(variant, rate, metric, values, tolerance,
                          CONVERGED if nans == 3 else INCONCLUSIVE, None,
                          "" if nans == 3 else "reached at some levels only")
    r = guarded_check(*values, tolerance=tolerance)
    return ThreeLevel(variant, rate, metric, values, tolerance, r.outcome, r.estimate, r.note)
