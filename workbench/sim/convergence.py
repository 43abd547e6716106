"""Three-level refinement check with a Richardson error estimate.

A simulated metric enters a finding only when it has converged in the
numerical parameters (issue 33, item 4): the metric is computed at a step
``dt`` and at ``dt / r`` and ``dt / r**2`` (``r`` the refinement ratio, 2
for step halving), giving ``q1``, ``q2``, ``q4``. With ``d1 = q1 - q2`` and
``d2 = q2 - q4`` the observed order of convergence is

    p = log_r(|d1| / |d2|),

and Richardson's estimate of the error left in the finest value ``q4`` is

    E = |d2| / (r**p - 1).

The check is a pure function of the three values (:func:`refinement_check`);
it returns a small frozen :class:`Refinement` whose outcome is one of a
closed set, the enum :class:`Convergence` (:data:`OUTCOMES`; its members
compare equal to their words, which the reports print):

``CONVERGED``
    ``E <= tolerance``, or every difference is at rounding level;
``NOT_CONVERGED``
    ``E > tolerance``;
``INCONCLUSIVE`` (not determined)
    the sequence is not in its asymptotic range (observed order below
    :data:`P_MIN`) and its differences are too large to dismiss, or a value
    is not finite, so no estimate is trusted.

Guards (our choice where the issue is silent): an observed order outside
[:data:`P_MIN`, :data:`P_MAX`] is clipped into it in the estimate. Above
``P_MAX`` (the differences collapse faster than any scheme used here
converges) clipping makes the estimate larger, so conservative. Below
``P_MIN`` (differences that do not shrink, or grow: the levels are not in
the asymptotic range, as with event times on a sampled clock or a Monte
Carlo share) the estimate uses the larger of the two differences,
``max(|d1|, |d2|) / (r**P_MIN - 1)``; the outcome is CONVERGED when even that
is within the tolerance, and INCONCLUSIVE otherwise (no order can be trusted
to say by how much it is off). Differences at or below ``floor`` (default
``64 eps`` times the largest |q|) are rounding noise: when both are, the
metric is converged with ``E = floor``; when only ``d2`` is, the order is
taken as ``P_MAX`` on ``d2 = floor``.

References
----------
L. F. Richardson, "The deferred approach to the limit", Phil. Trans. R.
Soc. A 226, 299-361, 1927.
P. J. Roache, "Quantification of uncertainty in computational fluid
dynamics", Annu. Rev. Fluid Mech. 29, 123-160, 1997 (observed order,
three-grid estimate).
"""
from __future__ import annotations

import enum
import math
from dataclasses import dataclass

__all__ = ["CONVERGED", "Convergence", "INCONCLUSIVE", "LEVELS", "NOT_CONVERGED", "OUTCOMES",
           "P_MAX", "P_MIN", "ROUNDING", "Refinement", "refinement_check"]


class Convergence(enum.StrEnum):
    """The verdict of a convergence check: converged, not converged, or not
    determined (INCONCLUSIVE: no estimate is trusted). A member is its word
    (``str``), as tables, JSON and claim notes print it."""

    CONVERGED = "CONVERGED"
    NOT_CONVERGED = "NOT_CONVERGED"
    INCONCLUSIVE = "INCONCLUSIVE"


CONVERGED, NOT_CONVERGED, INCONCLUSIVE = Convergence
#: The closed set of outcomes of :func:`refinement_check`.
OUTCOMES = tuple(Convergence)
#: Refinement levels: the step divided by 2**k (q1, q2, q4).
LEVELS = (0, 1, 2)
#: Observed orders outside [P_MIN, P_MAX] are guarded (module docstring).
P_MIN, P_MAX = 0.5, 4.0
#: Differences at or below this times the largest |value| are rounding noise
#: (the default floor of :func:`refinement_check`).
ROUNDING = 64 * 2.0 ** -52


@dataclass(frozen=True)
class Refinement:
    """Result of a three-level refinement check.

    Attributes
    ----------
    values : tuple of float
        ``(q1, q2, q4)`` at the step, a refinement, and two refinements.
    ratio : float
        Refinement ratio ``r`` between consecutive levels.
    order : float or None
        Observed order ``p`` (before clipping); None when both differences
        are at rounding level or a value is not finite; ``inf`` when only
        the finer difference is.
    estimate : float or None
        Richardson estimate of the error of ``q4`` (same unit as the
        values; guarded as in the module docstring); None when a value is
        not finite.
    tolerance : float
        The tolerance the estimate was compared with.
    outcome : Convergence
        One of :data:`OUTCOMES`.
    note : str
        Which guard applied (empty when none).
    """

    values: tuple[float, float, float]
    ratio: float
    order: float | None
    estimate: float | None
    tolerance: float
    outcome: Convergence
    note: str = ""

    @property
    def converged(self) -> bool:
        return self.outcome == CONVERGED


def refinement_check(q1: float, q2: float, q4: float, *, ratio: float = 2.0,
                     tolerance: float, floor: float | None = None) -> Refinement:
    """Observed order and Richardson error estimate of three refinements.

    Parameters
    ----------
    q1, q2, q4 : float
        The metric at step ``h``, ``h / ratio`` and ``h / ratio**2``.
    ratio : float, optional
        Refinement ratio (> 1); 2 for step halving.
    tolerance : float
        Largest acceptable error of the finest value (the claim's
        tolerance, same unit as the values; >= 0).
    floor : float, optional
        Differences at or below this are rounding noise; default
        ``64 eps max(|q1|, |q2|, |q4|)``.

    Returns
    -------
    Refinement
        Outcome CONVERGED, NOT_CONVERGED or INCONCLUSIVE with the observed
        order and the estimate (see the module docstring for the guards).

    References
    ----------
    Richardson (1927); Roache (1997): three-grid observed order.
    """
    if not ratio > 1:
        raise ValueError(f"ratio = {ratio!r}; expected a number > 1")
    if not tolerance >= 0:
        raise ValueError(f"tolerance = {tolerance!r}; expected a number >= 0")
    vals = (float(q1), float(q2), float(q4))
    if not all(math.isfinite(v) for v in vals):
        return Refinement(vals, ratio, None, None, tolerance, INCONCLUSIVE,
                          "a value is not finite")
    if floor is None:
        floor = ROUNDING * max(abs(v) for v in vals)
    d1, d2 = abs(vals[0] - vals[1]), abs(vals[1] - vals[2])
    if d1 <= floor and d2 <= floor:
        out = CONVERGED if floor <= tolerance else NOT_CONVERGED
        return Refinement(vals, ratio, None, floor, tolerance, out,
                          "differences at rounding level")
    if d2 <= floor:
        order, p, note = math.inf, P_MAX, f"only the finer difference at rounding level: p taken as {P_MAX:g}"
        d2 = floor
    else:
        order = math.log(d1 / d2, ratio) if d1 > 0 else -math.inf
        p, note = order, ""
        if order < P_MIN:
            est = max(d1, d2) / (ratio ** P_MIN - 1)
            note = (f"observed order {order:.2g} < {P_MIN:g}: not in the asymptotic range; "
                    f"estimate from the larger difference at p = {P_MIN:g}")
            return Refinement(vals, ratio, order, est, tolerance,
                              CONVERGED if est <= tolerance else INCONCLUSIVE, note)
        if order > P_MAX:
            p, note = P_MAX, f"observed order {order:.2g} > {P_MAX:g}: clipped to {P_MAX:g}"
    est = d2 / (ratio ** p - 1)
    return Refinement(vals, ratio, order, est, tolerance,
                      CONVERGED if est <= tolerance else NOT_CONVERGED, note)
