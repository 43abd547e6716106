"""What an ``[analysis]`` module's runs need of its ``stop-accuracy`` design,
checked in one place: the controllers it names (with their named modules),
the grid's factors and ``feasible_with``, the faults, the constants and the
optional tables. A design that lacks any of them fails on
``analysis.module`` with one message (exit 2) that says what the module needs
and what is missing.
"""
from __future__ import annotations

__all__ = ["TABLES", "missing", "require"]

#: spec attribute -> the design table it is read from
TABLES = {"command": "[target] command", "reference": "[reference]",
          "sections": "[[sections]]", "montecarlo": "[montecarlo]"}


def missing(spec, *, controllers=(), loops=(), pids=(), grid=(), feasible_with=None,
            faults=(), constants=(), tables=()) -> list[str]:
    """What of the named parts ``spec`` lacks (empty: nothing).

    Parameters
    ----------
    spec : StopAccuracySpec
    controllers : iterable of str
        Controllers the module runs by name.
    loops, pids : iterable of str
        Of those, the ones that need the named module ``deceleration_loop`` or ``pid``.
    grid : iterable of str
        The factors of ``[grid]``, exactly; ``feasible_with`` its feasibility controller.
    faults, constants : iterable of str
        ``[[faults]]`` and constants the module reads by name.
    tables : iterable of str
        Keys of :data:`TABLES` the module needs.
    """
    have = {c.name: c for c in spec.controllers}
    out = [k for k in controllers if k not in have]
    out += [f"deceleration_loop in {k}" for k in loops if k in have and have[k].loop is None]
    out += [f"pid in {k}" for k in pids if k in have and have[k].pid is None]
    if grid and set(dict(spec.grid)) != set(grid):
        out.append("[grid] of " + ", ".join(grid))
    if feasible_with is not None and spec.grid_feasible != feasible_with:
        out.append(f"feasible_with = {feasible_with}")
    out += [f"fault {k}" for k in faults if k not in {f.name for f in spec.faults}]
    out += [f"constant {k}" for k in constants if k not in spec.constants]
    out += [TABLES[t] for t in tables if getattr(spec, t) is None]
    return out


def require(root, spec, module: str, **needs) -> None:
    """Raise the design error of ``analysis.module`` (exit 2, one line) unless
    ``spec`` has every part of ``needs`` (the keywords of :func:`missing`)."""
    gaps = missing(spec, **needs)
    if not gaps:
        return
    parts = ["the controllers " + ", ".join(needs.get("controllers", ()))]
    for key, what in (("loops", "deceleration_loop in"), ("pids", "pid in")):
        if needs.get(key):
            parts.append(f"{what} " + ", ".join(needs[key]))
    if needs.get("grid"):
        parts.append("a [grid] of " + ", ".join(needs["grid"]) + (
            f" feasible_with {needs['feasible_with']}" if needs.get("feasible_with") else ""))
    for key, what in (("faults", "the faults"), ("constants", "the constants")):
        if needs.get(key):
            parts.append(f"{what} " + ", ".join(needs[key]))
    parts += [TABLES[t] for t in needs.get("tables", ())]
    raise root.fail("analysis.module", module, "a design with " + "; ".join(parts)
                    + " (missing: " + ", ".join(gaps) + ")")
