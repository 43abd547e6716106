"""The eps at which the free-weighting criterion certifies a given delay
bound (a printed one, say), with one solve per bisection step (issue 36,
item 4).

The criterion is the descriptor free-weighting LMI with the slack scalar eps
(:class:`workbench.lmi.freeweighting003.FreeWeighting003`, the
``free-weighting-003`` synthesis of :mod:`workbench.synthesis`).
:func:`workbench.synthesis.eps_for_bound` decides each step of its eps
bisection with a whole delay bisection, ``bisect_delay(guess=h_target)``,
and asks only whether its ``h_certified`` is below ``h_target``. That
bisection's first solve is at ``h_target`` itself (the guess, inside
``[h_lo, h_hi]``), and that solve settles the question:

* CERTIFIED at ``h_target``: ``h_certified`` is the largest certified delay
  tried, so ``h_certified >= h_target`` (not below);
* REFUTED at ``h_target``: every later delay the bisection tries lies below
  its first not-certified delay (geometric steps down from the guess,
  bisection and secant steps inside the bracket, island probes below the
  smallest refuted delay), so every certified delay, and ``h_certified``
  (0 when none), is below ``h_target``.

An INCONCLUSIVE solve settles nothing (island probes may look above it), and
then the whole bisection runs as before. A solve at (eps, h) is the same in
both: one parametrised problem, whose Clarabel solver cvxpy keeps and
updates with the new data, scaled with the equilibration of its first solve
-- which both make at (eps_lo, h_target). So every decision, and the returned
eps, equal :func:`eps_for_bound`'s bit for bit;
``tests/test_antiskid_cruise_match.py`` compares the two.
"""
from __future__ import annotations

__all__ = ["eps_matching"]


def eps_matching(A, B, h_target: float, eps_lo: float, eps_hi: float, settings,
                 rel_tol: float = 1e-3) -> float | None:
    """The eps at which the free-weighting certified bound equals ``h_target``:
    :func:`workbench.synthesis.eps_for_bound` (same bisection on eps, same
    result), each step decided by one solve where it can be (module
    docstring).

    Parameters
    ----------
    A, B : array_like
        The loop x' = A x + B u(t - h).
    h_target : float
        The delay bound to match (s), e.g. a printed one.
    eps_lo, eps_hi : float
        Bisection range of the slack scalar eps; the bound is assumed to grow
        with eps there (checked at the ends; ``None`` when ``h_target`` is not
        bracketed).
    settings : workbench.synthesis.SynthesisSettings
    rel_tol : float
        Relative width of the final eps bracket.

    Returns
    -------
    float or None
    """
    import numpy as np

    from ..lmi.core import Outcome, bisect_delay
    from ..lmi.freeweighting003 import FreeWeighting003
    from ..lmi.scaling import balancing
    A, B = np.asarray(A, float), np.asarray(B, float).reshape(np.shape(A)[0], -1)
    T = balancing(A)                   # the balanced system of eps_for_bound, as it computes it
    Tinv = np.diag(1.0 / np.diag(T))
    crit = FreeWeighting003(Tinv @ A @ T, Tinv @ B, eps_lo, margin=settings.margin)
    bis = settings.bisection()

    def h_of(eps):
        crit.set_eps(eps)
        return bisect_delay(crit.solve_at, guess=h_target, **bis).h_certified

    def below(eps) -> bool:
        """h_of(eps) < h_target."""
        if bis["h_lo"] <= h_target <= bis["h_hi"]:
            crit.set_eps(eps)
            out = crit.solve_at(h_target).outcome
            if out is Outcome.CERTIFIED:
                return False
            if out is Outcome.REFUTED:
                return True
        return h_of(eps) < h_target

    lo, hi = eps_lo, eps_hi
    if not ((below(lo) or h_of(lo) <= h_target) and not below(hi)):
        return None
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        if below(mid):
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
