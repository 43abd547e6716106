"""Printed forms of synthesis results shared by the reports of every kind that
synthesises a delay-feedback gain (``delay-feedback``, ``antiskid-cruise``) and
by the gain comparisons of :mod:`workbench.features` (``eps_sweep``,
``other_gains``, ``published_rows``): exact margins, capped certified bounds,
closed-loop eigenvalues and the per-block re-check table of a certificate.
"""
from __future__ import annotations

import numpy as np

from .markdown import fmt, margin_text, md_table

__all__ = ["capped_text", "closed_loop_eigs_text", "exact_margin_text", "gain_text",
           "recheck_table"]


def gain_text(K, digits: int = 4) -> str:
    """A gain matrix as printed: rows in brackets, ``digits`` significant
    digits (one row: ``[k1, k2]``); ``—`` for None."""
    if K is None:
        return "—"
    K = np.atleast_2d(K)
    rows = ["[" + ", ".join(fmt(float(k), digits) for k in row) + "]" for row in K]
    return rows[0] if len(rows) == 1 else "[" + ", ".join(rows) + "]"


def exact_margin_text(dm) -> str:
    """An exact delay margin as printed: 5 significant digits, ``∞``, or
    ``0 (unstable at h = 0)``; ``—`` for None."""
    if dm is None:
        return "—"
    if dm.reason == "unstable-at-zero-delay":
        return "0 (unstable at h = 0)"
    return fmt(dm.h, 5)


def capped_text(h, cap) -> str:
    """A certified bound, marked when it is the search cap (a lower bound only)."""
    if h is None:
        return "—"
    return f"≥ {fmt(cap, 4)} (cap)" if h >= cap else fmt(h, 4)


def closed_loop_eigs_text(A, B, K) -> str:
    """Eigenvalues of A + B K (delay-free closed loop), 1/s."""
    if K is None:
        return "—"
    ev = sorted(np.linalg.eigvals(A + B @ np.atleast_2d(np.asarray(K, float))),
                key=lambda z: (z.real, z.imag))
    return ", ".join(fmt(complex(e).real, 3) if abs(complex(e).imag) < 1e-9
                     else f"{fmt(complex(e).real, 3)} ± {fmt(abs(complex(e).imag), 3)}j"
                     for e in ev if complex(e).imag >= -1e-9)


def recheck_table(res) -> str:
    """Per-block re-check margins of every canonical certificate (``res.rows``,
    :class:`workbench.synthesis.SynthesisRow`), as decades, in a <details> block."""
    rows = [r for r in res.rows if r.recheck]
    if not rows:
        return ""
    names = list(rows[0].recheck)
    body = [[b] + [margin_text(r.recheck[b]) for r in rows] for b in names]
    return ("<details><summary>Re-check: relative margin of every LMI block of the canonical "
            "certificate (numpy eigenvalues; must be ≥ the margin)</summary>\n\n"
            + md_table(["block"] + [f"eps = {fmt(r.eps)}" for r in rows], body,
                       "l" + "r" * len(rows))
            + "\n\nShown as the decade the margin lies in: a solver's internal values "
            "agree between machines only to a few digits.\n\n</details>")
