"""The basin check inside the ``antiskid-run`` study: the design's ``[basin]``
table, and the check run on the study's results.

Design table (optional; absent: no basin section)::

    [basin]
    enabled = true                     # false: the section is left out
    k2_grid = [-40.0, -10.0, 0.0, 2.0, 4.0, 6.0, 8.0, 10.0]
    compare_gains = [[-0.0049, 10.5080], ...]   # [k1, k2] rows judged at the printed switch
    compare_labels = ["eps = 0.35", ...]        # one per row
    compare_source = "003 Table 3 (dry rail, v_d = 70 m/s)"
    bisect = 4                         # bisection steps on the edge of the safe k2 range
    seed = 0                           # falsifier seed

The switch states are the simulated states where law (61) takes over in each
case (``v_at_cruise`` / ``lam_at_cruise`` for ``cruise_entry = "speed"``,
the handover state for ``"creep"``); the k2 rule is judged at the printed
switch state (v_d, lambda_opt). The cruise -> braking switch is judged at
each case's state at t_brake against the braking law (69) frozen at that
instant (:mod:`.antiskid_basin_brake`). The basin uses the controller's nominal
model (a design's plant mass factor is not in it; the report says so).

What stays here is paper 003's: the k2 key, the switch names, where the
switches are in a case's metrics, and which law judges each switch. The
switch states, the per-case switch verdicts and their quantities (with the
level and gain sweep quantities) are the general ones of
:mod:`workbench.features.basin_switch`, and the table (``enabled``, ``seed``,
``compare_*``, ``bisect``) is read by
:func:`workbench.features.basin_points.load_gain_sweep`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ...features.basin_points import GainSweep, GainSweepSettings, load_gain_sweep
from ...features.basin_switch import (switch_basin_quantities, switch_basin_quantity_names,
                                      switch_states)
from .antiskid_basin import CruiseBasin, cruise_basin, safe_k2_range


@dataclass(frozen=True)
class BasinResult:
    """Basin of the cruise law at the design's gain and the k2 rule."""

    basin: CruiseBasin
    sweep: GainSweep
    compare_source: str
    mass_factor: float
    brake: tuple = ()          # FrozenSwitch (antiskid_basin_brake) per case that braked


def load_basin_settings(root) -> GainSweepSettings | None:
    """Read ``[basin]`` from a design (a :class:`workbench.reader.Reader`): ``grid``
    the k2 values, ``compare`` rows (label, (k1, k2)); None when the table is
    absent or ``enabled = false``."""
    return load_gain_sweep(root, "k2_grid", 2, what="cruise gains k2")


def switch_points(cases) -> list:
    """(case name, (v, lambda)) where law (61) took over, per case (cases whose
    cruise law never started are left out)."""
    def at(c):
        key = "handover" if c.case.cruise_entry == "creep" else "cruise"
        return c.case.name, (c.metrics.get(f"v_at_{key}", math.nan),
                             c.metrics.get(f"lam_at_{key}", math.nan))
    return switch_states(cases, at)


def brake_points(cases, v_d: float) -> list:
    """(case name, (v, lambda)) at t_brake, per case that reached braking."""
    return switch_states(cases, lambda c: (c.case.name, (
        v_d + c.metrics.get("v_err_at_brake", math.nan), c.metrics.get("lam_at_brake", math.nan))))


def run_basin(settings: GainSweepSettings, values: dict, v_d: float, K, lambda_opt: float, cases,
              mass_factor: float = 1.0, *, profile=None, k_de: float | None = None
              ) -> BasinResult:
    """The basin check of one antiskid-run design.

    Parameters
    ----------
    settings : GainSweepSettings
    values : dict
        Nominal plant constants (SI) the controller is built on.
    v_d : float
        Cruise speed (m/s).
    K : (k1, k2)
        The design's cruise gain.
    lambda_opt : float
        Creep ratio of peak adhesion (the printed switch: lambda = lambda_opt).
    cases : sequence of CaseResult
        The study's cases (their switch states).
    mass_factor : float
        Plant mass / nominal (reported: the basin uses the nominal model).
    profile : CreepSpeedProfile, optional
        Eq (76); with ``k_de``, the cruise -> braking switch is judged too.
    k_de : float, optional
        Gain of the braking law (69) (1/s).
    """
    basin = cruise_basin(values, v_d, K, switch_points(cases), seed=settings.seed)
    sweep = safe_k2_range(values, v_d, float(K[0]), (v_d, lambda_opt), grid=settings.grid,
                          compare=settings.compare, bisect=settings.bisect, seed=settings.seed)
    brake = ()
    if profile is not None and k_de is not None:
        from .antiskid_basin_brake import brake_switch
        brake = tuple(brake_switch(values, lab, pt, profile=profile, k_de=k_de,
                                   seed=settings.seed) for lab, pt in brake_points(cases, v_d))
    return BasinResult(basin, sweep, settings.compare_source, mass_factor, brake)


def basin_quantities(basin, sweep, labels=(), brake=()) -> dict:
    """Claim quantities of the basin check (``labels``: every case; a case
    whose cruise law never started, or that never braked, gets None)."""
    return switch_basin_quantities(basin.check.estimate, labels, {
        "cruise": basin.judged, "brake": [b.judged for b in brake]}, sweep, "k2")


def basin_quantity_names(labels) -> set:
    """Names of :func:`basin_quantities`, the k2 rule's included."""
    return switch_basin_quantity_names(labels, ("cruise", "brake"), "k2")
