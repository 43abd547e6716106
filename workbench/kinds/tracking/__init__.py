"""Kind ``tracking``: a train follows a jerk-limited speed profile between
stations under sampled controllers whose gains are tuned on a grid by a
multi-objective rule (stop error, punctuality, comfort, energy).

A design configures (``designs/tracking-synthetic.toml`` is a small one):

``[route]``, ``[[line]]``
    the main station pair and further pairs: distance, planned run time,
    speed limit, gradient sections;
``[profile]``
    the target curve's acceleration, braking and jerk limits;
``[train]``
    a train model of :mod:`workbench.plants.train002` (``delay-lag-002``:
    command -> demanded acceleration -> delay -> lag -> speed, Davis resistance
    and gravity) and its command limits;
``[simulation]``
    the control cycle ``Ts`` and the plant step ``dt``;
``[tuning]``
    the rule (``weighted-sum``), the objectives' scales and weights, and the
    comfort limit ``peak_jerk`` as a constraint (:mod:`workbench.tuning`);
``[[plant_readings]]`` (optional)
    several plant models run side by side, each with its own controllers'
    grids; without it one reading, ``nominal``, is the ``[train]``;
controllers (``[pid]`` or, per reading, ``[plant_readings.pid]``)
    ``pid``: kp, ki, kd grids of the sampled PID (:mod:`workbench.controllers.pid`);
    ``mfac``: eta, mu, rho, lam, phi1 grids and epsilon of the CFDL-MFAC
    (:mod:`workbench.controllers.mfac`). MFAC is a *named* controller, not an
    expression: it is stateful (a PPD estimate updated from measured
    increments, with a reset rule and recorded histories for the CFDL
    diagnostics), which a design-file expression of (y, y*) cannot hold;
``[requirements]``
    the stop tolerance;
``[analysis]`` (optional)
    ``module = "pNNN.name"``: a paper's module whose ``render`` writes the
    report in the paper's words (:mod:`workbench.papers.p002.mfac_report`).

The tables are read in :mod:`.spec`, the computation is in :mod:`.run`
(controller-independent) and :mod:`.mfac` (the CFDL diagnostics of an MFAC
controller), the report in :mod:`.render`.
"""
from __future__ import annotations

from .spec import TrackingSpec, load_spec, quantity_names

__all__ = ["Tracking", "STUDY"]


class Tracking:
    """The ``tracking`` study object (see the module docstring)."""

    kind = "tracking"
    #: numerical step refined (dt/2, dt/4) for the findings (workbench.features.refinement)
    refine_field, refine_unit = "dt", "s"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root) -> TrackingSpec:
        return load_spec(root)

    def quantity_names(self, spec: TrackingSpec) -> set[str]:
        return quantity_names(spec)

    def run(self, design):
        from .run import run_study
        return run_study(design.spec)

    def quantities(self, res) -> dict:
        from .run import study_quantities
        return study_quantities(res)


STUDY = Tracking()
