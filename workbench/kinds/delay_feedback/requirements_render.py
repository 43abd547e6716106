"""The requirements table of a design to requirements (issue 31): pure rendering
of a :class:`workbench.requirements.RequirementResult` (Markdown)."""
from __future__ import annotations

import math

import numpy as np

from ...report.markdown import fmt, fmt_floor, md_table

__all__ = ["gain_text", "requirements_rows", "requirements_section", "requirements_table"]


def gain_text(K, digits: int) -> str:
    """A gain matrix as printed: rows in brackets, ``digits`` significant digits."""
    if K is None:
        return "—"
    K = np.atleast_2d(K)
    rows = ["[" + ", ".join(fmt(float(k), digits) for k in row) + "]" for row in K]
    return rows[0] if len(rows) == 1 else "[" + ", ".join(rows) + "]"


_WHAT = {
    "delay": ("certified: the largest cap H such that the rounded gain is certified stable for "
              "every constant delay in [0, H] (s, rounded down); exact: the worst decay rate on "
              "the range (1/s, > 0: stable)"),
    "decay": ("certified: decay rate of the rounded gain for every constant delay in the range "
              "and every vertex, Bessel-Legendre (N = 2) cells over the range (1/s, rounded "
              "down); exact: the worst rightmost root on a 61-point delay grid, with no "
              "crossing of Re s = −certified between grid points"),
    "l2_gain": ("certified: bounded-real descriptor LMI with P2, P3 free, every constant delay "
                "in [0, h_max] (rounded up); exact: the largest H-infinity norm of the delayed "
                "loop on the delay grid"),
    "input_limit": ("certified: 1 when an invariant ellipsoid contains the box of constant "
                    "initial histories and keeps |u_k| ≤ u_max,k; exact: peak |u_k| / u_max,k "
                    "of linear simulations from the box's vertices at h_min, mid-range and "
                    "h_max"),
}


def _ceil(x, sig: int = 2) -> str:
    """A positive upper bound rounded *up* to ``sig`` significant digits."""
    if x is None or not math.isfinite(x) or x <= 0:
        return fmt(x)
    q = 10.0 ** (math.floor(math.log10(x)) - (sig - 1))
    return fmt(math.ceil(x / q - 1e-12) * q, sig)


def requirements_table(spec, r) -> str:
    """The requirements table: required, certified, exact, verdict (Markdown)."""
    return requirements_rows(spec.requirements, r, spec.synthesis.settings.gain_digits)


def requirements_rows(req, r, digits: int) -> str:
    """The table of :func:`requirements_table` from a RequirementsSpec ``req``."""
    rows = []
    for row in r.rows:
        cert = row.certified
        if cert is not None:
            cert = (_ceil(cert) if row.name == "l2_gain" else
                    "yes" if row.name == "input_limit" else fmt_floor(cert, 2))
        rows.append([row.name, row.required, cert if cert is not None else "—",
                     fmt(row.exact, 3), f"**{row.verdict}**", req.sources.get(row.name, "")])
    K = gain_text(r.K, digits)
    return (md_table(["requirement", "required", "certified", "exact", "verdict", "source"],
                     rows, "llrrll") + f"\n\nGain (rounded, the gain every row is about): "
            f"K = {K}" + (f". No gain: {r.reason}" if r.K is None else "")
            + ".\n\n" + "\n".join(f"- *{k}*: {v}" for k, v in _WHAT.items()
                                   if any(row.name == k for row in r.rows)))


def requirements_section(spec, r) -> str:
    """The section that opens the report of a design with ``[requirements]``."""
    q = spec.requirements
    box = ("" if q.box is None else " Input limit from the box of initial deviations "
           + ", ".join(f"|δ{k}| ≤ {fmt(v)}" for k, v in q.box.items())
           + " (constant initial history, w = 0).")
    return (f"## Requirements\n\nObjective: **{q.objective}**, subject to the others; "
            f"delays: every constant delay in [{fmt(q.delay[0])}, {fmt(q.delay[1])}] s."
            + box + "\n\n" + requirements_table(spec, r))
