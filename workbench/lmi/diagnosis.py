"""Diagnosis before solving, and the reason of every inconclusive answer.

:func:`uncontrollable_mode` is the stabilisability test (Popov-Belevitch-
Hautus) that runs before any synthesis LMI: an eigenvalue lambda of A with
``Re lambda >= -alpha`` at which ``[lambda I - A, B]`` loses rank is a mode
that no gain moves, with or without an input delay (in the Kalman
decomposition the uncontrollable block evolves as ``x2' = A22 x2``, whatever
u(t - h) is), so no gain gives the decay rate alpha (alpha = 0: no gain
stabilises the loop). The test is exact, in rational arithmetic on the
floating-point entries (which are rationals): the rank of the controllability
matrix, the characteristic polynomial of the uncontrollable block
(Faddeev-LeVerrier) and the Routh-Hurwitz test of that polynomial shifted by
alpha. A rank decision never depends on a tolerance, so an INFEASIBLE
diagnosis is a proof; the eigenvalue is only *named* in floating point.

:func:`inconclusive_reason` says why a bracket certified nothing (or less
than a required delay): the solver's status, the block that failed the numpy
re-check and its relative margin, or a search cap below the required delay.

References
----------
.. [HAU69] Hautus M. L. J., "Controllability and observability conditions of
   linear autonomous systems", Indagationes Mathematicae 31, 443-448, 1969.
.. [KAI80] Kailath T., *Linear Systems*, Prentice-Hall 1980, sec. 2.4
   (Kalman decomposition, PBH tests) and sec. 3.4 (Faddeev-LeVerrier).
.. [GAN59] Gantmacher F. R., *The Theory of Matrices*, vol. 2, Chelsea 1959,
   ch. XV (Routh-Hurwitz).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction
from typing import Sequence

import numpy as np

from .core import Bracket, Outcome

__all__ = ["INFEASIBLE", "Uncontrollable", "uncontrollable_mode", "inconclusive_reason",
           "synthesis_reason"]

#: Largest state dimension diagnosed (exact rational arithmetic grows fast: about 0.4 s at 12
#: states, 1.1 s at 16, benchmarks/certified_gain.py); larger plants go to the LMIs undiagnosed.
MAX_STATES = 12
#: The bracket of a synthesis that a diagnosis stopped before any solve.
INFEASIBLE = Bracket(0.0, math.inf, Outcome.INFEASIBLE, None, ())


@dataclass(frozen=True)
class Uncontrollable:
    """An uncontrollable mode with ``Re >= -alpha``: the synthesis is INFEASIBLE.

    Attributes
    ----------
    vertex : int
        Index of the operating point (0 for a single plant).
    eigenvalue : complex
        The mode (1/s), named in floating point (decided exactly).
    alpha : float
        Required decay rate (1/s).
    reason : str
        One line naming the mode and what cannot be done.
    """

    vertex: int
    eigenvalue: complex
    alpha: float
    reason: str


def _rat(M) -> list[list[Fraction]]:
    return [[Fraction(float(v)) for v in row] for row in np.atleast_2d(np.asarray(M, float))]


def _column_basis(cols: list[list[Fraction]], n: int) -> list[list[Fraction]]:
    """A basis (exact) of the span of the vectors ``cols`` (each of length n)."""
    basis: list[list[Fraction]] = []
    pivots: list[int] = []
    for v in cols:
        w = list(v)
        for b, p in zip(basis, pivots):           # reduce against the echelon basis
            if w[p]:
                f = w[p] / b[p]
                w = [wi - f * bi for wi, bi in zip(w, b)]
        nz = next((i for i in range(n) if w[i]), None)
        if nz is not None:
            basis.append(w)
            pivots.append(nz)
    return basis


def _solve(M: list[list[Fraction]], rhs: list[list[Fraction]]) -> list[list[Fraction]]:
    """M^{-1} rhs, exact (M square, invertible)."""
    n = len(M)
    aug = [list(M[i]) + list(rhs[i]) for i in range(n)]
    for c in range(n):
        p = next(r for r in range(c, n) if aug[r][c])
        aug[c], aug[p] = aug[p], aug[c]
        piv = aug[c][c]
        aug[c] = [v / piv for v in aug[c]]
        for r in range(n):
            if r != c and aug[r][c]:
                f = aug[r][c]
                aug[r] = [a - f * b for a, b in zip(aug[r], aug[c])]
    return [row[n:] for row in aug]


def _charpoly(M: list[list[Fraction]]) -> list[Fraction]:
    """Coefficients c_0 = 1, c_1, ..., c_k of det(s I - M) = sum c_i s^{k-i}
    (Faddeev-LeVerrier, exact)."""
    k = len(M)
    coeffs = [Fraction(1)]
    Mk = [[Fraction(0)] * k for _ in range(k)]
    for i in range(1, k + 1):
        Mk = [[sum(M[r][t] * Mk[t][c] for t in range(k)) + (coeffs[-1] if r == c else 0)
               for c in range(k)] for r in range(k)]
        AM = [[sum(M[r][t] * Mk[t][c] for t in range(k)) for c in range(k)] for r in range(k)]
        coeffs.append(-sum(AM[j][j] for j in range(k)) / i)
    return coeffs


def _shift(coeffs: list[Fraction], a: Fraction) -> list[Fraction]:
    """Coefficients of p(s - a) from those of p(s) (Horner's Taylor shift)."""
    c = list(coeffs)
    k = len(c) - 1
    for i in range(k):
        for j in range(1, k - i + 1):
            c[j] -= a * c[j - 1]
    return c


def _hurwitz(coeffs: list[Fraction]) -> bool:
    """Every root in Re s < 0 (Routh array, exact; a zero in the first column
    or a sign change means a root with Re s >= 0)."""
    if any(not c > 0 for c in coeffs):           # a Hurwitz polynomial has positive coefficients
        return False
    rows = [coeffs[0::2], coeffs[1::2]]
    while len(rows[-1]) and len(rows) < len(coeffs):
        a, b = rows[-2], rows[-1]
        if not b[0] > 0:
            return False
        nxt = [(b[0] * (a[i + 1] if i + 1 < len(a) else 0)
                - a[0] * (b[i + 1] if i + 1 < len(b) else 0)) / b[0] for i in range(len(a) - 1)]
        rows.append(nxt)
    return all(r[0] > 0 for r in rows if r)


def _uncontrollable_block(A, B) -> list[list[Fraction]] | None:
    """A22 of the Kalman decomposition (exact), None when (A, B) is controllable."""
    n = A.shape[0]
    Ar, cols = _rat(A), [list(col) for col in zip(*_rat(B))]
    basis = _column_basis(cols, n)
    frontier = basis
    while frontier and len(basis) < n:
        images = [[sum(Ar[i][j] * v[j] for j in range(n)) for i in range(n)] for v in frontier]
        new = _column_basis(basis + images, n)[len(basis):]
        basis, frontier = basis + new, new
    r = len(basis)
    if r == n:
        return None
    full = _column_basis(basis + [[Fraction(int(i == j)) for i in range(n)] for j in range(n)], n)
    T = [[full[c][i] for c in range(n)] for i in range(n)]          # columns = basis vectors
    AT = [[sum(Ar[i][t] * T[t][c] for t in range(n)) for c in range(n)] for i in range(n)]
    At = _solve(T, AT)                                               # T^{-1} A T
    return [row[r:] for row in At[r:]]


def uncontrollable_mode(points: Sequence[tuple[np.ndarray, np.ndarray]], alpha: float = 0.0
                        ) -> Uncontrollable | None:
    """The first uncontrollable mode with ``Re >= -alpha`` over the vertices, or None.

    Parameters
    ----------
    points : sequence of (A, B)
        Operating points (vertices) of x' = A x + B u(t - h).
    alpha : float
        Required decay rate (1/s), >= 0 (0: asymptotic stability).

    Returns
    -------
    Uncontrollable or None
        None when every vertex is alpha-stabilisable (the LMIs may still fail:
        PBH is necessary, not sufficient, with a delay), or when a plant has
        more than :data:`MAX_STATES` states (not diagnosed).
    """
    if not (math.isfinite(alpha) and alpha >= 0):
        raise ValueError(f"alpha = {alpha!r}; expected a non-negative rate (1/s)")
    for k, (A, B) in enumerate(points):
        A = np.atleast_2d(np.asarray(A, float))
        if A.shape[0] > MAX_STATES:
            continue
        B = np.asarray(B, float).reshape(A.shape[0], -1)
        A22 = _uncontrollable_block(A, B)
        if A22 is None or _hurwitz(_shift(_charpoly(A22), Fraction(alpha))):
            continue
        eig = np.linalg.eigvals(np.array([[float(v) for v in row] for row in A22]))
        lam = complex(max(eig, key=lambda z: z.real))
        name = f"{lam.real:.6g}" if abs(lam.imag) <= 1e-12 * max(1.0, abs(lam)) else \
            f"{lam.real:.6g} ± {abs(lam.imag):.6g}j"
        where = f" at vertex {k + 1}" if len(points) > 1 else ""
        goal = (f"no gain can give decay {alpha:g}" if alpha > 0
                else "no gain can stabilise the loop")
        return Uncontrollable(k, lam, float(alpha),
                              f"eigenvalue {name} of A{where} is uncontrollable from u: {goal}")
    return None


def inconclusive_reason(br: Bracket, *, margin: float, h_cap: float,
                        h_required: float | None = None) -> str:
    """Why ``br`` is not a certificate of what was asked (empty when it is).

    Parameters
    ----------
    br : Bracket
    margin : float
        Relative definiteness margin of the re-check.
    h_cap : float
        Search cap (s).
    h_required : float, optional
        A delay the certificate had to reach (s).
    """
    if br.outcome is Outcome.INFEASIBLE:
        return "infeasible"
    if h_required is not None and h_cap < h_required:
        return (f"search cap below the required delay: h_max = {h_cap:g} s < "
                f"{h_required:g} s")
    if br.outcome is Outcome.CERTIFIED and (h_required is None or br.h_certified >= h_required):
        return ""
    bad = [s for s in br.steps if s.outcome is Outcome.INCONCLUSIVE]
    if bad:
        s = min(bad, key=lambda s: s.h)
        if s.recheck:
            name, m = min(s.recheck.items(), key=lambda kv: kv[1])
            return (f"block {name!r} failed the numpy re-check at h = {s.h:.6g} s: relative "
                    f"margin {m:.3g} < {margin:g}")
        return f"solver status {s.solver_status!r} at h = {s.h:.6g} s"
    if br.outcome is Outcome.REFUTED or not br.steps:
        lo = min((s.h for s in br.steps), default=math.nan)
        return (f"refuted at every delay tried (smallest {lo:.6g} s): no certificate of this "
                "criterion with the relative margin")
    return (f"certified only up to {br.h_certified:.6g} s < the required "
            f"{h_required:g} s" if h_required is not None else "")


def synthesis_reason(bracket: Bracket, gain, *, margin: float, h_cap: float,
                     diagnosis: str = "", h_required: float | None = None) -> str:
    """Why a synthesis returned no certified gain (empty when it did).

    ``gain`` is the :class:`~workbench.lmi.gain.CanonicalGain` (or None): the
    synthesis bracket may be certified while the canonical point or the
    rounded gain's own bisection is not.
    """
    if diagnosis:
        return diagnosis
    why = inconclusive_reason(bracket, margin=margin, h_cap=h_cap, h_required=h_required)
    if why or bracket.outcome is not Outcome.CERTIFIED:
        return why or f"synthesis bracket {bracket.outcome.value}"
    if gain is None:
        return "no gain: the synthesis bracket has no certificate"
    if gain.K is None:
        p = gain.point
        what = (f"solver status {p.solver_status!r}" if not p.recheck else
                "block {!r} failed the numpy re-check (relative margin {:.3g})".format(
                    *min(p.recheck.items(), key=lambda kv: kv[1])))
        return f"the minimum-norm point at h = {gain.h_design:.6g} s: {what}"
    if gain.analysis is None or gain.analysis.outcome is not Outcome.CERTIFIED:
        inner = ("not run" if gain.analysis is None else
                 inconclusive_reason(gain.analysis, margin=margin, h_cap=h_cap))
        return f"the rounded gain's own bisection: {inner}"
    return inconclusive_reason(gain.analysis, margin=margin, h_cap=h_cap, h_required=h_required)
