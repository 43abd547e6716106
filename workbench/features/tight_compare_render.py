"""Markdown of the ``[tight]`` comparison
(:mod:`workbench.features.tight_compare`; pure rendering)."""
from __future__ import annotations

import math

from ..report.markdown import fmt, md_table
from ..report.synthesis_text import (capped_text, closed_loop_eigs_text, exact_margin_text,
                                     gain_text)

__all__ = ["tight_section"]


def tight_section(t, A, B, reference_label: str) -> str:
    """``## Tight synthesis beyond the paper``: the gains of a
    :class:`~workbench.features.tight_compare.TightComparison` on x' = A x + B u(t - h);
    ``reference_label`` names the sweep's row in the table."""
    s, cap = t.synthesis, t.synthesis.h_max
    N = t.check.N if t.check else None
    rows = []

    def bl(c):
        return capped_text(c.h_certified, cap) if c else "—"

    def em(c):
        return exact_margin_text(c.exact) if c else "—"
    if t.published:
        p = t.published
        rows.append([f"paper, printed ({p.source})", fmt(p.eps), gain_text(p.K),
                     fmt(p.h_m, 4) + " (printed)", bl(t.published_check), em(t.published_check),
                     closed_loop_eigs_text(A, B, p.K)])
    r = t.reference
    rows.append([reference_label, fmt(r.eps), gain_text(r.K),
                 fmt(r.h_gain, 4), bl(t.reference_check), em(t.reference_check),
                 closed_loop_eigs_text(A, B, r.K)])
    rows.append(["tight: Wirtinger synthesis, eps searched", fmt(s.eps, 3), gain_text(s.K),
                 capped_text(s.gain.h_certified if s.gain else None, cap), bl(t.check), em(t.check),
                 closed_loop_eigs_text(A, B, s.K)])
    table = md_table(["design", "eps", "K", "certified h with this K, own LMI (s)",
                      f"certified h, Bessel-Legendre N = {N} analysis with this K (s)",
                      "exact margin h* (s)", "eigenvalues of A + BK (1/s)"], rows, "lrlrrrl")
    tried = md_table(["eps", "certified h (s)"],
                     [[fmt(e, 4), capped_text(h, cap)] for e, h in s.eps_tried], "rr")
    notes = [
        "The tight synthesis is the Wirtinger-based criterion of Seuret & Gouaisbaut (2013) with "
        "Fridman's descriptor slack P3 = eps P2, made linear by the congruence Y = P2⁻¹, V = K Y "
        "(`workbench/lmi/tight_synthesis.py`); eps is searched automatically (log grid, then "
        "golden section, stopping once the cap is reached), and each eps is a certified, "
        f"re-checked bisection on h (best bound {capped_text(s.h_certified, cap)} s). Its gain is the "
        "canonical one, as above (minimum-norm certificate at the chosen fraction of that "
        "bound, rounded), and the third column is what that gain certifies with K fixed. Every "
        "gain is then re-certified by the Bessel-Legendre *analysis* LMI (independent of the "
        "synthesis LMI) and by the exact delay margin.",
    ]
    if t.check is not None and s.at_cap and math.isinf(t.check.exact.h):
        notes.append(
            f"**The tight bound is the search cap, not a limit.** The synthesis certifies the "
            f"cap h_max = {fmt(cap, 4)} s and the exact margin with its gain is infinite, so the "
            "largest certifiable delay is bounded only by h_max: raising the cap raises the "
            "number. It says *at least* h_max, nothing more.")
    if t.open_loop_hurwitz:
        notes.append(
            "**Why the tight gain is so small.** A is already Hurwitz (see the eigenvalues "
            "above), so K = 0 is stable for every delay; maximising the certified delay alone "
            "is therefore a degenerate objective on this plant, and the synthesis returns a "
            "gain close to zero. The comparison that matters is the Bessel-Legendre column: "
            "the *same* gains judged by a tighter analysis criterion. A meaningful tight design "
            "needs an objective besides the delay (a decay rate or a bandwidth like the "
            "paper's gain), which this section does not impose.")
    if t.published_check is not None:
        c = t.published_check
        reach = (f"up to the search cap ({fmt(cap, 4)} s)" if c.h_certified >= cap
                 else f"up to {fmt(c.h_certified, 4)} s")
        notes.append(
            f"The printed gain's bound {fmt(t.published.h_m, 4)} s is the free-weighting "
            f"criterion's conservatism: the Bessel-Legendre analysis certifies that very gain "
            f"{reach}, and its exact margin is {em(c)}.")
    notes.append("The last column is the delay-free closed loop A + BK, to compare with the "
                 "open-loop eigenvalues of A above.")
    return ("## Tight synthesis beyond the paper\n\n" + table + "\n\n"
            + "\n\n".join(notes)
            + "\n\n<details><summary>eps search of the tight synthesis</summary>\n\n"
            + tried + "\n\n</details>")
