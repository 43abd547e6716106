"""The ``[tight]`` table: a Wirtinger-based synthesis next to the design's own
free-weighting row and the row a source printed.

A design whose loop x' = A x + B u(t - h) is swept by the free-weighting
synthesis over eps (:func:`workbench.synthesis.synthesize_delay_bound`) may
ask for the tighter synthesis of :mod:`workbench.lmi.tight_synthesis`
(Wirtinger inequality, its descriptor scalar searched automatically) and
compare three gains: the printed one (``[[synthesis.published]]``,
:mod:`workbench.features.published_rows`), the sweep's row at
``reference_eps`` and the tight one. Each gain is re-certified by the
Bessel-Legendre *analysis* LMI of order N and by the exact delay margin
(:func:`workbench.crosscheck.check_gain`, :func:`~workbench.crosscheck.check_tight`).

Design table::

    [tight]   enable = true, h_max = 10.0, grid = [0.01, ..., 100.0], order = 2,
              reference_eps = 0.35

Quantities: ``tight.<name>`` for each name of :data:`TIGHT_QUANTITIES`;
:func:`workbench.features.tight_compare_render.tight_section` renders them.

References
----------
.. [SG13] Seuret A., Gouaisbaut F., "Wirtinger-based integral inequality:
   application to time-delay systems", Automatica 49(9), 2013.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..reader import Reader

if TYPE_CHECKING:   # the solvers load when a design runs
    from ..crosscheck import PointCheck
    from ..lmi.tight_synthesis import TightSynthesis
    from ..margins import DelayMargin
    from ..synthesis import SynthesisRow, SynthesisSettings
    from .published_rows import Published

__all__ = ["TIGHT_QUANTITIES", "TightComparison", "TightSettings", "load_tight", "run_tight",
           "tight_quantities"]

#: Quantities of the ``[tight]`` comparison (prefixed ``tight.``).
TIGHT_QUANTITIES = ("eps", "h_certified", "h_analysis", "exact_margin", "exact_margin_siso",
                    "K1", "K2", "at_cap", "ratio_to_reference", "reference.h_analysis",
                    "paper_K.h_analysis", "paper_K.exact_margin")


@dataclass(frozen=True)
class TightSettings:
    """``[tight]``: Wirtinger-based synthesis beyond the free-weighting sweep.

    Attributes
    ----------
    h_max : float
        Delay search cap (s) of the synthesis and of the analysis checks.
    grid : tuple[float, ...]
        Log grid of the descriptor scalar eps (refined by golden section).
    order : int
        Bessel-Legendre order N of the analysis check of each gain.
    reference_eps : float
        Row of the free-weighting sweep (and of the printed table) to compare with.
    """

    h_max: float
    grid: tuple[float, ...]
    order: int
    reference_eps: float


@dataclass(frozen=True)
class TightComparison:
    """The tight synthesis next to the printed row and the sweep's row.

    Attributes
    ----------
    synthesis : TightSynthesis
    reference : SynthesisRow
        The sweep's row at ``reference_eps``.
    reference_check : PointCheck or None
        Bessel-Legendre bound and exact margin with that row's K.
    published : Published or None
        The printed row at ``reference_eps`` (if the design lists one).
    published_check : PointCheck or None
        Bessel-Legendre bound and exact margin with the printed K.
    open_loop_hurwitz : bool
        A itself is Hurwitz (then K = 0 is stable for every delay).
    check : PointCheck or None
        Bessel-Legendre analysis bound and exact margin with the tight K.
    exact_siso : DelayMargin or None
        python-control's single-input exact margin with the tight K.
    """

    synthesis: TightSynthesis
    reference: SynthesisRow
    reference_check: PointCheck | None
    published: Published | None
    published_check: PointCheck | None
    open_loop_hurwitz: bool
    check: PointCheck | None = None
    exact_siso: DelayMargin | None = None


def load_tight(root: Reader, eps: tuple[float, ...]) -> TightSettings | None:
    """The ``[tight]`` table (None when absent or ``enable = false``); ``eps``
    are the sweep's values, one of which is the reference."""
    if not root.has("tight"):
        return None
    t = root.table("tight")
    enable = t.boolean("enable", default=True)
    h_max = t.number("h_max", default=10.0, lo=1e-3, hi=1e3, what="number (s)")
    from .eps_sweep import read_grid
    grid = read_grid(t)
    order = t.number("order", default=2, integer=True, lo=0, hi=8, what="integer N")
    ref = t.number("reference_eps", default=eps[0], positive=True)
    if ref not in eps:
        raise t.fail("reference_eps", ref, "one of synthesis.eps " + str(list(eps)))
    t.finish()
    return TightSettings(h_max, grid, int(order), ref) if enable else None


def run_tight(A, B, ts: TightSettings, st: SynthesisSettings, rows,
              published: tuple[Published, ...] = ()) -> TightComparison:
    """Tight synthesis on x' = A x + B u(t - h), and the Bessel-Legendre +
    exact check of the reference gains (``rows``: the sweep's
    :class:`~workbench.synthesis.SynthesisRow` s, ``published``: printed rows)."""
    import numpy as np

    from ..crosscheck import check_gain, check_tight
    from ..lmi.tight_synthesis import synthesize_tight
    syn = synthesize_tight(A, B, eps_grid=ts.grid, h_max=ts.h_max,
                           margin=st.margin, rel_tol=max(st.rel_tol, 1e-3),
                           gain_fraction=st.gain_fraction, gain_digits=st.gain_digits)
    own = (check_tight(A, B, syn.K, N=ts.order, margin=st.margin, h_hi=ts.h_max)
           if syn.K is not None else None)

    def check(K):
        return check_gain([(A, B)], np.array([K]), N=ts.order, margin=st.margin,
                          h_hi=ts.h_max)[0]
    ref = next(r for r in rows if r.eps == ts.reference_eps)
    pub = next((p for p in published if p.eps == ts.reference_eps), None)
    return TightComparison(syn, ref, check(ref.K) if ref.K else None, pub,
                           check(pub.K) if pub else None,
                           bool(np.max(np.linalg.eigvals(A).real) < 0),
                           own.check if own else None, own.exact_siso if own else None)


def tight_quantities(t: TightComparison) -> dict:
    """name -> value of :data:`TIGHT_QUANTITIES` (prefixed ``tight.``)."""
    s, c = t.synthesis, t.check
    K = s.K.ravel() if s.K is not None else None
    q = {"eps": s.eps, "h_certified": s.h_certified if s.h_certified > 0 else None,
         "h_analysis": c.h_certified if c else None, "exact_margin": c.exact.h if c else None,
         "exact_margin_siso": t.exact_siso.h if t.exact_siso else None,
         "K1": None if K is None else float(K[0]), "K2": None if K is None else float(K[1]),
         "at_cap": "yes" if s.at_cap else "no",
         "ratio_to_reference": (s.h_certified / t.reference.h_certified
                                if s.h_certified > 0 and t.reference.h_certified > 0 else None),
         "reference.h_analysis": t.reference_check.h_certified if t.reference_check else None,
         "paper_K.h_analysis": t.published_check.h_certified if t.published_check else None,
         "paper_K.exact_margin": t.published_check.exact.h if t.published_check else None}
    return {f"tight.{k}": v for k, v in q.items()}
