"""Exact stability of a periodically sampled loop: the lifted map over one period.

For x' = A x + B u with the state sampled at t_k = k T, u_k = K x(t_k), and
each u_k applied (zero-order hold) from t_k + tau until the next value
arrives at t_{k+1} + tau, the state at the sampling instants obeys a linear
recursion — no LMI and no approximation. Write tau = d T + r with the integer
d >= 0 and 0 <= r < T. On [t_k, t_{k+1}) the plant sees u_{k-d-1} for r
seconds, then u_{k-d}, so

    x_{k+1} = e^{AT} x_k + e^{A(T-r)} Psi(r) B u_{k-d-1} + Psi(T-r) B u_{k-d},
    Psi(s) = int_0^s e^{A v} dv,

and with the augmented state z_k = [x_k; u_{k-1}; ...; u_{k-d-1}] (the inputs
still in flight; for tau < T only the previous input, z_k = [x_k; u_{k-1}])
z_{k+1} = F(T, tau) z_k. The loop is exponentially stable for this constant
T and tau iff the spectral radius of F(T, tau) is below 1 (the nonzero
eigenvalues of F are those of the monodromy operator of the sampled-data
system). Every block comes from one matrix exponential,
expm([[A, B], [0, 0]] s) = [[e^{As}, Psi(s) B], [0, I]].

The set of stable T for a fixed tau need not be an interval (a lightly damped
mode aliases at T = pi / omega); :func:`periodic_stable_set` scans a grid and
refines every boundary by bisection on rho(T) - 1.

For sampling jitter, :func:`alternating_radius` gives the growth rate
rho(F(T2) F(T1))^(1/2) of the alternating sequence T1, T2, T1, ...: a value
above 1 is an unstable admissible sequence, so it refutes any claim of
stability for every interval sequence in a range containing T1 and T2
(Hetel et al. 2017, sec. 3).

References
----------
Zhang, W., Branicky, M. S., Phillips, S. M. (2001). Stability of networked
control systems. IEEE Control Systems Magazine 21(1), 84-99 (the benchmark
A = [[0, 1], [0, -0.1]], B = [0; 0.1], K = -[3.75, 11.5]).
Astrom, K. J., Wittenmark, B. (1997). Computer-Controlled Systems, 3rd ed.,
sec. 2.3 (sampling a system with a time delay).
Hetel, L., Fiter, C., Omran, H., Seuret, A., Fridman, E., Richard, J.-P.,
Niculescu, S.-I. (2017). Recent developments on the stability of systems with
aperiodic sampling: an overview. Automatica 76, 309-335.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

__all__ = ["lifted_map", "spectral_radius", "alternating_radius", "PeriodicStableSet",
           "periodic_stable_set", "first_unstable_period"]

#: Largest delay in samples, floor(tau / T), of a lifted map (issue 32: a size cap).
MAX_QUEUE = 10000
#: Relative bisection tolerance on each boundary of the stable set of T.
BOUNDARY_RTOL = 1e-10


def _hold_blocks(A: np.ndarray, B: np.ndarray, s: float) -> tuple[np.ndarray, np.ndarray]:
    """(e^{As}, Psi(s) B) from one matrix exponential."""
    n, m = B.shape
    M = np.zeros((n + m, n + m))
    M[:n, :n], M[:n, n:] = A * s, B * s
    E = sl.expm(M)
    return E[:n, :n], E[:n, n:]


def lifted_map(A, B, K, T: float, tau: float = 0.0) -> np.ndarray:
    """The one-period map F(T, tau) of the sampled loop (module docstring).

    Parameters
    ----------
    A, B, K : array_like
        Plant (n x n, n x m) and gain (m x n), u_k = K x(t_k).
    T : float
        Sampling period (s), > 0.
    tau : float
        Constant delay from sampling to actuation (s), >= 0 (any size).

    Returns
    -------
    numpy.ndarray
        (n + (d+1) m) square matrix acting on z_k = [x_k; u_{k-1}; ...; u_{k-d-1}],
        d = floor(tau / T).
    """
    A, B, K = (np.asarray(M, dtype=float) for M in (A, B, K))
    if not T > 0 or not tau >= 0 or not math.isfinite(T + tau):
        raise ValueError(f"T = {T!r} s, tau = {tau!r} s; expected T > 0 and tau >= 0")
    n, m = B.shape
    if not tau / T <= MAX_QUEUE:
        raise ValueError(f"tau / T = {tau / T:.4g}; expected at most {MAX_QUEUE} samples "
                         f"in the delay (the map has n + (d + 1) m rows)")
    d = int(math.floor(tau / T))
    r = tau - d * T
    if r >= T:                      # rounding of tau / T
        d, r = d + 1, 0.0
    Phi, _ = _hold_blocks(A, B, T)
    E1, G_r = _hold_blocks(A, B, T - r)        # e^{A(T-r)}, Psi(T-r) B
    _, Psi_r = _hold_blocks(A, B, r)
    G_old = E1 @ Psi_r                          # weight of u_{k-d-1}
    size = n + (d + 1) * m
    F = np.zeros((size, size))
    F[:n, :n] = Phi
    col = lambda j: slice(n + (j - 1) * m, n + j * m)   # block of u_{k-j}, j = 1..d+1
    F[:n, col(d + 1)] += G_old
    if d == 0:
        F[:n, :n] += G_r @ K
    else:
        F[:n, col(d)] += G_r
    F[col(1), :n] = K                                   # u_k = K x_k enters the queue
    for j in range(2, d + 2):
        F[col(j), col(j - 1)] = np.eye(m)
    return F


def spectral_radius(F: np.ndarray) -> float:
    """Largest eigenvalue modulus of a square matrix."""
    return float(np.max(np.abs(np.linalg.eigvals(F))))


def alternating_radius(A, B, K, T1: float, T2: float, tau: float = 0.0) -> float:
    """Growth rate per period of the alternating sequence T1, T2, T1, ...

    rho(F(T2, tau) F(T1, tau))^(1/2); above 1 the sequence is unstable.
    Both maps must act on the same augmented state, so ``tau`` must be
    below min(T1, T2) (or 0).
    """
    if tau >= min(T1, T2):
        raise ValueError(f"tau = {tau!r} s; expected tau < min(T1, T2) = {min(T1, T2)!r} s")
    F = lifted_map(A, B, K, T2, tau) @ lifted_map(A, B, K, T1, tau)
    return math.sqrt(spectral_radius(F))


@dataclass(frozen=True)
class PeriodicStableSet:
    """The stable periods T of the loop at one constant delay.

    Attributes
    ----------
    tau : float
        Constant delay (s).
    T_range : (float, float)
        The scanned range of T (s).
    intervals : tuple of (float, float)
        Maximal intervals of T (s) inside ``T_range`` where rho(F(T, tau)) < 1,
        each end refined by bisection to :data:`BOUNDARY_RTOL`.
    first_unstable : float
        Smallest T in the range with rho >= 1 (s); ``inf`` if none was found.
    grid : int
        Points of the scan.
    """

    tau: float
    T_range: tuple[float, float]
    intervals: tuple[tuple[float, float], ...]
    first_unstable: float
    grid: int

    def contains(self, T: float) -> bool:
        """Whether the period T (s) lies in a stable interval."""
        return any(a <= T <= b for a, b in self.intervals)


def _radius_minus_one(A, B, K, tau):
    return lambda T: spectral_radius(lifted_map(A, B, K, T, tau)) - 1.0


def _refine(f, a: float, b: float, fa: float) -> tuple[float, float]:
    """Bisection of a sign change of f in [a, b]: (a', b') with f(a') of fa's
    sign and f(b') of the other, b' - a' <= BOUNDARY_RTOL b'."""
    while b - a > BOUNDARY_RTOL * b:
        c = 0.5 * (a + b)
        if (f(c) < 0) == (fa < 0):
            a = c
        else:
            b = c
    return a, b


def periodic_stable_set(A, B, K, *, tau: float = 0.0, T_max: float,
                        T_min: float | None = None, grid: int = 400) -> PeriodicStableSet:
    """The set of stable constant periods T in [T_min, T_max] at delay tau.

    A scan of ``grid`` points (uniform, or geometric when the range spans more
    than two decades), every sign change of rho(F) - 1 refined by bisection. A stable window narrower than the grid step can be
    missed; the scan is a map of the set, its ends are exact to
    :data:`BOUNDARY_RTOL`.

    Parameters
    ----------
    A, B, K : array_like
        Plant and gain (see :func:`lifted_map`).
    tau : float
        Constant delay (s), >= 0.
    T_max : float
        Largest period scanned (s).
    T_min : float, optional
        Smallest period scanned (s); default ``T_max / grid`` / 10.
    grid : int
        Scan points.

    Returns
    -------
    PeriodicStableSet
    """
    if not (T_max > 0 and math.isfinite(T_max)):
        raise ValueError(f"T_max = {T_max!r} s; expected a positive finite period")
    T_min = T_max / grid / 10 if T_min is None else float(T_min)
    if not 0 < T_min < T_max:
        raise ValueError(f"T_min = {T_min!r} s; expected 0 < T_min < T_max = {T_max!r} s")
    f = _radius_minus_one(A, B, K, tau)
    Ts = (np.geomspace(T_min, T_max, grid) if T_max > 100 * T_min
          else np.linspace(T_min, T_max, grid))
    vals = [f(float(T)) for T in Ts]
    intervals, start, first_unstable = [], None, math.inf
    if vals[0] < 0:
        start = float(Ts[0])
    else:
        first_unstable = float(Ts[0])
    for i in range(1, grid):
        a, b, fa, fb = float(Ts[i - 1]), float(Ts[i]), vals[i - 1], vals[i]
        if (fa < 0) == (fb < 0):
            continue
        inner, outer = _refine(f, a, b, fa)
        if fa < 0:                       # stable -> unstable
            intervals.append((start, inner))
            first_unstable = min(first_unstable, outer)
            start = None
        else:                            # unstable -> stable
            start = outer
    if start is not None:
        intervals.append((start, float(Ts[-1])))
    return PeriodicStableSet(float(tau), (T_min, float(T_max)), tuple(intervals),
                             first_unstable, grid)


def first_unstable_period(A, B, K, *, tau: float = 0.0, T_max: float, grid: int = 400) -> float:
    """Smallest constant period T (s) in (0, T_max] with rho(F(T, tau)) >= 1 (``inf`` if none)."""
    return periodic_stable_set(A, B, K, tau=tau, T_max=T_max, grid=grid).first_unstable
