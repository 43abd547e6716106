"""Input checks shared by the public functions of :mod:`workbench.margins`.

Every message says what was found and what was expected, in the form of
python-control's ``mateqn._check_shape`` and :class:`workbench.errors.DesignError`:
``A has shape (2, 3); expected a square matrix``.
"""
from __future__ import annotations

import math
import numbers

import numpy as np


def real_matrix(M, name: str) -> np.ndarray:
    """``M`` as a finite, real, non-empty 2-D float array (a copy).

    Raises
    ------
    ValueError
        For complex, non-numeric, non-2-D, empty or non-finite input.
    """
    try:
        arr = np.asarray(M)
    except (TypeError, ValueError) as exc:   # ragged nested lists
        raise ValueError(f"{name} = {M!r}; expected a real matrix ({exc})") from None
    if np.iscomplexobj(arr):
        raise ValueError(f"{name} has complex entries (dtype {arr.dtype}); expected a real "
                         "matrix")
    if arr.dtype == bool or not (np.issubdtype(arr.dtype, np.integer)
                                 or np.issubdtype(arr.dtype, np.floating)):
        raise ValueError(f"{name} has entries of type {arr.dtype}; expected real numbers")
    if arr.ndim != 2:
        raise ValueError(f"{name} has shape {arr.shape}; expected a 2-D matrix")
    if arr.size == 0:
        raise ValueError(f"{name} has shape {arr.shape}; expected a non-empty matrix")
    arr = arr.astype(float)
    bad = np.argwhere(~np.isfinite(arr))
    if len(bad):
        i, j = (int(v) for v in bad[0])
        raise ValueError(f"{name}[{i}, {j}] = {arr[i, j]}; expected finite numbers")
    return arr


def square(M, name: str) -> np.ndarray:
    """A finite real square matrix (see :func:`real_matrix`)."""
    arr = real_matrix(M, name)
    if arr.shape[0] != arr.shape[1]:
        raise ValueError(f"{name} has shape {arr.shape}; expected a square matrix")
    return arr


def system(A, Ad) -> tuple[np.ndarray, np.ndarray]:
    """``(A, Ad)`` of x' = A x + A_d x(t - h): finite, real, square, same shape."""
    A = square(A, "A")
    Ad = real_matrix(Ad, "Ad")
    if Ad.shape != A.shape:
        raise ValueError(f"Ad has shape {Ad.shape}; expected {A.shape} like A")
    return A, Ad


def delay(h, name: str = "h", *, positive: bool = False) -> float:
    """A finite delay in seconds, >= 0 (> 0 with ``positive``)."""
    if isinstance(h, bool) or not isinstance(h, numbers.Real):
        raise ValueError(f"{name} = {h!r}; expected a real number (s)")
    h = float(h)
    if positive and not h > 0:
        raise ValueError(f"{name} = {h!r}; expected a positive delay (s)")
    if not h >= 0:
        raise ValueError(f"{name} = {h!r}; expected a delay >= 0 (s)")
    if not math.isfinite(h):
        raise ValueError(f"{name} = {h!r}; expected a finite delay (s)")
    return h


def integer(k, name: str, *, lo: int, hi: int | None = None) -> int:
    """An integer in [lo, hi]."""
    if isinstance(k, bool) or not isinstance(k, numbers.Integral):
        raise ValueError(f"{name} = {k!r}; expected an integer >= {lo}")
    if not k >= lo or (hi is not None and not k <= hi):
        rng = f">= {lo}" if hi is None else f"in [{lo}, {hi}]"
        raise ValueError(f"{name} = {k!r}; expected an integer {rng}")
    return int(k)


def fraction(x, name: str) -> float:
    """A relative tolerance in (0, 1)."""
    if isinstance(x, bool) or not isinstance(x, numbers.Real) or not 0 < x < 1:
        raise ValueError(f"{name} = {x!r}; expected a number in (0, 1)")
    return float(x)
