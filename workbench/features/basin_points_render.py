"""Markdown tables of judged states (and what their verdicts mean) and of a
gain sweep, and the sentence of the sweep's certified range (pure rendering of
:class:`~workbench.roa.check.BasinCheck` points and of
:class:`~workbench.features.basin_points.GainSweep`); the headings and the
words around them are the caller's."""
from __future__ import annotations

from ..report.markdown import fmt, md_table
from ..roa.render import fmt_level


def points_table(check, fates, header, *, shift=None, digits: int = 4) -> str:
    """One row per judged state: its label, coordinates (plus ``shift``, e.g.
    back to absolute ones; ``digits`` significant digits), level V (rounded
    up), verdict and the fate of its trajectory (``fates``, one per state).
    ``header``: the column titles (label, one per coordinate, V, verdict, fate)."""
    rows = []
    for p, fate in zip(check.points, fates):
        xs = p.x if shift is None else [x + s for x, s in zip(p.x, shift)]
        rows.append([f"`{p.label}`", *(fmt(x, digits) for x in xs),
                     fmt_level(p.verdict.level, "up"), p.verdict.outcome.name, fate])
    n = len(header) - 4
    return md_table(header, rows, "l" + "r" * (n + 1) + "ll")


def points_verdict_text(kind: str, escape: str) -> str:
    """What the verdict and fate columns of :func:`points_table` mean, for a
    loop described by the adjective ``kind`` (e.g. "delay-free"); ``escape``:
    what its escape word means (in parentheses at the end)."""
    return (f"CERTIFIED: V at the state is below c_certified, so the {kind} loop converges "
            "from it. REFUTED: its level holds a point with V' >= 0, so this V cannot certify "
            f"it; the last column says what the {kind} trajectory does ({escape}).")


def gain_sweep_table(sweep, header, *, digits=None) -> str:
    """One row per gain of a :class:`~workbench.features.basin_points.GainSweep`
    (grid and bisection rows, then the gains compared): its entries (``digits``
    significant digits per entry, default 4), source, verdict, deciding
    candidate and fate. ``header``: the column titles."""
    n = len(sweep.gain)
    digits = digits or (4,) * n
    rows = [[*(fmt(g, d) for g, d in zip(r.gain, digits)), r.source, r.verdict.outcome.name,
             fmt(r.verdict.w), r.verdict.fate] for r in (*sweep.rows, *sweep.compared)]
    return md_table(header, rows, "r" * n + "llrl")


def gain_edge_text(sweep, entry: str, state: str, *, kept: str = "") -> str:
    """The certified range of a :class:`~workbench.features.basin_points.GainSweep`
    in one sentence: ``state`` lands in a certified basin for ``entry`` up to the
    edge's lower end and not from its upper end (``kept``: the words before, e.g.
    the entries held; only when an edge was found)."""
    if sweep.edge is None:
        return "No edge between certified and non-certified gains was found on the grid."
    lo, hi = (fmt(e, 4) for e in sweep.edge)
    return (f"{kept}{state} lands in a certified basin for {entry} <= {lo} (every grid value "
            f"from {fmt(sweep.grid_min)} up to it is certified"
            + ("" if sweep.certified_below_edge else " — except where the table says not")
            + f"), and not for {entry} >= {hi}: the edge lies in [{lo}, {hi}] (bisected).")
