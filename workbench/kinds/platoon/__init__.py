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
Claimable quantities: ``<run>.<metric>`` (max_abs_e, cruise_abs_e, ...),
``<a>_over_<b>.max_abs_e`` of two runs from exact spacing, ``convergence.*``
(with ``[reaching]``), ``emergency.*``, ``delay_margin.*``, ``delay_sweep.*``,
``leader.v_cruise``, and the ``[analysis]`` module's.
"""
from __future__ import annotations

from ...reader import Reader

__all__ = ["METRICS", "STUDY", "Platoon"]

#: Per-run metrics a claim may name (``<run>.<metric>``).
METRICS = ("max_abs_e", "cruise_abs_e", "cruise_abs_de", "chatter", "sign_rate",
           "lumped_ratio", "string_ratio", "max_speed")
_REACH = ("t_reach", "e_reach", "slide_eq22", "slide_band", "slide_measured")


def _ratio_runs(spec) -> list[str]:
    return [r.name for r in spec.runs if r.initial_errors is None]


class Platoon:
    """The ``platoon`` study (see the module docstring)."""

    kind = "platoon"
    uses_solver = False    # no convex solver runs: the report says so

    def load(self, root: Reader):
        from .spec import load_spec
        return load_spec(root)

    def quantity_names(self, spec) -> set[str]:
        from .realism import realism_quantity_names
        names = {f"{r.name}.{k}" for r in spec.runs for k in METRICS} | {"leader.v_cruise"}
        ex = _ratio_runs(spec)
        names |= {f"{a}_over_{b}.max_abs_e" for a in ex for b in ex if a != b}
        if spec.reaching is not None:
            names |= {"convergence.max_reaching_time", "convergence.max_rel_error_band",
                      "convergence.max_ratio_eq22"}
            for i in range(2, spec.n + 1):
                names |= {f"convergence.train{i}.{k}" for k in _REACH}
        if spec.analysis is not None:
            names |= spec.analysis.quantity_names(spec)
        return names | realism_quantity_names(spec)

    def run(self, design):
        from .run import run
        return run(design.spec)

    def quantities(self, res) -> dict:
        from .realism import realism_quantities
        spec = res.spec
        q = {"leader.v_cruise": res.profile.v_cruise}
        for name, m in res.metrics.items():
            q[f"{name}.max_abs_e"] = max(m.max_abs_e)
            q[f"{name}.cruise_abs_e"] = max(m.cruise_abs_e)
            q[f"{name}.cruise_abs_de"] = max(m.cruise_abs_de)
            q[f"{name}.chatter"] = max(m.chatter)
            q[f"{name}.sign_rate"] = max(m.sign_rate)
            q[f"{name}.lumped_ratio"] = m.lumped_ratio
            q[f"{name}.string_ratio"] = m.string_ratio
            q[f"{name}.max_speed"] = max(m.max_speed)
        ex = _ratio_runs(spec)
        for a in ex:
            for b in ex:
                if a != b:
                    den = q[f"{b}.max_abs_e"]
                    q[f"{a}_over_{b}.max_abs_e"] = q[f"{a}.max_abs_e"] / den if den else None
        if spec.reaching is not None:
            for i, c in enumerate(res.convergence):
                for k in _REACH:
                    q[f"convergence.train{i + 2}.{k}"] = getattr(c, k)
            done = [c for c in res.convergence if c.slide_measured is not None]
            ok = len(done) == len(res.convergence) and bool(done)
            q["convergence.max_reaching_time"] = max(c.t_reach for c in done) if ok else None
            q["convergence.max_rel_error_band"] = max(
                abs(c.slide_measured / c.slide_band - 1.0) for c in done) if ok else None
            q["convergence.max_ratio_eq22"] = max(
                c.slide_measured / c.slide_eq22 for c in done) if ok else None
        q.update(realism_quantities(res.realism))
        if spec.analysis is not None:
            q.update(spec.analysis.quantities(spec, res))
        return q


STUDY = Platoon()
