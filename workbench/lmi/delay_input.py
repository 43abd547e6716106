"""Input checks of the delay-LMI searches (same expected-versus-found messages as
the CLI) and the system's own time scale, so that no default is absolute.
"""
from __future__ import annotations

import math

import numpy as np


def system_matrices(A, Ad) -> tuple[np.ndarray, np.ndarray]:
    """(A, A_d) as real float arrays of equal square shape; ValueError naming
    what was found and what was expected (complex, NaN/inf, empty, shapes)."""
    out = []
    for name, M in (("A", A), ("A_d", Ad)):
        arr = np.asarray(M)
        if arr.dtype == object or not (np.issubdtype(arr.dtype, np.number)
                                       or arr.dtype == bool):
            raise ValueError(f"{name} has dtype {arr.dtype}; expected a real numeric matrix")
        if np.iscomplexobj(arr):
            if np.any(np.imag(arr) != 0):
                raise ValueError(f"{name} is complex; expected a real matrix")
            arr = np.real(arr)
        arr = np.atleast_2d(arr.astype(float))
        if arr.ndim != 2 or arr.size == 0:
            raise ValueError(f"{name} has shape {np.shape(M)}; expected a non-empty n x n matrix")
        if not np.all(np.isfinite(arr)):
            raise ValueError(f"{name} contains NaN or inf; expected finite entries")
        out.append(arr)
    A, Ad = out
    if A.shape != Ad.shape or A.shape[0] != A.shape[1]:
        raise ValueError(f"A {A.shape}, A_d {Ad.shape}; expected equal square shapes")
    return A, Ad


def time_scale(A, Ad) -> float:
    """1 / R (s): the system's own time unit (inf when A = A_d = 0).

    R = rho(A) + rho(A_d) (spectral radii), or rho(A + A_d) when both vanish,
    or ||A||_2 + ||A_d||_2 when that vanishes too (nilpotent matrices). The
    spectral radii do not change under a similarity x = T x~, so a search
    started from this time scale starts at the same delay in any state
    coordinates (a stability window is found or missed alike); time scaling
    (c A, c A_d) divides it by c."""
    A, Ad = np.asarray(A, float), np.asarray(Ad, float)
    rho = lambda M: float(np.max(np.abs(np.linalg.eigvals(M)))) if M.size else 0.0
    R = rho(A) + rho(Ad)
    if not R > 0:
        R = rho(A + Ad)
    if not R > 0:
        R = float(np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2))
    return 1.0 / R if R > 0 else math.inf


#: Default search range of :func:`certified_delay` in units of the system's
#: time scale (:func:`time_scale`; scale-free: (c A, c A_d) gives h / c).
H_LO_SCALE, H_HI_SCALE = 1e-4, 1e4


def search_range(A: np.ndarray, Ad: np.ndarray, h_lo: float | None, h_hi: float | None
                 ) -> tuple[float, float]:
    """(h_lo, h_hi) of a search (s): the given values, checked, or the defaults
    :data:`H_LO_SCALE` and :data:`H_HI_SCALE` times the system's time scale."""
    tau = time_scale(A, Ad)
    tau = tau if math.isfinite(tau) else 1.0
    for name, v in (("h_lo", h_lo), ("h_hi", h_hi)):
        if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float, np.floating))
                              or not (math.isfinite(v) and v > 0)):
            raise ValueError(f"{name} = {v!r}; expected a positive finite delay (s) or None")
    lo = H_LO_SCALE * tau if h_lo is None else float(h_lo)
    hi = H_HI_SCALE * tau if h_hi is None else float(h_hi)
    if not lo < hi:
        raise ValueError(f"h_lo = {lo!r} s, h_hi = {hi!r} s; expected h_lo < h_hi")
    return lo, hi


def check_bisection(rel_tol, guess, max_solves) -> None:
    if isinstance(rel_tol, bool) or not (isinstance(rel_tol, (int, float, np.floating))
                                         and 0 < rel_tol < 1):
        raise ValueError(f"rel_tol = {rel_tol!r}; expected a relative tolerance in (0, 1)")
    if guess is not None and (isinstance(guess, bool) or not isinstance(
            guess, (int, float, np.floating)) or not (math.isfinite(guess) and guess > 0)):
        raise ValueError(f"guess = {guess!r}; expected a positive finite delay (s) or None")
    if isinstance(max_solves, bool) or not (isinstance(max_solves, (int, np.integer))
                                            and max_solves >= 1):
        raise ValueError(f"max_solves = {max_solves!r}; expected an integer >= 1")
