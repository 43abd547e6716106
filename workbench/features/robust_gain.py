"""One state-feedback gain for a family of linear delay loops
x' = A_i x + B_i u(t - h) at listed operating points, with a decay rate.

:func:`run_robust` runs the descriptor synthesis with common Y and V
(:func:`workbench.lmi.robust.synthesize_robust`, eps searched on a log grid
then by golden section), then re-checks the rounded canonical gain at every
point (:func:`workbench.crosscheck.check_gain`: stability at h = 0, exact
delay margin, Bessel-Legendre analysis of order N) and computes the spectral
abscissa at the delay that gain certifies. The certificate holds at the listed
points only. The points themselves (their plant, their linearisation) are the
design's; this module takes them as (A_i, B_i) pairs with ids.

Design keys (inside ``[synthesis]``, :func:`load_robust_settings`): alpha,
eps_grid, golden_steps, rel_tol, h_max, margin, analysis_order,
gain_fraction, gain_digits. Quantities: :func:`robust_quantity_names`.

References
----------
.. [FR01] Fridman E., "New Lyapunov-Krasovskii functionals for stability of
   linear retarded and neutral type systems", Systems & Control Letters 43
   (2001) 309-319 (descriptor method).
.. [FS02] Fridman E., Shaked U., "An improved stabilization method for linear
   time-delay systems", IEEE TAC 47(11), 2002 (P3 = eps P2, Y = P2^{-1}).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from ..reader import Reader

if TYPE_CHECKING:   # the solvers load when a design runs
    from ..crosscheck import PointCheck
    from ..lmi.robust import RobustSynthesis

__all__ = ["RobustGain", "RobustSettings", "load_robust_settings", "robust_quantities",
           "robust_quantity_names", "run_robust"]


@dataclass(frozen=True)
class RobustSettings:
    """The ``[synthesis]`` settings of a robust gain.

    Attributes
    ----------
    alpha : float
        Exponential decay rate (1/s) certified at the delay.
    eps_grid : tuple[float, ...]
        Log grid of the descriptor scalar eps.
    golden_steps : int
        Golden-section steps of the eps search after the grid.
    rel_tol, h_max, margin : float
        Bisection tolerance (relative), delay search cap (s), LMI margin.
    order : int
        Bessel-Legendre order N of the per-point analysis check.
    gain_fraction, gain_digits : float, int
        The canonical gain's fraction of the bound and its significant digits.
    """

    alpha: float
    eps_grid: tuple[float, ...]
    golden_steps: int
    rel_tol: float
    h_max: float
    margin: float
    order: int
    gain_fraction: float
    gain_digits: int


def load_robust_settings(syn: Reader) -> RobustSettings:
    """Read the robust synthesis keys of a ``[synthesis]`` table (the caller
    calls ``syn.finish()``)."""
    from ..lmi.core import DEFAULT_MARGIN
    from ..lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION
    from .eps_sweep import EPS_RANGE
    return RobustSettings(
        alpha=syn.number("alpha", nonneg=True, hi=10.0, what="decay rate (1/s)"),
        eps_grid=syn.numbers("eps_grid", positive=True, min_len=2, what="eps values",
                             lo=EPS_RANGE[0], hi=EPS_RANGE[1]),
        golden_steps=int(syn.number("golden_steps", default=3, integer=True, lo=0, hi=20)),
        rel_tol=syn.number("rel_tol", default=1e-2, positive=True, hi=0.1),
        h_max=syn.number("h_max", default=10.0, lo=1e-3, hi=1e4, what="number (s)"),
        margin=syn.number("margin", default=DEFAULT_MARGIN, positive=True, hi=1e-2),
        order=int(syn.number("analysis_order", default=2, integer=True, lo=0, hi=6)),
        gain_fraction=syn.number("gain_fraction", default=DEFAULT_FRACTION, positive=True,
                                 hi=1.0, what="fraction of h_certified"),
        gain_digits=int(syn.number("gain_digits", default=DEFAULT_DIGITS, integer=True,
                                   lo=2, hi=8)))


@dataclass(frozen=True)
class RobustGain:
    """The robust synthesis and its per-point checks.

    Attributes
    ----------
    settings : RobustSettings
    synthesis : RobustSynthesis
    checks : tuple[PointCheck, ...]
        The gain's check at every point (empty without a gain).
    abscissa : tuple[float, ...]
        Spectral abscissa (1/s) at the delay the gain certifies, per point.
    """

    settings: RobustSettings
    synthesis: RobustSynthesis
    checks: tuple[PointCheck, ...]
    abscissa: tuple[float, ...]


def run_robust(points, s: RobustSettings) -> RobustGain:
    """The robust gain of ``points`` ((A_i, B_i) pairs) and its checks."""
    from ..crosscheck import check_gain
    from ..lmi.robust import synthesize_robust
    from ..margins import spectral_abscissa
    pts = list(points)
    syn = synthesize_robust(pts, alpha=s.alpha, eps_grid=s.eps_grid,
                            golden_steps=s.golden_steps, rel_tol=s.rel_tol,
                            margin=s.margin, h_hi=s.h_max, gain_fraction=s.gain_fraction,
                            gain_digits=s.gain_digits)
    checks, absc = (), ()
    if syn.K is not None:
        checks = check_gain(pts, syn.K, N=s.order, margin=s.margin)
        h = syn.gain.h_certified          # what the rounded canonical K certifies
        absc = tuple(spectral_abscissa(A, B @ syn.K, h) for A, B in pts)
    return RobustGain(s, syn, checks, absc)


def robust_quantity_names(ids, n_states: int) -> set[str]:
    """``synthesis.*`` (K1..Kn: the first input's row of K), ``robust.*`` and
    ``points[ID].*`` of a robust gain at the points ``ids``."""
    names = {"synthesis.h_certified", "synthesis.h_gain", "synthesis.eps",
             "robust.all_stable", "robust.min_exact_margin", "robust.max_abscissa_at_h",
             "robust.min_exact_over_certified"}
    names |= {f"synthesis.K{j + 1}" for j in range(n_states)}
    return names | {f"points[{i}].{f}" for i in ids
                    for f in ("exact_margin", "h_certified", "abscissa_at_h")}


def robust_quantities(ids, n_states: int, r: RobustGain) -> dict:
    """Values of :func:`robust_quantity_names` (``None``: not determined)."""
    syn = r.synthesis
    h = syn.bracket.h_certified
    h_gain = syn.gain.h_certified if syn.gain else 0.0
    q = {"synthesis.h_certified": h if h > 0 and syn.K is not None else None,  # no gain
         "synthesis.h_gain": h_gain if h_gain > 0 else None, "synthesis.eps": syn.eps}
    q |= {f"synthesis.K{j + 1}": None if syn.K is None else float(syn.K[0, j])
          for j in range(n_states)}
    if r.checks:
        q["robust.all_stable"] = "yes" if all(c.stable_at_zero for c in r.checks) else "no"
        q["robust.min_exact_margin"] = min(c.exact.h for c in r.checks)
        q["robust.max_abscissa_at_h"] = max(r.abscissa)
        q["robust.min_exact_over_certified"] = (min(c.exact.h for c in r.checks) / h_gain
                                                if h_gain > 0 else None)
        for i, c, a in zip(ids, r.checks, r.abscissa):
            q[f"points[{i}].exact_margin"] = c.exact.h
            q[f"points[{i}].h_certified"] = c.h_certified
            q[f"points[{i}].abscissa_at_h"] = a
    return q
