"""The verdict of a one-state loop in words (pure rendering of a
:class:`~workbench.features.basin_scalar.ScalarVerdict`): a table cell saying
why the state is, or is not, in a basin, and the table of
:class:`~workbench.features.basin_scalar.FrozenSwitch` results. Proven bounds
are printed to 2 significant digits, rounded in their safe direction (a rate
down, a time up); the headings and the words around the table are the caller's."""
from __future__ import annotations

from ..printed_grid import directed
from ..report.markdown import fmt, md_table
from ..roa.render import fmt_level


def _directed(x: float, up: bool) -> str:
    """x rounded up or down to 2 significant digits (a proven bound's direction)."""
    return fmt(directed(x, up=up, sig=2), 2)


def scalar_verdict_text(sv, x_s: float, limit: float, *, name: str = "x",
                        rate_unit: str = "1/s") -> str:
    """Why the state ``x_s`` of a one-state loop on [-limit, limit] (``name``: the
    state's display name, ``rate_unit`` that of its rate; time in s) has the verdict ``sv``: no equilibrium up
    to the end it moves to (the proven rate, and the time within which it gets
    there), the equilibrium it moves to (with the level set's V and c_certified),
    or why nothing is proven."""
    if sv.why == "no equilibrium":
        up = sv.direction > 0
        return (f"no equilibrium from the state {'up to' if up else 'down to'} {name} = "
                f"{'' if up else '−'}{fmt(limit)}: |{name}'| >= "
                f"{_directed(sv.rate, False)} {rate_unit} proven, so it gets there within "
                f"{_directed((limit - sv.direction * x_s) / sv.rate, True)} s")
    if sv.star is not None:
        return (f"equilibrium {name}* = {fmt(sv.star, 4)} ({sv.why}"
                + (f"; V = {fmt_level(sv.level[0], 'up')}, c_certified = "
                   f"{fmt_level(sv.level[1])}" if sv.level else "") + ")")
    return sv.why.replace("sign not", f"sign of {name}' not")


def scalar_method_text(limit: float, *, name: str = "x") -> str:
    """How :func:`~workbench.features.basin_scalar.scalar_verdict` judges a
    state of a loop frozen to one state on [-limit, limit] (``name``: the
    state's display name), in one sentence for a report."""
    return (f"The frozen loop has one state, {name}' = g({name}), so its trajectory moves "
            "monotonically to the nearest equilibrium in the direction of g: the verdict is "
            f"REFUTED when no equilibrium lies between the state and |{name}| = {fmt(limit)} "
            "(the sign of g proven by interval arithmetic on the whole interval), CERTIFIED "
            "when the state reaches a certified level set of a stable equilibrium (a level "
            "set of `workbench/roa`, with the sign of g proven on the way to it).")


def frozen_switch_table(switches, header, limit: float, *, index: int, name: str = "x",
                        at: str = "the switch") -> str:
    """One row per :class:`~workbench.features.basin_scalar.FrozenSwitch`: its
    label, state (4 significant digits), reference held, the frozen loop's
    verdict in words (:func:`scalar_verdict_text` of the state ``index`` on
    [-limit, limit], ``name``: its display name), outcome, and the fate of the
    time-varying loop (an escape with its time: "|name| = limit at ``at`` + t s").
    ``header``: the column titles (label, one per state, reference, verdict
    text, outcome, fate)."""
    rows = []
    for b in switches:
        fate = (b.fate if b.t_fate is None
                else f"{b.fate}: |{name}| = {fmt(limit)} at {at} + {fmt(b.t_fate, 2)} s")
        rows.append([f"`{b.label}`", *(fmt(x, 4) for x in b.x), fmt(b.reference, 4),
                     scalar_verdict_text(b.verdict, b.x[index], limit, name=name),
                     b.outcome.name, fate])
    return md_table(header, rows, "l" + "r" * (len(header) - 4) + "lll")
