"""Exact delay margins, stability windows and the spectral abscissa, independent
of any LMI.

For x' = A x + A_d x(t - h) the *exact delay margin* h* is the largest h
such that the system is asymptotically stable for every constant delay in
[0, h*). It is

* ``0`` when A + A_d is not Hurwitz (unstable, or not asymptotically
  stable, without delay);
* ``inf`` when no characteristic root ever reaches the imaginary axis: then
  the loop is stable for *every* constant delay ("delay-independent"), and
  any finite LMI bound is conservatism of the criterion, not a property of
  the loop;
* otherwise the smallest delay at which a root s = j w, w > 0, crosses.

Beyond h* the system may regain stability: :func:`stability_windows` gives the
exact stability set up to a horizon from every crossing and its direction.

Two independent exact computations, cross-checked by :func:`exact_margin`:

:func:`delay_margin_eig`
    Chen, Gu & Nett (1995): the unit-circle eigenvalues of a 2 n^2 pencil
    (O(n^6); n < 15).
:func:`delay_margin_sweep`
    A sweep of the delay phase theta following every eigenvalue branch of
    A + A_d e^{-j theta} (O(n^3) per grid point; any n).
:func:`delay_margin_siso`
    For A_d = B K with one input: python-control's ``stability_margins``.

:func:`spectral_abscissa` / :func:`rightmost_roots` give the rightmost roots at
one delay (adaptive Chebyshev collocation, Newton-polished).

Every tolerance is relative (to R = ||A||_2 + ||A_d||_2 or dimensionless in the
phase): (c A, c A_d) gives h* / c and windows / c. Every public function checks
its input and raises ``ValueError`` with what was found and what was expected.

References
----------
.. [CGN95] Chen J., Gu G., Nett C.N., "A new method for computing delay
   margins for stability of linear delay systems", Systems & Control
   Letters 26 (1995) 107-117.
.. [GKC03] Gu K., Kharitonov V.L., Chen J., *Stability of Time-Delay
   Systems*, Birkhauser 2003, ch. 2.
.. [BMV05] Breda D., Maset S., Vermiglio R., SIAM J. Sci. Comput. 27 (2005) 482-495.
"""
from __future__ import annotations

from .crossings import Crossing, CrossingSet, kronecker_crossings, phase_crossings, scale
from .delay import (AGREEMENT_RTOL, KRONECKER_MAX_N, Agreement, DelayMargin, ExactMargin,
                    compare_margins, delay_margin_eig, delay_margin_siso, delay_margin_sweep,
                    exact_margin, is_hurwitz, relative_difference, stability_windows,
                    windows_from_crossings)
from .spectrum import Spectrum, SpectrumNotConverged, rightmost_roots, spectral_abscissa

__all__ = ["AGREEMENT_RTOL", "KRONECKER_MAX_N", "Agreement", "Crossing", "CrossingSet",
           "DelayMargin", "ExactMargin", "Spectrum", "SpectrumNotConverged", "compare_margins",
           "delay_margin_eig", "delay_margin_siso", "delay_margin_sweep", "exact_margin",
           "is_hurwitz", "kronecker_crossings", "phase_crossings", "relative_difference",
           "rightmost_roots", "scale", "spectral_abscissa", "stability_windows",
           "windows_from_crossings"]
