"""Canonical state coordinates for the delay LMIs: certified bounds that do not
depend on the coordinates the model was written in.

The LMI criteria are invariant under a change of state coordinates in exact
arithmetic, but their *relative* definiteness margin (smallest eigenvalue over
the largest block norm, :mod:`workbench.lmi.core`) is invariant only under
orthogonal changes. :func:`modal_metric` picks coordinates z, x = L z, that are
determined by the loop up to an orthogonal change, so the margins the solver
and the re-check see are the same whatever similarity the model came in:

1. the real modal basis of the delay-free matrix A + A_d (eigenvectors; a
   complex pair as the real and imaginary parts of one eigenvector), which
   fixes the coordinates up to one scale per mode (and a rotation within a
   complex pair, which is orthogonal);
2. those scales by Osborne balancing of (L^{-1} A L, L^{-1} A_d L) with one
   factor per mode (Frobenius norms of the mode's rows and columns outside
   it, so a rotation within a pair changes nothing), which is invariant under
   a rescaling of the modes.

L is only a change of coordinates of the solve: the certificate is mapped
back to the balanced coordinates of the caller (:meth:`original`) and
re-checked there, against the caller's own A and A_d, with its margins
measured in the z coordinates (a congruence by L, which preserves
definiteness). When A + A_d is close to defective (eigenvector basis with a
condition number above :data:`MAX_COND`) the modal basis is not used.

References
----------
.. [OSB60] Osborne E. E., "On pre-conditioning of matrices", J. ACM 7(4),
   338-345, 1960 (balancing; convergence for irreducible matrices).
.. [GVL13] Golub G. H., Van Loan C. F., *Matrix Computations*, 4th ed., 2013,
   sec. 7.1-7.4 (real modal and Schur forms, eigenvector conditioning).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["MAX_COND", "modal_metric", "congruence"]

#: Largest condition number of the modal basis that is used (else: None).
MAX_COND = 1e6
#: Osborne sweeps and their stopping tolerance (relative change of a scale).
SWEEPS, SWEEP_TOL = 200, 1e-10
#: A coupling below this times cond(L) times the matrices' norm is rounding, not coupling.
ZERO_COUPLING = 1e-12


def _real_modal_basis(M: np.ndarray) -> tuple[np.ndarray, list[list[int]]] | None:
    w, V = np.linalg.eig(M)
    cols, groups = [], []
    order = sorted(range(len(w)), key=lambda i: (w[i].real, abs(w[i].imag), w[i].imag))
    for i in order:
        if w[i].imag < 0:
            continue
        v = V[:, i] / np.linalg.norm(V[:, i])
        if w[i].imag == 0:
            groups.append([len(cols)])
            cols.append(v.real)
        else:
            groups.append([len(cols), len(cols) + 1])
            cols += [v.real, v.imag]
    if len(cols) != M.shape[0]:
        return None
    return np.column_stack(cols), groups


def modal_metric(A, Ad) -> np.ndarray | None:
    """L (x = L z) of the module docstring, or None (near-defective A + A_d).

    Parameters
    ----------
    A, Ad : (n, n) array_like

    Returns
    -------
    numpy.ndarray or None
    """
    A, Ad = np.asarray(A, float), np.asarray(Ad, float)
    n = A.shape[0]
    if n < 2:
        return None
    basis = _real_modal_basis(A + Ad)
    if basis is None:
        return None
    L, groups = basis
    if not np.linalg.cond(L) <= MAX_COND:
        return None
    Li = np.linalg.inv(L)
    At, Adt = Li @ A @ L, Li @ Ad @ L
    # a coupling at the rounding level of the transformation counts as zero: a one-way
    # coupling (reducible pair) leaves that mode's scale to the unit-norm eigenvector
    floor = ZERO_COUPLING * np.linalg.cond(L) * math.hypot(np.linalg.norm(At), np.linalg.norm(Adt))
    d = np.ones(n)
    for _ in range(SWEEPS):
        moved = 0.0
        for g in groups:
            out = np.setdiff1d(np.arange(n), g)
            r = math.sqrt(np.sum(At[np.ix_(g, out)] ** 2) + np.sum(Adt[np.ix_(g, out)] ** 2))
            c = math.sqrt(np.sum(At[np.ix_(out, g)] ** 2) + np.sum(Adt[np.ix_(out, g)] ** 2))
            if not (r > floor and c > floor):
                continue
            f = math.sqrt(r / c)
            for M in (At, Adt):
                M[g, :] /= f
                M[:, g] *= f
            d[g] *= f
            moved = max(moved, abs(math.log(f)))
        if moved < SWEEP_TOL:
            break
    return L * d


def congruence(X: np.ndarray, M: np.ndarray) -> np.ndarray:
    """kron(I, M)' X kron(I, M) for X whose sides are multiples of M's size
    (a form on stacked state vectors); rectangular X gets its own identities."""
    n = M.shape[0]
    left = np.kron(np.eye(X.shape[0] // n), M)
    right = np.kron(np.eye(X.shape[1] // n), M)
    return left.T @ X @ right


def canonical(A0: np.ndarray, Ad0: np.ndarray):
    """(L, A0, Ad0, A~, Ad~): the solve's coordinates x = L z for the loop
    (A0, Ad0) (L None: the solve runs in (A0, Ad0) itself)."""
    L = modal_metric(A0, Ad0)
    if L is None:
        return None, A0, Ad0, A0, Ad0
    Li = np.linalg.inv(L)
    return L, A0, Ad0, Li @ A0 @ L, Li @ Ad0 @ L


def original(lmi, values):
    """A certificate of ``lmi`` (solved in z, x = L z) in the caller's x:
    every decision variable is a form on stacked states, X_x = kron(I, L^{-1})' X_z kron(I, L^{-1})."""
    if getattr(lmi, "L", None) is None:
        return values
    Li = np.linalg.inv(lmi.L)
    return {k: congruence(np.asarray(v, float), Li) for k, v in values.items()}


def recheck_original(lmi, values, h: float, owner=None) -> dict[str, float]:
    """Relative margins of a certificate re-evaluated with numpy against the
    caller's own (A0, Ad0): the certificate mapped back by :func:`original`,
    every block then measured in the z coordinates (congruence by L).
    ``owner``: the criterion holding L, A0, Ad0 when it is ``lmi.base`` (an
    interval LMI built on it)."""
    import copy

    from .core import Block, MarginLMI, relative_margins
    owner = lmi if owner is None else owner
    if getattr(owner, "L", None) is None:
        return MarginLMI.recheck(lmi, values, h)
    twin_owner = copy.copy(owner)
    twin_owner.A, twin_owner.Ad = owner.A0, owner.Ad0
    twin = twin_owner
    if owner is not lmi:
        twin = copy.copy(lmi)
        twin.base = twin_owner
    blocks = MarginLMI.evaluate_blocks(twin, original(owner, values), h)
    return relative_margins([Block(b.name, congruence(np.asarray(b.matrix, float), owner.L),
                                   b.sense) for b in blocks])
