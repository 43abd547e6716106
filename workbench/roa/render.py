"""Markdown of a basin check: a pure function of :class:`~workbench.roa.check.BasinCheck`.

Levels are printed to 4 significant digits, c_certified rounded *down* and
c_refuted rounded *up* (the printed bracket still holds); box and sample
counts are not printed (they are not part of the result a second machine
must reproduce digit for digit).
"""
from __future__ import annotations

import math

from ..outcome import Outcome
from ..printed_grid import sig_round
from .check import BasinCheck


#: c_inner below this fraction of c_search is printed as that bound, not its
#: digits: it grows with the square of the equilibrium's residual f(x*), a
#: rounding-level number whose digits differ between CPUs and with the inputs'
#: last bits (2.75e-26 against 2.33e-26 with inputs moved 3 ulp, issue 36); a
#: residual that is no rounding error (1e-6 of the state scale) gives ~1e-12.
INNER_NEGLIGIBLE = 1e-12


def _sig(x: float, direction: str, digits: int = 4) -> str:
    if x == 0 or not math.isfinite(x):
        return "0" if x == 0 else "∞"
    how = math.floor if direction == "down" else math.ceil
    return f"{sig_round(x, digits, how):.{digits}g}"


def fmt_level(x: float, direction: str = "down") -> str:
    """A level to 4 significant digits, rounded ``direction`` ("down"/"up")."""
    return _sig(x, direction)


def render_basin_markdown(check: BasinCheck, *, heading: str = "### Region of attraction") -> str:
    """Markdown section of a basin check (heading, loop, V, bracket, points)."""
    est = check.estimate
    P = est.P
    rows = "; ".join("[" + ", ".join(f"{v:.4g}" for v in row) + "]" for row in P)
    names = ", ".join(est.names)
    eq = ", ".join(f"{v:.6g}" for v in est.x_eq)
    inner = ("0 (f(x*) = 0 exactly)" if est.c_inner == 0
             else f"< {INNER_NEGLIGIBLE:.0e} c_search (residual of the equilibrium: rounding)"
             if est.c_inner < INNER_NEGLIGIBLE * est.c_search
             else f"{fmt_level(est.c_inner, 'up')} (residual of the equilibrium)")
    lines = [
        heading, "",
        f"Loop: {check.loop}. State ({names}), equilibrium x* = ({eq}).",
        f"V = (x - x*)' P (x - x*), P = [{rows}] (from: {est.P_source}).", "",
        "| quantity | value |", "| --- | --- |",
        f"| c_certified (V' < 0 proven on {{c_inner < V <= c}}) | {fmt_level(est.c_certified)} |",
        f"| c_refuted (a point of that level has V' >= 0) | {fmt_level(est.c_refuted, 'up')} |",
        f"| levels searched up to | {fmt_level(est.c_search)} |",
        f"| ball argument (Taylor, interval Hessian) up to | {fmt_level(est.c_ball)} |",
        f"| c_inner | {inner} |", "",
        "Verification: interval arithmetic with outward rounding on an adaptive box cover "
        "of the annulus (a box may shrink to 2^-12 of its distance from x*); the neighbourhood of x* by "
        "Taylor's theorem with an interval bound of the Hessian of V'. Falsification: "
        f"seeded samples (seed {est.seed}), rays and SLSQP, each hit confirmed by interval "
        "arithmetic.",
    ]
    if check.points:
        lines += ["", "| state | " + " | ".join(est.names) + " | level V | verdict |",
                  "| --- |" + " --- |" * (len(est.names) + 2)]
        for p in check.points:
            v = p.verdict
            shown = {Outcome.CERTIFIED: "inside the certified basin (CERTIFIED)",
                     Outcome.REFUTED: "beyond the refuted level (REFUTED)",
                     Outcome.INCONCLUSIVE: "between the levels (INCONCLUSIVE)"}[v.outcome]
            coords = " | ".join(f"{c:.5g}" for c in p.x)
            lines.append(f"| {p.label} | {coords} | {fmt_level(v.level, 'up')} | {shown} |")
    return "\n".join(lines) + "\n"
