"""The decay rate of a given gain over a delay range, by Bessel-Legendre cells.

With z = e^{alpha t} x, the loop x' = A x + A_d x(t - h) becomes
z' = (A + alpha I) z + e^{alpha h} A_d z(t - h): exponential stability of the
latter at h proves that every solution of the former decays at least like
e^{-alpha t}. The delayed matrix beta A_d, beta = e^{alpha h}, moves with h,
so [0, H] is cut into cells [h_a, h_b] and each cell is certified for every
(h, beta) in the box [h_a, h_b] x [e^{alpha h_a}, e^{alpha h_b}] (which
contains the curve beta = e^{alpha h}) by one Bessel-Legendre certificate
(order N, :class:`~workbench.lmi.analysis.BesselLegendreLMI`) with its
variables shared by the four corners:

* for a fixed beta, h Phi_N(h) = X + h Y + h^2 F'RF with R >= 0 is convex in
  h (:mod:`workbench.lmi.interval`);
* for a fixed h it is convex in beta: X and Y are affine in A_d and
  F = A e_0 + beta A_d e_1 enters through F'RF, R >= 0.

So h Phi_N(h, beta) is below the convex combination of its values at the
corners, and the cell is certified when the four corner blocks are
(h_a = 0: the interval module's limit block at both beta ends). The
argument needs the shared variables to be one functional in one set of
coordinates and one time unit at both beta ends: the analysis LMIs choose
their own balancing, modal coordinates and unit from (A, A_d)
(:mod:`workbench.lmi.coordinates`), so a cell fixes them once, from its
middle beta, and both ends are written and re-checked (on the caller's
loop) in that frame. This is
less conservative than the descriptor/Jensen synthesis LMI of
:mod:`workbench.lmi.requirements` and it is the certificate of the decay of
the returned gain.

Every cell of one size (n states, order N) is the same problem with other
numbers, so it is compiled once (:class:`CellFamily`: the cell's data as cvxpy
parameters, DPP) and re-solved per cell; each cell keeps its own frame, its
solver status and its numpy re-check of every block against the caller's loop
(``WORKBENCH_DECAY_UNSHARED=1`` selects the former path, a fresh cvxpy problem
per cell, for ``benchmarks/decay_cells.py``).

References
----------
.. [SG15] Seuret A., Gouaisbaut F., "Hierarchy of LMI conditions for the
   stability analysis of time-delay systems", SCL 81 (2015) 1-7.
.. [Fri14] Fridman E., *Introduction to Time-Delay Systems*, Birkhauser 2014,
   sec. 3.6 (the change of variables z = e^{alpha t} x).
"""
from __future__ import annotations

import copy
import dataclasses
import math
import os
import time
from typing import Sequence

import cvxpy as cp
import numpy as np

from .analysis import BesselLegendreLMI
from .coordinates import congruence, original
from .core import (DEFAULT_BOUND, DEFAULT_MARGIN, Block, Bracket, MarginLMI, Outcome, Step,
                   bisect_delay, relative_margins)
from .interval import IntervalLMI
from .legendre import blockdiag_S
from .scaling import balancing

__all__ = ["CellLMI", "CellFamily", "cell_family", "decay_cells", "certified_decay"]

#: Largest alpha (h_b - h_a) of a cell: e^{alpha h} varies by at most 10 %
#: across a cell.
CELL_LOG_SPAN = 0.1
#: Caps (issues 32, 36): cells per point at one rate and cells solved in one
#: decay search (counts: these decide, the same on every machine; the shipped
#: searches solve 31-346 cells), and wall-clock seconds of a decay search, a
#: last-resort safety only (MAX_SEARCH_CELLS cells take about 30 s of CPU on the
#: shared 2-core machine, 0.02 s a cell, so it acts on a machine or a load about
#: 20x slower). Beyond any of them a rate is INCONCLUSIVE with the cap as its reason.
MAX_CELLS, MAX_SEARCH_CELLS, MAX_SECONDS = 400, 1500, 600.0


class CellLMI(MarginLMI):
    """One Bessel-Legendre certificate for every (h, beta) of a cell (module
    docstring). ``solve_at(h_b)`` decides the cell [h_a, h_b].

    Parameters
    ----------
    A, Ad : (n, n) arrays
        The shifted system's A + alpha I and the undelayed A_d.
    betas : (float, float)
        e^{alpha h_a} and e^{alpha h_b}.
    h_a : float
        Lower end of the cell (s), 0 allowed.
    N : int
        Bessel-Legendre order.
    family : CellFamily, optional
        Solve on this compiled problem (its size must match) instead of a
        problem of the cell's own; the frame, the ends and the re-check are
        the cell's either way.
    """

    def __init__(self, A, Ad, betas: tuple[float, float], h_a: float, N: int = 2, *,
                 family: "CellFamily | None" = None, **kw):
        margin = kw.get("margin", DEFAULT_MARGIN)
        own = family is None              # a cvxpy problem of its own (else numpy only)
        # one frame (balancing T, modal coordinates L, time unit) for both ends, fixed at
        # the cell's middle beta: the variables are shared, so they must mean the same
        # functional at every (h, beta) of the cell (the convexity argument above)
        self.frame = BesselLegendreLMI(A, math.sqrt(betas[0] * betas[1]) * np.asarray(Ad, float),
                                       N, margin=margin, build=own)
        self.ends = [IntervalLMI(_at_beta(self.frame, Ad, b), from_zero=h_a == 0, build=own)
                     for b in betas]
        self.h_a = float(h_a)
        self.family = family
        super().__init__(build=own, **kw)
        if h_a > 0:
            self.set_parameters(h_a=h_a, iota_a=1.0 / h_a)
        if family is not None:
            size, own_size = ((family.n, family.N, family.bound),
                              (self.frame.n, self.frame.N, self.bound))
            if size != own_size:
                raise ValueError(f"family of size (n, N, bound) = {size}; expected {own_size}")
            self._vars, self._t, self._problem = family._vars, family._t, family._problem

    def set_delay(self, h: float) -> None:
        """The delay parameters, and the family's cell data when it has one."""
        super().set_delay(h)
        if self.family is not None:
            self.family.load(self, h)

    def recheck(self, values, h: float) -> dict[str, float]:
        """Margins re-evaluated with numpy on the caller's loop at both betas
        (:func:`~workbench.lmi.coordinates.recheck_original`, per end)."""
        L = self.frame.L
        if L is None:
            return MarginLMI.recheck(self, values, h)
        twin = copy.copy(self)
        twin.ends = []
        for end in self.ends:
            base = copy.copy(end.base)
            base.A, base.Ad = base.A0, base.Ad0
            twin.ends.append(copy.copy(end))
            twin.ends[-1].base = base
        blocks = MarginLMI.evaluate_blocks(twin, original(self.frame, values), h)
        return relative_margins([Block(b.name, congruence(np.asarray(b.matrix, float), L),
                                       b.sense) for b in blocks])

    def parameters(self):
        return () if self.h_a == 0 else ("h_a", "iota_a")

    def variables(self):
        return self.ends[0].variables()

    def blocks(self, x, p, bmat):
        out = []
        for tag, end in zip(("lo", "hi"), self.ends):
            for b in end.blocks(x, p, bmat):
                if "@" in b.name or tag == "lo":
                    out.append(dataclasses.replace(b, name=f"{b.name}/beta_{tag}"))
        return out


def _at_beta(frame, Ad, beta: float):
    """The criterion ``frame`` for the delayed matrix beta A_d, in ``frame``'s
    balancing, coordinates and time unit (T, L and the unit are not recomputed)."""
    lmi = copy.copy(frame)
    lmi.Ad0 = np.diag(1.0 / np.diag(frame.T)) @ (beta * np.asarray(Ad, float)) @ frame.T
    lmi.Ad = lmi.Ad0 if frame.L is None else np.linalg.solve(frame.L, lmi.Ad0 @ frame.L)
    return lmi


class CellFamily(MarginLMI):
    """The problem of every :class:`CellLMI` of one size (n states, order N),
    compiled once, with a cell's numbers as cvxpy parameters (DPP).

    A cell's problem has the blocks of its four corners (two betas x two
    delays, :class:`CellLMI`), each the Bessel-Legendre block of
    :class:`~workbench.lmi.analysis.BesselLegendreLMI` in the cell's frame
    and time unit u, with (A u, beta A_d u, h / u, u / h) as numbers. Written
    for parameters, a corner block is

        He(G0' Theta Pi) + c (diag(S, -S, 0) - sum_k (2k+1) Gamma_k' R Gamma_k)
        + He(G1' Theta Pg) - He(G1' D(S) Pi) + mat(M vec(R)),

    with c = u / h, Pi = c H, Pg = H, M = (h / u) (F' kron F') (vec(F'RF) =
    (F' kron F') vec(R)), i.e. the same affine function of Theta, S, R as the
    cell's own block, with every product of two numbers formed before it
    reaches cvxpy (DPP allows one parameter per product). The limit block X
    of a cell from h_a = 0 is the same form with c = u, Pg = 0, M = 0
    (:mod:`workbench.lmi.interval`). The constraints are those of
    :class:`~workbench.lmi.core.MarginLMI` on the same blocks in the same
    order, so a cell solved here is the cell's problem up to the rounding of
    those products; :meth:`CellLMI.recheck` re-checks it as before.

    Parameters
    ----------
    n : int
        States.
    N : int
        Bessel-Legendre order.
    bound : float
        Bound on every decision variable entry (the cells' own).
    """

    def __init__(self, n: int, N: int, *, bound: float = DEFAULT_BOUND):
        self.n, self.N = int(n), int(N)
        m, k = (self.N + 2) * self.n, (self.N + 1) * self.n
        self._corners = [{"Pi": cp.Parameter((k, m)), "Pg": cp.Parameter((k, m)),
                          "c": cp.Parameter(nonneg=True), "M": cp.Parameter((m * m, n * n))}
                         for _ in range(4)]
        super().__init__(bound=bound)

    def variables(self):
        n, N = self.n, self.N
        return {"Theta": cp.Variable(((N + 1) * n, (N + 1) * n), symmetric=True, name="Theta"),
                "S": cp.Variable((n, n), symmetric=True, name="S"),
                "R": cp.Variable((n, n), symmetric=True, name="R")}

    def blocks(self, x, p, bmat):
        """The blocks of a cell in :class:`CellLMI`'s order (cvxpy only: the
        numpy re-check is the cell's)."""
        Th, S, R = x["Theta"], x["S"], x["R"]
        n, N, m = self.n, self.N, (self.N + 2) * self.n
        z = np.zeros((n, n))
        G0, G1, _, _, gam = BesselLegendreLMI.selectors(self, z, z)
        e0, e1 = G0[:n], np.eye(n, m, n, dtype=int)
        fixed = e0.T @ S @ e0 - e1.T @ S @ e1 - sum((2 * k + 1) * (g.T @ R @ g)
                                                    for k, g in enumerate(gam))
        DS = blockdiag_S(S, N, n, cp.bmat) if N else None
        vecR = cp.vec(R, order="F")
        phi = []
        for d in self._corners:
            he0 = G0.T @ Th @ d["Pi"]
            he1 = G1.T @ Th @ d["Pg"]
            if N:
                he1 = he1 - G1.T @ DS @ d["Pi"]
            quad = cp.reshape(d["M"] @ vecR, (m, m), order="F")
            phi.append(he0 + he0.T + d["c"] * fixed + he1 + he1.T + quad)
        names = [f"phi@{at}/beta_{tag}" for tag in ("lo", "hi") for at in ("lo", "hi")]
        out = [Block(name, f, "nsd") for name, f in zip(names, phi)]
        own = [Block(f"{k}/beta_lo", v, "psd") for k, v in (("theta", Th), ("S_pos", S),
                                                             ("R_pos", R))]
        return out[:2] + own + out[2:]

    def _symmetric_blocks(self):
        # every block is symmetric as written (He(.) terms, c x symmetric, mat(M vec R)
        # with M = kron(F', F')), so (m + m')/2 would be m itself; it is not formed:
        # cvxpy 1.9's COO backend fails on scaling a parametrised matrix by a constant
        for blk in self.blocks(self._vars, self._params, cp.bmat):
            yield blk, blk.matrix, np.eye(blk.matrix.shape[0])

    # the selectors of BesselLegendreLMI read the order here
    @property
    def _N(self) -> int:
        return self.N

    def load(self, cell: "CellLMI", h: float) -> None:
        """Set the parameters to the numbers of ``cell`` decided at [h_a, h]."""
        corners = iter(self._corners)
        for end in cell.ends:
            base = end.base
            for at in ("lo", "hi"):
                d = next(corners)
                if at == "hi":
                    A, Ad, hs, c = base.scaled({"h": float(h), "iota": 1.0 / float(h)})
                    gate = 1.0
                elif end.from_zero:         # the limit block X (interval module)
                    A, Ad, _, c = base.scaled({"h": 0.0, "iota": 1.0})
                    hs, gate = 0.0, 0.0
                else:
                    A, Ad, hs, c = base.scaled({"h": cell.h_a, "iota": 1.0 / cell.h_a})
                    gate = 1.0
                _, _, H, F, _ = base.selectors(A, Ad)
                d["Pi"].value = c * H
                d["Pg"].value = gate * H
                d["c"].value = c
                d["M"].value = hs * np.kron(F.T, F.T)


_FAMILIES: dict[tuple[int, int, float], CellFamily] = {}


def cell_family(n: int, N: int, bound: float = DEFAULT_BOUND) -> CellFamily:
    """The compiled :class:`CellFamily` of this size (one per process)."""
    key = (int(n), int(N), float(bound))
    if key not in _FAMILIES:
        _FAMILIES[key] = CellFamily(n, N, bound=bound)
    return _FAMILIES[key]


def decay_cells(alpha: float, h_lo: float, H: float) -> list[tuple[float, float]]:
    """Equal cells covering [h_lo, H] with alpha x width <= :data:`CELL_LOG_SPAN`."""
    k = max(1, math.ceil(alpha * (H - h_lo) / CELL_LOG_SPAN))
    edges = np.linspace(h_lo, H, k + 1)
    return [(float(a), float(b)) for a, b in zip(edges[:-1], edges[1:])]


def _decide(points, alpha: float, h_lo: float, H: float, N: int, margin: float,
            deadline: float = math.inf, budget: list[int] | None = None) -> Step:
    """CERTIFIED when every cell of every point is (the last cell's step is
    returned); otherwise the first cell that was not. INCONCLUSIVE past
    :data:`MAX_CELLS` cells, when ``budget`` (cells left in the search, one
    element, decremented per cell) is spent, or past the ``deadline``
    (``time.perf_counter()``, last resort)."""
    last = None
    seconds = 0.0
    k = math.ceil(alpha * (H - h_lo) / CELL_LOG_SPAN)      # the count of decay_cells
    if not k <= MAX_CELLS:
        return Step(alpha, Outcome.INCONCLUSIVE, f"error: {k:g} delay cells at rate "
                    f"{alpha:.3g} 1/s, above the cap of {MAX_CELLS}", None, {}, None, 0.0)
    cells = decay_cells(alpha, h_lo, H)
    shared = os.environ.get("WORKBENCH_DECAY_UNSHARED") != "1"
    for A, Ad in points:
        Aa = A + alpha * np.eye(A.shape[0])
        family = cell_family(A.shape[0], N) if shared else None
        for a, b in cells:
            if budget is not None and budget[0] <= 0:
                return Step(alpha, Outcome.INCONCLUSIVE, f"error: cap of {MAX_SEARCH_CELLS} "
                            "delay cells of the decay search reached", None, {}, None, seconds)
            if time.perf_counter() > deadline:
                return Step(alpha, Outcome.INCONCLUSIVE, f"error: wall-clock cap of "
                            f"{MAX_SECONDS:g} s of the decay search reached", None, {}, None,
                            seconds)
            if budget is not None:
                budget[0] -= 1
            lmi = CellLMI(Aa, Ad, (math.exp(alpha * a), math.exp(alpha * b)), a, N,
                          margin=margin, family=family)
            step = lmi.solve_at(b)
            seconds += step.seconds
            if step.outcome is not Outcome.CERTIFIED:
                return dataclasses.replace(step, h=alpha, seconds=seconds)
            last = step
    return dataclasses.replace(last, h=alpha, seconds=seconds)


def certified_decay(points: Sequence[tuple[np.ndarray, np.ndarray]], *, h_lo: float, H: float,
                    alpha_hi: float, N: int = 2, margin: float = DEFAULT_MARGIN,
                    rel_tol: float = 1e-3, guess: float | None = None) -> Bracket:
    """Bracket of the decay rate (1/s) certified for x' = A_i x + A_d,i x(t - h),
    every constant delay in [h_lo, H] (s) and every point (A_i, A_d,i).

    A certified alpha (the bracket's ``h_certified``; the bracket's h is the
    rate) holds for every cell of every point; the bisection is the shared
    :func:`~workbench.lmi.core.bisect_delay` on alpha in
    [1e-5 alpha_hi, alpha_hi]. Coordinates are balanced per point by a
    power-of-two diagonal (exact) from A, and, when that does not certify a
    rate, from |A| + |A_d| (both are similarity transforms of the same loop,
    so either certificate proves the rate; solvers differ on them).
    """
    if not (0 <= h_lo < H < math.inf):
        raise ValueError(f"delay range [{h_lo!r}, {H!r}] s; expected 0 <= h_min < h_max < inf")
    bal: list[list] = [[], []]        # two exact power-of-two scalings of every point
    for A, Ad in points:
        A, Ad = np.asarray(A, float), np.asarray(Ad, float)
        for k, M in enumerate((A, np.abs(A) + np.abs(Ad))):   # A alone may be triangular
            T = balancing(M)
            Tinv = np.diag(1.0 / np.diag(T))
            bal[k].append((Tinv @ A @ T, Tinv @ Ad @ T))

    deadline = time.perf_counter() + MAX_SECONDS
    budget = [MAX_SEARCH_CELLS]

    def decide(a: float) -> Step:
        step = _decide(bal[0], a, h_lo, H, N, margin, deadline, budget)
        if step.outcome is Outcome.CERTIFIED:
            return step
        other = _decide(bal[1], a, h_lo, H, N, margin, deadline, budget)
        return other if other.outcome is Outcome.CERTIFIED else step

    return bisect_delay(decide, h_lo=1e-5 * alpha_hi,
                        h_hi=alpha_hi, rel_tol=rel_tol, guess=guess, max_seconds=MAX_SECONDS)
