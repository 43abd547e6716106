"""Quadratic Lyapunov functions of a Hurwitz closed-loop matrix A + B K.

* :func:`lyapunov_P` -- the Lyapunov equation A' P + P A = -Q;
* :func:`modal_P` -- P = S^-T W S^-1 in the modal coordinates of A.

Both round P to a fixed number of significant digits, so that V is the same
function on every CPU whatever the last bits LAPACK returns.
"""
from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from ..errors import ModelError


def round_up(x, digits: int) -> np.ndarray:
    """x >= 0 rounded up to ``digits`` significant digits (elementwise)."""
    x = np.asarray(x, float)
    e = np.floor(np.log10(np.where(x > 0, x, 1.0))) - (digits - 1)
    return np.where(x > 0, np.ceil(x / 10.0**e) * 10.0**e, 0.0)


def lyapunov_P(A_cl, Q=None, *, digits: int = 10) -> np.ndarray:
    """P of the Lyapunov equation A_cl' P + P A_cl = -Q (Q = I by default).

    Parameters
    ----------
    A_cl : (n, n) array_like
        Closed-loop linearisation A + B K at the equilibrium (Hurwitz).
    Q : (n, n) array_like, optional
        Symmetric positive definite weight.
    digits : int
        P is rounded to this many significant digits (relative to its
        largest entry): V is then the same function on every CPU, whatever
        the last bits LAPACK returns.

    Raises
    ------
    ModelError
        When A_cl is not Hurwitz or P is not positive definite.
    """
    A = np.asarray(A_cl, float)
    Q = np.eye(A.shape[0]) if Q is None else np.asarray(Q, float)
    eig = np.linalg.eigvals(A)
    if not np.all(eig.real < 0):
        raise ModelError(f"closed-loop linearisation is not Hurwitz: eigenvalues {eig}")
    P = sla.solve_continuous_lyapunov(A.T, -Q)
    P = 0.5 * (P + P.T)
    scale = 10.0 ** (np.floor(np.log10(np.max(np.abs(P)))) - digits + 1)
    P = np.round(P / scale) * scale
    if not np.all(np.linalg.eigvalsh(P) > 0):
        raise ModelError("Lyapunov equation gave a P that is not positive definite")
    return P


def modal_P(A_cl, weights=None, *, digits: int = 10) -> np.ndarray:
    """Lyapunov matrix of A_cl in its modal coordinates: P = S^-T W S^-1.

    With S the real modal basis of A_cl (eigenvectors; real and imaginary
    parts for a complex pair) and W = diag(weights) (one weight per real
    mode or complex pair), V = xi' W xi in modal coordinates xi = S^-1 x,
    so V' = sum_i 2 Re(s_i) w_i |xi_i|^2: every mode decays at its own rate
    (P solves the Lyapunov equation with Q = -S^-T (W L + L' W) S^-1, L the
    real block-diagonal form). Slow and fast modes (e.g. speed and creep
    ratio in paper 003's cruise loop) then do not trade decay against each
    other as they do with P from Q = I; the weights set the shape of the
    level sets and are the free parameter of a basin search.

    Parameters
    ----------
    A_cl : (n, n) array_like
        Hurwitz closed-loop matrix, diagonalisable.
    weights : sequence of float, optional
        Positive weights in the order of the modes sorted by decreasing real
        part (slowest first); 1 by default.
    digits : int
        Significant digits P is rounded to (see :func:`lyapunov_P`).

    Raises
    ------
    ModelError
        When A_cl is not Hurwitz or not diagonalisable.
    """
    A = np.asarray(A_cl, float)
    ev, vec = np.linalg.eig(A)
    if not np.all(ev.real < 0):
        raise ModelError(f"closed-loop matrix is not Hurwitz: eigenvalues {ev}")
    order = np.argsort(-ev.real, kind="stable")
    cols, blocks, done = [], [], set()
    for k in order:
        if k in done:
            continue
        done.add(k)
        if abs(ev[k].imag) > 1e-12 * abs(ev[k]):
            j = next(i for i in order if i not in done and abs(ev[i] - np.conj(ev[k])) <
                     1e-9 * abs(ev[k]))
            done.add(j)
            cols += [vec[:, k].real, vec[:, k].imag]
            blocks.append(2)
        else:
            cols.append(vec[:, k].real)
            blocks.append(1)
    S = np.column_stack(cols)
    if np.linalg.cond(S) > 1e12:
        raise ModelError("closed-loop matrix is not (numerically) diagonalisable")
    w = np.ones(len(blocks)) if weights is None else np.asarray(weights, float)
    if w.shape != (len(blocks),) or not np.all(w > 0):
        raise ModelError(f"modal_P needs {len(blocks)} positive weights; got {weights!r}")
    W = np.diag(np.repeat(w, blocks))
    Si = np.linalg.inv(S)
    P = Si.T @ W @ Si
    P = 0.5 * (P + P.T)
    scale = 10.0 ** (np.floor(np.log10(np.max(np.abs(P)))) - digits + 1)
    P = np.round(P / scale) * scale
    if not np.all(np.linalg.eigvalsh(P) > 0):
        raise ModelError("modal P is not positive definite after rounding")
    return P
