"""Study ``ato-tracking``: paper 002's CFDL-MFAC against PID on ATO speed profiles,
per reading of the lost plant table, with multi-objective tuning.

The design tables are read in :mod:`.ato_tracking_spec`, the computation is in
:mod:`.ato_tracking_run`, the report in :mod:`.ato_tracking_render`.
"""
from __future__ import annotations

from .ato_tracking_spec import TrackingSpec, load_spec, quantity_names

__all__ = ["ATOTracking", "STUDY"]


class ATOTracking:
    kind = "ato-tracking"
    #: numerical step refined (dt/2, dt/4) for the findings (workbench.refinement)
    refine_field, refine_unit = "dt", "s"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root) -> TrackingSpec:
        return load_spec(root)

    def quantity_names(self, spec: TrackingSpec) -> set[str]:
        return quantity_names(spec)

    def run(self, design):
        from .ato_tracking_run import run_study
        return run_study(design.spec)

    def quantities(self, res) -> dict:
        from .ato_tracking_run import study_quantities
        return study_quantities(res)


STUDY = ATOTracking()
