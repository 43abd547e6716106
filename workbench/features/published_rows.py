"""Rows a paper printed against what we compute: ``[[synthesis.published]]``.

A design that sweeps the free-weighting synthesis over eps
(:func:`workbench.synthesis.synthesize_delay_bound`) may list rows a source
printed: eps, the delay bound h_m and the gain K. They are data for the
comparison only, never inputs to the synthesis. For each printed row
:func:`check_published` finds, on the design's own loop x' = A x + B u(t - h):

* our certified bound at the same eps (if that eps is in the sweep);
* what the **printed gain** certifies under the very same criterion (V = K L
  fixed, :func:`workbench.synthesis.certify_given_gain`);
* the exact delay margin of the loop closed with the printed gain
  (:func:`workbench.margins.delay_margin_eig`);
* the eps at which our bound equals the printed h_m
  (:func:`workbench.features.eps_match.eps_matching`, searched in
  [min eps / 2, 1.5 max eps] of the sweep).

Design table (inside ``[synthesis]``)::

    [[synthesis.published]]   eps = 0.35, h_m = 0.0433, K = [k1, ..., kn], source = "..."

Quantities: ``published[eps=E].h_paper_K`` (s), ``.exact_margin_paper_K``
(s) and ``.eps_matching``; :func:`published_section` renders the table.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..reader import Reader
from .other_gains import gain_entries

if TYPE_CHECKING:
    from ..margins import DelayMargin

__all__ = ["Published", "PublishedCheck", "check_published", "load_published",
           "published_quantities", "published_quantity_names", "published_section"]


@dataclass(frozen=True)
class Published:
    """A row a source printed: eps, h_m and K (for comparison only)."""

    eps: float
    h_m: float
    K: tuple[float, ...]
    source: str


@dataclass(frozen=True)
class PublishedCheck:
    """What we find for a printed row.

    Attributes
    ----------
    row : Published
    h_ours : float or None
        Our h_certified at the same eps (None if eps not in the sweep).
    h_paper_K : float
        Largest delay the same criterion certifies with the printed K.
    h_paper_K_refuted : float
    exact_paper_K : DelayMargin
        Exact margin of the loop closed with the printed K.
    eps_matching : float or None
        The eps at which our bound equals the printed h_m (None: not found
        in [eps_lo, eps_hi] of the sweep).
    """

    row: Published
    h_ours: float | None
    h_paper_K: float
    h_paper_K_refuted: float
    exact_paper_K: DelayMargin
    eps_matching: float | None


def _key(eps: float) -> str:
    return f"{eps:g}"


def load_published(syn: Reader, n: int = 2) -> tuple[Published, ...]:
    """``[[synthesis.published]]`` of the ``[synthesis]`` table ``syn`` (none
    when absent); ``n`` entries per K (single input)."""
    out = []
    for pr in syn.tables("published", default=[]):
        e = pr.number("eps", positive=True)
        h = pr.number("h_m", positive=True)
        K = gain_entries(pr, n)
        out.append(Published(e, h, K, pr.string("source")))
        pr.finish()
    return tuple(out)


def check_published(A, B, rows, published, eps, settings) -> tuple[PublishedCheck, ...]:
    """Each printed row on the loop (A, B): see the module docstring.

    Parameters
    ----------
    A, B : numpy.ndarray
    rows : tuple[workbench.synthesis.SynthesisRow, ...]
        Our sweep over ``eps``.
    published : tuple[Published, ...]
    eps : tuple[float, ...]
        The sweep's eps values (they set the range of the eps match).
    settings : workbench.synthesis.SynthesisSettings
    """
    import numpy as np

    from ..margins import delay_margin_eig
    from ..synthesis import certify_given_gain
    from .eps_match import eps_matching
    eps_lo, eps_hi = min(eps) / 2, max(eps) * 1.5
    out = []
    for p in published:
        ours = next((r.h_certified for r in rows if r.eps == p.eps), None)
        K = np.array([p.K])
        br = certify_given_gain(A, B, K, p.eps, settings)
        em = delay_margin_eig(A, B @ K)
        match = eps_matching(A, B, p.h_m, eps_lo, eps_hi, settings)
        out.append(PublishedCheck(p, ours, br.h_certified, br.h_refuted, em, match))
    return tuple(out)


def published_quantity_names(published) -> set[str]:
    """The quantities of the module docstring for these rows."""
    return {f"published[eps={_key(p.eps)}].{f}" for p in published
            for f in ("h_paper_K", "exact_margin_paper_K", "eps_matching")}


def published_quantities(checks) -> dict:
    """Values of :func:`published_quantity_names`."""
    q = {}
    for c in checks:
        base = f"published[eps={_key(c.row.eps)}]"
        q[f"{base}.h_paper_K"] = c.h_paper_K
        q[f"{base}.exact_margin_paper_K"] = c.exact_paper_K.h
        q[f"{base}.eps_matching"] = c.eps_matching
    return q


def published_section(checks) -> str:
    """``## Comparison with the printed table``."""
    from ..report.markdown import fmt, md_table
    from ..report.synthesis_text import exact_margin_text
    prow = []
    for c in checks:
        p = c.row
        prow.append([fmt(p.eps), fmt(p.h_m, 4), fmt(c.h_ours, 4),
                     "[" + ", ".join(fmt(k, 5) for k in p.K) + "]",
                     f"{fmt(c.h_paper_K, 4)}", fmt(c.eps_matching, 3),
                     exact_margin_text(c.exact_paper_K), p.source])
    return ("## Comparison with the printed table\n\n"
            + md_table(["eps", "printed h_m (s)", "ours h_certified (s)", "printed K",
                        "printed K certifies (same LMI, s)", "eps giving printed h_m",
                        "h* with printed K (s)", "source"], prow, "rrrlrrrl")
            + "\n\nFor each printed row: the bound our certified bisection finds at the same "
            "eps; what the **printed gain** certifies under the very same criterion (V = K L "
            "fixed); the eps at which our bound would equal the printed value; and the exact "
            "margin of the loop closed with the printed gain. A printed bound below what its "
            "own gain certifies, or matched only at another eps, is evidence of a slip in the "
            "printed row, not of a looser criterion.")
