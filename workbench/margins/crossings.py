"""Imaginary-axis crossings of x' = A x + A_d x(t - h), by two independent methods.

s = j w (w > 0) is a characteristic root at delay h iff j w is an eigenvalue of
M(theta) = A + A_d e^{-j theta} with theta = w h (mod 2 pi) [GKC03, sec. 2.3].
A crossing (w, theta) therefore puts a root on the axis at every delay
h_k = (theta + 2 pi k) / w, k = 0, 1, ...; the root moves into the right half
plane as h increases when d Re lambda / d theta > 0 at the crossing, the same
sign for every k [CvdD86]. (From det(s I - A - A_d e^{-s h}) = 0 with left/right
null vectors y, x: Re ds/dh has the sign of Im(y^H A_d z x conj(y^H x)), which
is the sign of Re dlambda/dtheta = Re(y^H (-j A_d z) x / y^H x).)

Both finders return every crossing, polished by Newton's method on
Re lambda(theta) = 0, with its direction and multiplicity:

:func:`kronecker_crossings`
    Chen, Gu & Nett [CGN95]: the unit-circle eigenvalues z of the quadratic
    pencil z^2 (A_d (x) I) + z (A (+) A) + (I (x) A_d) (size 2 n^2) are the only
    possible e^{-j theta}. Cost O(n^6): a cross-check for small n.
:func:`phase_crossings`
    Sweep of theta in [0, pi] (M(2 pi - theta) is the conjugate of M(theta))
    following *every* eigenvalue branch of M(theta): neighbouring grid points are
    matched through the first-order prediction lambda + dlambda/dtheta dtheta,
    and an interval is bisected until every branch either stays on one side of
    the imaginary axis by more than half the prediction error u (a branch with
    bounded curvature leaves its chord by about u / 4) or crosses it once, with
    an unambiguous match. Cost O(n^3) per grid point.

Every tolerance is relative: eigenvalue residuals to R = ||A||_2 + ||A_d||_2
(the bound on |lambda(M(theta))|, so on every crossing frequency), and phases
are dimensionless, so (c A, c A_d) gives the same theta and w scaled by c.

References
----------
.. [CGN95] Chen J., Gu G., Nett C.N., "A new method for computing delay margins
   for stability of linear delay systems", Systems & Control Letters 26 (1995)
   107-117.
.. [GKC03] Gu K., Kharitonov V.L., Chen J., *Stability of Time-Delay Systems*,
   Birkhauser 2003, sec. 2.3 (frequency sweeping) and 2.4 (crossing direction).
.. [CvdD86] Cooke K.L., van den Driessche P., "On zeroes of some transcendental
   equations", Funkcialaj Ekvacioj 29 (1986) 77-90 (crossing direction does not
   depend on k).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg as sl

EPS = float(np.finfo(float).eps)
TWO_PI = 2 * math.pi
#: Residual |Re lambda| / R accepted as "on the axis" after polishing.
AXIS_RTOL = 64 * EPS
#: |dRe lambda/dtheta| / R below which a crossing is a tangency (direction 0).
TANGENT_RTOL = 1e3 * EPS
#: |lambda| / R below which an eigenvalue of A + A_d is the root s = 0 (and |w| / R
#: below which a crossing frequency is 0).
ZERO_RTOL = 16 * EPS
#: Two crossings are one when w agrees to this fraction of R and theta to this (rad).
MERGE_RTOL = 1e-7
#: Eigenvalues of M(theta) within this fraction of R of j w count towards the multiplicity.
CLUSTER_RTOL = 1e-7
#: Loose pre-filter of the Chen-Gu-Nett candidates (every candidate is polished).
PENCIL_PREFILTER = 1e-3
#: Largest number of halvings of a sweep interval.
MAX_DEPTH = 40
#: Largest number of intervals examined by one sweep.
MAX_INTERVALS = 100_000


@dataclass(frozen=True)
class Crossing:
    """A root s = j omega at the delays h_k = (theta + 2 pi k) / omega.

    Attributes
    ----------
    omega : float
        Crossing frequency (rad/s), > 0.
    theta : float
        Delay phase omega h mod 2 pi (rad), in [0, 2 pi).
    direction : int
        +1 when the root pair enters the right half plane as h increases,
        -1 when it leaves, 0 for a tangency.
    multiplicity : int
        Eigenvalues of A + A_d e^{-j theta} at j omega.
    """

    omega: float
    theta: float
    direction: int
    multiplicity: int = 1

    @property
    def h0(self) -> float:
        """Smallest delay of the sequence (s)."""
        return self.theta / self.omega

    def delays(self, h_max: float) -> list[float]:
        """Every delay h_k <= h_max of the sequence (s)."""
        k_max = math.floor((h_max * self.omega - self.theta) / TWO_PI)
        return [(self.theta + TWO_PI * k) / self.omega for k in range(0, k_max + 1)]

    def next_after(self, h: float) -> float:
        """The first delay h_k > h of the sequence (s)."""
        k = max(0, math.floor((h * self.omega - self.theta) / TWO_PI) + 1)
        while (self.theta + TWO_PI * k) / self.omega <= h:
            k += 1
        return (self.theta + TWO_PI * k) / self.omega


@dataclass(frozen=True)
class CrossingSet:
    """Every crossing of one system, and whether s = 0 is a root for every h
    (det(A + A_d) = 0: never asymptotically stable)."""

    crossings: tuple[Crossing, ...]
    zero_root: bool


def scale(A: np.ndarray, Ad: np.ndarray) -> float:
    """R = ||A||_2 + ||A_d||_2 (rad/s): every |lambda(A + A_d e^{-j theta})| <= R."""
    return float(np.linalg.norm(A, 2) + np.linalg.norm(Ad, 2))


def _eig_derivative(A, Ad, theta: float):
    """Eigenvalues of M(theta) and their derivatives d lambda / d theta
    = y^H (-j A_d e^{-j theta}) x / (y^H x) (simple eigenvalues)."""
    z = np.exp(-1j * theta)
    ev, yl, xr = sl.eig(A + Ad * z, left=True, right=True)
    num = np.einsum("ik,ij,jk->k", yl.conj(), -1j * z * Ad, xr)
    den = np.einsum("ik,ik->k", yl.conj(), xr)
    with np.errstate(all="ignore"):
        d = num / den
    d[~np.isfinite(d)] = np.inf
    return ev, d


def _eig_derivative_batch(A, Ad, thetas: np.ndarray):
    """:func:`_eig_derivative` on a grid (batched LAPACK calls)."""
    z = np.exp(-1j * thetas)[:, None, None]
    ev, X = np.linalg.eig(A[None] + Ad[None] * z)
    try:
        Xi = np.linalg.inv(X)
    except np.linalg.LinAlgError:
        return tuple(np.array(v) for v in zip(*(_eig_derivative(A, Ad, t) for t in thetas)))
    DX = (-1j * z * Ad[None]) @ X
    d = np.einsum("mki,mik->mk", Xi, DX)
    d[~np.isfinite(d)] = np.inf
    return ev, d


def _direction(d_re: float, R: float) -> int:
    return 0 if abs(d_re) <= TANGENT_RTOL * R else (1 if d_re > 0 else -1)


def _multiplicity(A, Ad, theta: float, lam: complex, R: float, ev=None) -> int:
    if ev is None:
        ev = np.linalg.eigvals(A + Ad * np.exp(-1j * theta))
    return max(1, int(np.sum(np.abs(ev - lam) <= CLUSTER_RTOL * R)))


def zero_root(A, Ad, R: float) -> bool:
    """s = 0 is a root at every delay: A + A_d has an eigenvalue within
    ZERO_RTOL R of 0 (rounding of an exactly singular matrix)."""
    return bool(np.min(np.abs(np.linalg.eigvals(A + Ad))) <= ZERO_RTOL * R)


def _to_crossing(A, Ad, theta: float, lam: complex, d: complex, R: float, ev=None):
    """(theta, axis eigenvalue lam of M(theta)) -> Crossing with omega > 0, or
    None for w = 0 (s = 0 is handled by :func:`zero_root`; elsewhere h = inf).
    ``ev``: the eigenvalues of M(theta) when already computed."""
    w = float(lam.imag)
    if abs(w) <= ZERO_RTOL * R:
        return None
    mult = _multiplicity(A, Ad, theta, lam, R, ev)
    if w > 0:
        return Crossing(w, _wrap(theta), _direction(d.real, R), mult)
    # conjugate branch: conj(lambda(theta)) is an eigenvalue of M(2 pi - theta)
    return Crossing(-w, _wrap(-theta), -_direction(d.real, R), mult)


def _wrap(theta: float) -> float:
    """theta mod 2 pi in [0, 2 pi) (a rounding to 2 pi becomes 0)."""
    t = theta % TWO_PI
    return 0.0 if t >= TWO_PI else t


def _merge(found, R: float) -> tuple[Crossing, ...]:
    out: list[Crossing] = []
    for c in sorted(found, key=lambda c: (c.omega, c.theta)):
        for i, o in enumerate(out):
            dth = abs(c.theta - o.theta)
            if (abs(c.omega - o.omega) <= MERGE_RTOL * R
                    and min(dth, TWO_PI - dth) <= MERGE_RTOL):
                if o.direction == 0 and c.direction != 0:
                    out[i] = c
                break
        else:
            out.append(c)
    return tuple(sorted(out, key=lambda c: (c.h0, c.omega)))


def _collect(A, Ad, polished, R: float) -> CrossingSet:
    found = [_to_crossing(A, Ad, *p[:3], R, *p[3:]) for p in polished]
    return CrossingSet(_merge([c for c in found if c is not None], R), False)


# -- Newton on Re lambda(theta) = 0 ------------------------------------------------
def _newton_phase(A, Ad, theta: float, guess: complex, R: float, *,
                  bracket: tuple[float, float, float] | None = None, iters: int = 60):
    """Polish theta so that the eigenvalue of M(theta) nearest ``guess`` has zero
    real part. With ``bracket = (ta, tb, f(ta))`` (a sign change of the branch)
    the iteration is safeguarded by bisection. Returns (theta, lambda,
    dlambda/dtheta, eigenvalues of M(theta)), or None when it does not converge."""
    lam = d = None
    for _ in range(iters):
        ev, dv = _eig_derivative(A, Ad, theta)
        k = int(np.argmin(np.abs(ev - guess)))
        lam, d = ev[k], dv[k]
        f, fp = lam.real, d.real
        if abs(f) <= AXIS_RTOL * R:
            return theta, lam, d, ev
        step = f / fp if np.isfinite(fp) and fp != 0 else math.inf
        new = theta - step
        if bracket is not None:
            ta, tb, fa = bracket
            ta, tb, fa = (theta, tb, f) if (f > 0) == (fa > 0) else (ta, theta, fa)
            bracket = (ta, tb, fa)
            if not ta < new < tb:
                new = 0.5 * (ta + tb)
            if tb - ta <= 4 * EPS * max(abs(ta), abs(tb)):
                return theta, lam, d, ev
        elif not math.isfinite(new) or abs(step) > 0.5:
            return None
        guess = lam + d * (new - theta) if np.isfinite(d) else lam
        if abs(new - theta) <= 4 * EPS * max(abs(theta), abs(new)):
            ev, dv = _eig_derivative(A, Ad, new)
            k = int(np.argmin(np.abs(ev - guess)))
            return new, ev[k], dv[k], ev
        theta = new
    if lam is not None and abs(lam.real) <= math.sqrt(EPS) * R:
        return theta, lam, d          # lam is of the previous iterate: no eigenvalues given
    return None


# -- method 1: Chen-Gu-Nett pencil -----------------------------------------------------
def kronecker_crossings(A: np.ndarray, Ad: np.ndarray) -> CrossingSet:
    """Every crossing from the unit-circle eigenvalues of the Chen-Gu-Nett pencil
    [CGN95], each polished by Newton's method (inputs already checked)."""
    n = A.shape[0]
    R = scale(A, Ad)
    if R == 0 or zero_root(A, Ad, R):
        return CrossingSet((), True)
    I, N = np.eye(n), n * n
    P2, P1, P0 = np.kron(Ad, I), np.kron(A, I) + np.kron(I, A), np.kron(I, Ad)
    lhs = np.block([[np.zeros((N, N)), np.eye(N)], [-P0, -P1]])
    rhs = np.block([[np.eye(N), np.zeros((N, N))], [np.zeros((N, N)), P2]])
    with np.errstate(all="ignore"):
        zs = sl.eigvals(lhs, rhs)
    zs = zs[np.isfinite(zs) & (np.abs(zs) > 0)]
    zs = zs[np.abs(np.abs(zs) - 1.0) <= PENCIL_PREFILTER]
    polished = []
    for z in zs:
        theta = float(-np.angle(z)) % TWO_PI
        if theta > math.pi:                  # conjugate branch on [0, pi]
            theta = TWO_PI - theta
        ev = np.linalg.eigvals(A + Ad * np.exp(-1j * theta))
        for lam in ev[np.abs(ev.real) <= PENCIL_PREFILTER * R]:
            p = _newton_phase(A, Ad, theta, lam, R)
            if p is not None:          # any theta: _to_crossing folds it to omega > 0
                polished.append(p)
    return _collect(A, Ad, polished, R)


# -- method 2: phase sweep following every branch --------------------------------------
#: The last few sweeps, by their exact input (a margin and the windows of one loop
#: share one sweep: the cost of the exact methods at large n is the sweep).
_SWEEPS: dict = {}
SWEEP_CACHE = 8


def phase_crossings(A: np.ndarray, Ad: np.ndarray, *, grid: int | None = None) -> CrossingSet:
    """Every crossing by a sweep of theta in [0, pi] that follows each eigenvalue
    branch of A + A_d e^{-j theta} (inputs already checked; ``grid`` initial
    intervals, default 32 + 4 n). The result of the same (A, A_d, grid), bit for
    bit, is computed once (the last :data:`SWEEP_CACHE` inputs are kept)."""
    A, Ad = np.ascontiguousarray(A, dtype=float), np.ascontiguousarray(Ad, dtype=float)
    key = (A.shape, A.tobytes(), Ad.tobytes(), grid)
    if key not in _SWEEPS:
        if len(_SWEEPS) >= SWEEP_CACHE:
            del _SWEEPS[next(iter(_SWEEPS))]
        _SWEEPS[key] = _sweep(A, Ad, grid)
    return _SWEEPS[key]


def _sweep(A: np.ndarray, Ad: np.ndarray, grid: int | None) -> CrossingSet:
    n = A.shape[0]
    R = scale(A, Ad)
    if R == 0 or zero_root(A, Ad, R):
        return CrossingSet((), True)
    noise = 64 * EPS * R
    idx = np.arange(n)
    m = grid or 32 + 4 * n
    thetas = np.linspace(0.0, math.pi, m + 1)
    ev, dv = _eig_derivative_batch(A, Ad, thetas)
    stack = [(thetas[i], ev[i], dv[i], thetas[i + 1], ev[i + 1], dv[i + 1], 0)
             for i in range(m)]
    brackets = []
    budget = MAX_INTERVALS
    while stack:
        budget -= 1
        if budget < 0:
            raise ArithmeticError(f"phase sweep not resolved in {MAX_INTERVALS} intervals "
                                  "(eigenvalue branches too close to the imaginary axis)")
        ta, la, da, tb, lb, db, depth = stack.pop()
        dt = tb - ta
        fwd = np.abs((la + da * dt)[:, None] - lb[None, :])     # a-branch k -> b-eig j
        bwd = np.abs((lb - db * dt)[:, None] - la[None, :])     # b-eig j -> a-branch k
        mk = np.argmin(fwd, axis=1)
        back = np.argmin(bwd, axis=1)
        err = np.maximum(fwd[idx, mk], bwd[mk, idx])
        u = np.where(np.isfinite(err), err, np.inf) + noise
        cand = fwd <= 2 * u[:, None]                          # possible continuations
        pos_a, pos_b = la.real > 0, lb.real > 0
        same = ~np.any(cand & (pos_b[None, :] != pos_a[:, None]), axis=1)
        low = np.minimum(np.abs(la.real),
                         np.min(np.where(cand, np.abs(lb.real)[None, :], np.inf), axis=1))
        clear = same & (low > u / 2)        # off the axis: the chord deviates by ~u/4
        found, refine = [], False
        for k in np.flatnonzero(~clear):
            j = mk[k]
            ra, rbs = la[k].real, lb[cand[k]].real
            final = err[k] <= noise or depth >= MAX_DEPTH   # halving cannot help
            if ra * lb[j].real <= 0 and (final or len(rbs) == 1 and back[j] == k
                                         or np.all((rbs > 0) != (ra > 0))):
                found.append((ta, tb, la[k], lb[j]))
            elif not final:
                refine = True
                break
        if refine:
            tm = 0.5 * (ta + tb)
            em, dm = _eig_derivative(A, Ad, tm)
            stack += [(ta, la, da, tm, em, dm, depth + 1), (tm, em, dm, tb, lb, db, depth + 1)]
        else:
            brackets += found
    polished = []
    for ta, tb, la, lb in brackets:
        fa, fb = la.real, lb.real
        if fa == 0 or fb == 0:
            t0, guess = (ta, la) if fa == 0 else (tb, lb)
            p = _newton_phase(A, Ad, t0, guess, R)
        else:
            t0 = ta - fa * (tb - ta) / (fb - fa)
            guess = la + (lb - la) * (t0 - ta) / (tb - ta)
            p = _newton_phase(A, Ad, t0, guess, R, bracket=(ta, tb, fa))
        if p is not None:
            polished.append(p)
    return _collect(A, Ad, polished, R)
