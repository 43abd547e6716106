"""Study ``platoon``: a leader-follower platoon of trains under follower laws
written in the design file, in an ideal set-up and in a realistic one (V2V
link, actuator lag and limits, the leader's emergency brake, the exact delay
margin) (issue 35, item 1; first written for paper 001's NTSM platoon).

Tables::

    [plant]        model = "davis-001" (point masses, Davis resistance, gradient) and
                   m, c0, c1, c2, g with unit and source
    [uncertainty]  mass_spread, davis_spread, G_w, G_d (N), hold (s), seed: the seeded
                   true trains and external force |w| <= G_w
    [leader]       cruise_speed, cruise_time, accel, brake, jerk, gain: the manoeuvre
                   (accelerate - cruise - brake) and the leader's speed loop
    [platoon]      trains, spacing (m), T (s), horizon (s), headway (s, optional: the
                   time-headway policy, desired gap spacing + headway v; default 0,
                   constant spacing)
    [route]        grade_from, grade
    [constants]    name = { value, unit, source }: numbers the laws use
    [[laws]]       name, label, law = "force expression (N)", definitions = {...},
                   surface = "definition" (optional; :mod:`.laws`)
    [[runs]]       name, law, label, initial_errors (optional), chatters (bool)
    [figures]      runs = [two runs], speeds/errors/reaching captions (optional)
    [reaching]     run, reach_band, converge_band, sliding_time = "expression of e_r,
                   e_end (s)", prediction = "its name" (optional)
    [v2v] [actuator] [emergency] (laws = [...]) [delay_margin] (law, sweep, factors,
                   short; optional): the realistic scenario (:mod:`.realism`)
    [analysis]     module = "pNNN.name" (optional): a paper's module for what a
                   design cannot express (:func:`.spec._read_analysis`)

Laws are stateless: an expression of what the follower sees now, parsed
with :mod:`workbench.expr` (never evaluated as Python) and unit-checked.
Claimable quantities: :mod:`.quantities` (declared once, with units).
"""
from __future__ import annotations

from ...reader import Reader

__all__ = ["STUDY", "Platoon"]


class Platoon:
    """The ``platoon`` study (see the module docstring)."""

    kind = "platoon"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader):
        from .spec import load_spec
        return load_spec(root)

    def quantity_names(self, spec) -> set[str]:
        from ...features.quantities import names
        from .quantities import TABLE
        return names(TABLE, spec)

    def quantity_units(self, spec) -> dict[str, str]:
        """name -> unit of every claimable quantity (:mod:`.quantities`)."""
        from ...features.quantities import units
        from .quantities import TABLE
        return units(TABLE, spec)

    def run(self, design):
        from .run import run
        return run(design.spec)

    def quantities(self, res) -> dict:
        from ...features.quantities import values
        from .quantities import TABLE
        return values(TABLE, res.spec, res)


STUDY = Platoon()
