"""Exact-arithmetic re-check of an LMI certificate.

The floating-point certificate (decision variables returned by the solver)
is rounded to rationals — each float converted exactly
(:class:`fractions.Fraction`), symmetric variables symmetrised — and the
criterion's blocks are rebuilt from it in exact rational arithmetic (the
same ``blocks`` code as the solver path, evaluated on object arrays with
A, A_d and the delay as exact rationals). Each block is then tested for
*strict* definiteness, the theorem's own condition, by an exact LDL^T
factorisation without pivoting: a symmetric M is positive definite iff every
pivot is > 0 (equivalently, Sylvester's leading principal minors are > 0).

Outcome: CERTIFIED when every block is exactly definite; REFUTED (with the
block and the first non-positive pivot) otherwise. No tolerance is involved.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping

import numpy as np

from .coordinates import original
from .core import MarginLMI, Outcome


@dataclass(frozen=True)
class ExactCheck:
    """Result of :func:`exact_check`.

    Attributes
    ----------
    outcome : Outcome
        CERTIFIED or REFUTED.
    failed_block : str or None
        First block that is not strictly definite.
    detail : str
        Which pivot failed, or how many blocks were checked.
    """

    outcome: Outcome
    failed_block: str | None
    detail: str


def to_rational(M, *, symmetric: bool = False) -> np.ndarray:
    """Exact rational copy of a float array (object dtype of Fractions)."""
    M = np.atleast_1d(np.asarray(M, float))
    R = np.vectorize(Fraction, otypes=[object])(M)
    if symmetric:
        R = (R + R.T) / 2
    return R


def first_nonpositive_pivot(M: np.ndarray) -> tuple[int, Fraction] | None:
    """Exact LDL^T of a symmetric rational matrix without pivoting.

    Returns None when every pivot is > 0 (M positive definite), else the
    index and value of the first pivot <= 0.
    """
    M = [list(row) for row in M]
    n = len(M)
    for k in range(n):
        d = M[k][k]
        if d <= 0:
            return k, d
        for i in range(k + 1, n):
            f = M[i][k] / d
            if f:
                row_k, row_i = M[k], M[i]
                for j in range(k + 1, n):
                    row_i[j] -= f * row_k[j]
    return None


def exact_check(lmi: MarginLMI, values: Mapping[str, np.ndarray], h: float) -> ExactCheck:
    """Re-check a certificate of ``lmi`` at delay ``h`` in exact arithmetic.

    Parameters
    ----------
    lmi : MarginLMI
        A criterion whose blocks use only ``@``, ``+``, ``*``, ``.T`` and
        integer constants (true of :mod:`workbench.lmi.analysis`) and whose
        system matrices are the attributes ``A``, ``Ad`` (and ``B``, ``K``
        when present).
    values : mapping
        Decision variables of the certificate (floats).
    h : float
        Delay (s) at which the certificate was found.
    """
    exact = copy.copy(lmi)          # same blocks, exact system matrices
    for name in ("A", "Ad", "B", "K"):
        if hasattr(lmi, name):      # the caller's own (A, A_d) when solved in other coordinates
            own = getattr(lmi, name + "0", None) if getattr(lmi, "L", None) is not None else None
            setattr(exact, name, to_rational(np.atleast_2d(getattr(lmi, name) if own is None
                                                           else own)))
    values = original(lmi, values)
    x = {}
    for k, var in lmi._vars.items():
        x[k] = to_rational(np.reshape(values[k], var.shape),
                           symmetric=bool(var.is_symmetric()))
    hq = Fraction(float(h))
    p = {k: Fraction(float(v.value)) for k, v in lmi._params.items()
         if k not in ("h", "iota") and v.value is not None}
    p.update(h=hq, iota=1 / hq)
    blocks = exact.blocks(x, p, np.block)
    for blk in blocks:
        M = np.asarray(blk.matrix, dtype=object)
        if any(not isinstance(v, (Fraction, int)) for v in M.flat):
            raise TypeError(f"block {blk.name}: not exact rational (got {type(M.flat[0])})")
        if not all(M[i, j] == M[j, i] for i in range(M.shape[0]) for j in range(i)):
            return ExactCheck(Outcome.REFUTED, blk.name, "block not exactly symmetric")
        bad = first_nonpositive_pivot(-M if blk.sense == "nsd" else M)
        if bad is not None:
            k, d = bad
            return ExactCheck(Outcome.REFUTED, blk.name,
                              f"pivot {k} = {float(d):.3g} (not strictly definite)")
    return ExactCheck(Outcome.CERTIFIED, None, f"{len(blocks)} blocks strictly definite")
