"""A well-posed gain from a state-feedback synthesis LMI.

At the largest certified delay of a synthesis LMI the optimum is degenerate:
the Lyapunov variable (L of paper 003's problem (60), Y of the descriptor
LMIs) tends to a singular matrix and a whole face of points is optimal, so
the gain ``K = V L^{-1}`` a solver returns there is not determined by the
problem. It depends on the solver's path and on the CPU's BLAS kernels
(paper 003's dry design gave K1 = -0.0050126, -0.0050141 and -0.0050132 under
three OpenBLAS kernels). :func:`canonical_gain` replaces that arbitrary point
by a unique one:

1. the bisection gives the criterion's bracket ``[h_certified, h_refuted]``
   (this does not depend on which optimal point the solver returns);
2. at ``h_design = fraction * h_certified`` (strictly inside the certified
   range, default 0.99) the *minimum-norm certificate* is computed
   (:meth:`~workbench.lmi.core.MarginLMI.canonical_point`: the unique point
   of least Frobenius norm with every block definite by at least 1) and
   ``K = V L^{-1}`` is taken from it;
3. K is rounded to ``digits`` significant digits (default 4): the printed
   gain *is* the gain that is certified and simulated;
4. the rounded K is certified on its own by the same LMI with the gain fixed
   (``V = K L``), by the shared bisection: its own bracket.

The fixed-gain LMI is a restriction of the synthesis LMI (its points are the
synthesis points with ``V = K X``), so where the synthesis was refuted it is
refuted too; :func:`canonical_gain` takes that delay (``refuted_from``) and
decides the bisection's probes at or above it without a solve (issue 36,
item 4: about a third of the solves of the gain's bisection). The probes are
the same as with solves, so the bracket, the certified delay and everything
printed from them are the same; a certified delay still needs its own solve
and re-check.

References
----------
.. [BEFB94] Boyd S., El Ghaoui L., Feron E., Balakrishnan V., *Linear Matrix
   Inequalities in System and Control Theory*, SIAM 1994, sec. 2.4 (analytic
   centre and other canonical points of an LMI's feasible set).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import cvxpy as cp
import numpy as np

from .core import IMPLIED, Bracket, MarginLMI, Outcome, Step, bisect_delay

#: Fraction of the certified delay at which the canonical point is computed.
DEFAULT_FRACTION = 0.99
#: Significant digits of a canonical gain.
DEFAULT_DIGITS = 4
#: Decide the probes at or above ``refuted_from`` without a solve
#: (:func:`canonical_gain`); False solves them, as before issue 36's cut
#: (``benchmarks/synthesize_times.py``: the same bracket either way).
IMPLIED_PROBES = True
#: Lower end of the rounded gain's own bisection, as a fraction of the design
#: delay (relative, so the search is the same in any time unit).
ANALYSIS_FLOOR = 1e-4


def round_significant(x: np.ndarray, digits: int) -> np.ndarray:
    """Every entry of ``x`` rounded to ``digits`` significant (decimal) digits,
    through its decimal representation (the same on every machine)."""
    if not (isinstance(digits, int) and digits >= 1):
        raise ValueError(f"digits = {digits!r}; expected an integer >= 1")
    x = np.asarray(x, float)
    return np.array([float(f"{v:.{digits - 1}e}") for v in x.ravel()]).reshape(x.shape)


@dataclass(frozen=True)
class CanonicalGain:
    """The canonical gain of a synthesis and what it certifies on its own.

    Attributes
    ----------
    K : numpy.ndarray or None
        Gain in original coordinates, rounded to ``digits`` significant
        digits; None when the canonical point could not be certified.
    digits : int
    h_design : float
        Delay (s) of the minimum-norm certificate K was taken from.
    point : Step
        That certificate (balanced coordinates) with its relative re-check
        margins.
    analysis : Bracket or None
        The synthesis LMI with ``K`` fixed: the delay bracket (s) the rounded
        gain certifies by itself.
    """

    K: np.ndarray | None
    digits: int
    h_design: float
    point: Step
    analysis: Bracket | None

    @property
    def outcome(self) -> Outcome:
        """CERTIFIED when the rounded K certifies a positive delay on its own."""
        return Outcome.INCONCLUSIVE if self.analysis is None else self.analysis.outcome

    @property
    def h_certified(self) -> float:
        """Delay (s) the rounded gain certifies on its own (0 when none)."""
        return 0.0 if self.analysis is None else self.analysis.h_certified


def canonical_gain(lmi: MarginLMI, h_certified: float, fixed: Callable[[np.ndarray], MarginLMI],
                   T: np.ndarray, *, fraction: float = DEFAULT_FRACTION,
                   digits: int = DEFAULT_DIGITS, h_hi: float, h_lo: float | None = None,
                   rel_tol: float = 1e-4, max_solves: int = 60,
                   refuted_from: float | None = None) -> CanonicalGain:
    """The well-posed gain of a synthesis LMI (see the module docstring).

    Parameters
    ----------
    lmi : MarginLMI
        The synthesis LMI, with its scalar parameters (eps) already set; it
        must have a ``gain(values)`` method (K in its own coordinates).
    h_certified : float
        Largest delay (s) certified by the bisection of ``lmi`` (> 0).
    fixed : callable
        ``fixed(K) -> MarginLMI``: the same LMI with the gain fixed to ``K``
        (given in ``lmi``'s coordinates).
    T : (n, n) array
        Coordinates of ``lmi``: x = T x~ (K = K~ T^{-1}); a power-of-two
        diagonal, so mapping K is exact.
    fraction : float
        ``h_design = fraction * h_certified``, in (0, 1].
    digits : int
        Significant digits of K.
    h_hi : float
        Search cap (s) of the fixed-gain analysis (the synthesis's own cap).
    h_lo : float, optional
        Lower end of that search (s); default :data:`ANALYSIS_FLOOR` times
        the design delay (relative: no absolute default).
    rel_tol, max_solves
        Bisection settings of the fixed-gain analysis.
    refuted_from : float, optional
        A delay (s) at which ``lmi`` was refuted (its bisection's
        ``h_refuted``). Every point of the fixed-gain LMI is a point of
        ``lmi`` (``V = K X``) when ``|V| <= lmi.bound`` holds for it, which
        the gain guarantees when its largest absolute row sum is at most
        ``lmi.bound`` on every point that could certify (margin t > 0: ``X``
        is then positive definite with trace <= 1 in the solver's
        normalisation, so its entries are at most 1 in modulus): a fixed-gain
        point with margin >= ``lmi.margin`` would be one of ``lmi``, so the
        fixed-gain LMI is refuted at ``refuted_from`` and, as the bisection
        assumes (the criterion is monotone in h), above it. Probes there are recorded as
        REFUTED steps with the status :data:`~workbench.lmi.core.IMPLIED`,
        no solve; without that row-sum bound every probe is solved. For
        a ``lmi`` whose gain basis ``X`` has a positive block
        ``<gain_basis>_pos`` (e.g. :class:`~workbench.lmi.freeweighting003.
        FreeWeighting003`).

    Returns
    -------
    CanonicalGain
    """
    if not 0 < fraction <= 1:
        raise ValueError(f"fraction = {fraction!r}; expected a number in (0, 1]")
    if not h_certified > 0:
        raise ValueError(f"h_certified = {h_certified!r}; expected a positive delay (s)")
    h = fraction * h_certified
    h_lo = ANALYSIS_FLOOR * h if h_lo is None else h_lo
    point = lmi.canonical_point(h)
    if point.outcome is not Outcome.CERTIFIED:
        return CanonicalGain(None, digits, h, point, None)
    T = np.asarray(T, float)
    K = round_significant(lmi.gain(point.certificate) @ np.diag(1.0 / np.diag(T)), digits)
    crit = fixed(K @ T)
    decide = crit.solve_at
    if (IMPLIED_PROBES and refuted_from is not None and math.isfinite(refuted_from)
            and np.abs(K @ T).sum(axis=1).max() <= lmi.bound):
        def decide(h_, _solve=crit.solve_at, _from=float(refuted_from)):
            if h_ >= _from:
                return Step(h_, Outcome.REFUTED,
                            f"{IMPLIED} (the synthesis LMI was refuted at {_from:.6g} s)",
                            None, {}, None, 0.0)
            return _solve(h_)
    analysis = bisect_delay(decide, h_lo=h_lo, h_hi=h_hi, rel_tol=rel_tol,
                            max_solves=max_solves, guess=min(max(h, h_lo), h_hi))
    return CanonicalGain(K, digits, h, point, analysis)


class FixedGain:
    """Mixin turning a state-feedback synthesis LMI (variable ``V = K X``)
    into the analysis of a *given* gain: ``V`` is replaced by ``K X``.

    Use as ``class C(FixedGain, SomeSynthesis)`` with ``gain_basis`` naming X;
    the constructor takes the synthesis LMI's arguments and the gain as the
    keyword ``K``.

    With ``shared=True`` the gain is a cvxpy Parameter of the built problem
    (DPP: ``K X`` is a parameter times a variable), so :meth:`set_gain`
    changes it without compiling the problem again: one LMI serves the
    fixed-gain analyses of several gains (e.g. one per eps of a sweep,
    issue 36). The numpy re-check always uses the numpy ``K``.
    """

    gain_basis: str = "L"

    def __init__(self, *args, K, shared: bool = False, **kw):
        self.K = np.atleast_2d(np.asarray(K, float))
        self._K_param = cp.Parameter(self.K.shape, name="K") if shared else None
        if shared:
            self._K_param.value = self.K
        super().__init__(*args, **kw)

    def set_gain(self, K) -> None:
        """Fix the gain to ``K`` (same shape; only with ``shared=True``)."""
        if self._K_param is None:
            raise ValueError("set_gain needs an LMI built with shared=True")
        K = np.atleast_2d(np.asarray(K, float))
        if K.shape != self.K.shape:
            raise ValueError(f"K of shape {K.shape}; expected {self.K.shape}")
        self.K = K
        self._K_param.value = K

    def variables(self):
        v = super().variables()
        del v["V"]
        return v

    def blocks(self, x, p, bmat):
        K = self.K if self._K_param is None or bmat is not cp.bmat else self._K_param
        return super().blocks({**x, "V": K @ x[self.gain_basis]}, p, bmat)
