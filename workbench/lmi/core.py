"""Certified LMI feasibility in the delay h, and the bracketed bisection.

Every criterion of the workbench is a :class:`MarginLMI`: its blocks are
written once, as a function of the decision variables, and evaluated twice —
as cvxpy expressions for the solver and as numpy arrays for the independent
re-check of the returned point.

How a delay value is decided (a closed set of outcomes, cf. cvxpy's status
groups):

* the problem is solved as **maximise t** subject to every negative block
  ``F(x) <= -t I, trace(-F(x)) <= 1`` and every positive block
  ``G(x) >= t I, trace(G(x)) <= 1`` (all criteria are homogeneous, so bounding
  every block's size by 1 only fixes the scale) and ``|x| <= bound`` on the
  decision variables;
* the **margin is relative**: a point's margin is the smallest definiteness
  of its blocks divided by the size of the largest block,
  ``min_i lambda_min(-F_i) / max_j ||F_j||_*`` with the nuclear norm
  ``||F||_*`` (sum of absolute eigenvalues; the trace of a definite block)
  (:func:`relative_margins`). It does not change when the certificate is
  scaled, so how a loop is scaled (a near-zero gain entry, a slow mode, the
  time unit of the decision variables) does not decide what is certified;
  the optimal ``t*`` of the solve above is exactly the best relative margin
  of the criterion at ``h`` (the size constraints are linear, so the
  normalisation costs no extra cone);
* **CERTIFIED** when the solver reports ``optimal``, ``t* >= margin`` and the
  numpy re-check finds every block's relative margin ``>= margin`` (no
  strict LMIs: ``margin`` is the named relative definiteness margin);
* **REFUTED** when the solver reports ``optimal`` with ``t* < margin``: no
  point of the criterion holds with that relative margin;
* **INCONCLUSIVE** otherwise (inaccurate, solver error, or a point that
  fails its re-check) — never certified.

The maximise-t form always has a feasible point (x = 0, t = 0), so Clarabel
answers ``optimal`` on both sides of the boundary instead of relying on
infeasibility detection, which is fragile near a GEVP optimum where the
Lyapunov matrix becomes singular.
"""
from __future__ import annotations

import dataclasses
import math
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable, Mapping, Sequence

import cvxpy as cp
import numpy as np

from ..outcome import Outcome
from . import primal

#: Named definiteness margin of every LMI, relative to the largest block norm
#: of the certificate (see the module docstring).
DEFAULT_MARGIN = 1e-7
#: Bound on every decision variable entry, relative to the unit block size of
#: the solver's normalisation.
DEFAULT_BOUND = 1e3
#: Clarabel settings on top of its defaults (none: with relative margins the
#: defaults suffice; :attr:`MarginLMI.retry_settings` handles inaccurate answers).
CLARABEL_SETTINGS: dict = {}


#: Status of a step decided without a solve, from a relaxation refuted at or
#: below its delay (:func:`workbench.lmi.gain.canonical_gain`).
IMPLIED = "implied"


@dataclass(frozen=True)
class Block:
    """One LMI block: ``matrix <= -margin I`` (``sense='nsd'``) or ``>= margin I``."""

    name: str
    matrix: object
    sense: str  # "nsd" | "psd"


@dataclass(frozen=True)
class Step:
    """The decision at one delay value.

    Attributes
    ----------
    h : float
        Delay tested (s).
    outcome : Outcome
    solver_status : str
        cvxpy status string, or ``"error: ..."``.
    t_opt : float or None
        Optimal definiteness margin found by the solver.
    recheck : dict[str, float]
        Smallest eigenvalue margin of each block, recomputed with numpy from
        the returned values (positive = satisfied); empty when not solved.
    certificate : dict[str, numpy.ndarray] or None
        Decision variables (only for CERTIFIED steps).
    seconds : float
    """

    h: float
    outcome: Outcome
    solver_status: str
    t_opt: float | None
    recheck: Mapping[str, float]
    certificate: Mapping[str, np.ndarray] | None
    seconds: float


@dataclass(frozen=True)
class Bracket:
    """Result of a certified bisection on the delay.

    ``h_certified`` is the largest delay whose LMI was certified (0 when
    none was) and ``h_refuted`` the smallest delay refuted by the solver
    (``inf`` when none was). Inconclusive steps are kept in ``steps`` and
    never move ``h_certified``.
    """

    h_certified: float
    h_refuted: float
    outcome: Outcome
    certificate: Step | None
    steps: tuple[Step, ...] = field(repr=False)

    @property
    def solves(self) -> int:
        """Solver calls: the steps less those decided without a solve
        (status :data:`IMPLIED`)."""
        return sum(1 for s in self.steps if not s.solver_status.startswith(IMPLIED))

    @property
    def seconds(self) -> float:
        return sum(s.seconds for s in self.steps)


def relative_margins(blocks: Sequence[Block]) -> dict[str, float]:
    """Relative definiteness margin of every block, recomputed with numpy.

    Each entry is ``-lambda_max(F)`` (negative blocks) or ``lambda_min(G)``
    (positive blocks) divided by the largest nuclear norm (sum of absolute
    eigenvalues) among all blocks, so it is unchanged when the whole
    certificate is scaled; positive means satisfied. A block that is not
    symmetric to 1e-9 relative to that norm gets ``-inf``; so does every
    block when all of them vanish.
    """
    mats = [(b.name, b.sense, np.asarray(b.matrix, dtype=float)) for b in blocks]
    eigs = {name: np.linalg.eigvalsh((m + m.T) / 2) for name, _, m in mats}
    scale = max((float(np.sum(np.abs(e))) for e in eigs.values()), default=0.0)
    out: dict[str, float] = {}
    for name, sense, m in mats:
        if not scale > 0 or np.max(np.abs(m - m.T)) > 1e-9 * scale:
            out[name] = -math.inf
            continue
        e = eigs[name]
        out[name] = float(-e[-1] if sense == "nsd" else e[0]) / scale
    return out


class MarginLMI:
    """An LMI criterion in a scalar delay parameter, built once (DPP).

    Subclasses declare variables in :meth:`variables` and write the blocks
    once in :meth:`blocks`, which must work both on cvxpy expressions and on
    numpy arrays (``bmat`` is ``cvxpy.bmat`` or ``numpy.block``).

    Parameters
    ----------
    margin : float
        Relative definiteness margin (see module docstring).
    bound : float
        Bound on every decision variable entry (at unit block size).
    build : bool
        Build the cvxpy problem now (default); False defers it to the first
        solve, for an object used only for its numpy blocks and re-check
        (e.g. the frame and ends of a decay cell,
        :mod:`workbench.lmi.requirements_decay`).
    """

    #: Clarabel settings tried in order after an ``optimal_inaccurate`` answer
    #: (each on top of :data:`CLARABEL_SETTINGS`); a retry can only certify
    #: through the same numpy re-check.
    retry_settings: tuple[dict, ...] = ()
    #: The same for the minimum-norm :meth:`canonical_point` after an answer
    #: other than ``optimal`` (None: :attr:`retry_settings`).
    canonical_retry_settings: tuple[dict, ...] | None = None

    def __init__(self, *, margin: float = DEFAULT_MARGIN, bound: float = DEFAULT_BOUND,
                 build: bool = True):
        if not 0 < margin < 1:
            raise ValueError(f"margin = {margin!r}; expected a relative margin in (0, 1)")
        self.margin, self.bound = float(margin), float(bound)
        self._params = {k: cp.Parameter(nonneg=True, name=k)
                        for k in ("h", "iota") + tuple(self.parameters())}
        self._vars = self.variables()
        self._t = cp.Variable(name="t")
        self._problem = self._build() if build else None
        self._canonical: cp.Problem | None = None

    # -- to be written by each criterion -----------------------------------
    def variables(self) -> dict[str, cp.Variable]:
        raise NotImplementedError

    def parameters(self) -> tuple[str, ...]:
        """Names of scalar parameters besides ``h`` and ``iota`` (set with
        :meth:`set_parameters`; the problem is not rebuilt)."""
        return ()

    def blocks(self, x: Mapping[str, object], p: Mapping[str, object],
               bmat: Callable) -> list[Block]:
        """The LMI blocks; ``p["h"]`` is the delay, ``p["iota"] = 1/h``."""
        raise NotImplementedError

    def set_parameters(self, **values: float) -> None:
        """Set scalar parameters declared by :meth:`parameters`."""
        for k, v in values.items():
            if k in ("h", "iota") or k not in self._params:
                raise KeyError(k)
            self._params[k].value = float(v)

    def set_delay(self, h: float) -> None:
        """Set the delay parameters (``h`` and ``iota = 1/h``) before a solve;
        criteria with further delay-dependent parameters extend it."""
        self._params["h"].value, self._params["iota"].value = float(h), 1.0 / float(h)

    # -- machinery ----------------------------------------------------------
    def _symmetric_blocks(self):
        for blk in self.blocks(self._vars, self._params, cp.bmat):
            m = blk.matrix
            yield blk, (m + m.T) / 2, np.eye(m.shape[0])

    def _build(self) -> cp.Problem:
        t, cons = self._t, []
        for blk, sym, eye in self._symmetric_blocks():
            if blk.sense == "nsd":
                cons += [sym << -t * eye, -cp.trace(sym) <= 1]
            else:
                cons += [sym >> t * eye, cp.trace(sym) <= 1]
        cons += [cp.abs(var) <= self.bound for var in self._vars.values()]
        return cp.Problem(cp.Maximize(t), cons)

    def evaluate_blocks(self, values: Mapping[str, np.ndarray], h: float) -> list[Block]:
        """The blocks as numpy arrays at ``values`` (the re-check path)."""
        p = {k: float(v.value) for k, v in self._params.items() if k not in ("h", "iota")}
        p.update(h=float(h), iota=1.0 / float(h))
        return self.blocks(values, p, np.block)

    def recheck(self, values: Mapping[str, np.ndarray], h: float) -> dict[str, float]:
        """Relative margin of every block at ``values`` and delay ``h``,
        recomputed with numpy (:func:`relative_margins`)."""
        return relative_margins(self.evaluate_blocks(values, h))

    def solve_at(self, h: float) -> Step:
        """Decide the criterion at delay ``h`` (s); see the module docstring.

        After an ``optimal_inaccurate`` answer the solve is retried with each
        of :attr:`retry_settings`; the step's time counts every attempt."""
        step = self._solve_once(h, CLARABEL_SETTINGS)
        spent = step.seconds
        for extra in self.retry_settings:
            if step.solver_status != cp.OPTIMAL_INACCURATE:
                break
            step = self._solve_once(h, {**CLARABEL_SETTINGS, **extra})
            spent += step.seconds
        return dataclasses.replace(step, seconds=spent)

    def _run(self, problem: cp.Problem, h: float, settings: Mapping) -> tuple[str, float]:
        self.set_delay(h)
        return guarded_solve(problem, settings)

    def _checked(self, h: float, status: str, t_opt: float, seconds: float) -> Step:
        values = {k: np.array(v.value, dtype=float) for k, v in self._vars.items()}
        margins = self.recheck(values, h)
        ok = all(m >= self.margin for m in margins.values())
        return Step(h, Outcome.CERTIFIED if ok else Outcome.INCONCLUSIVE, status, t_opt,
                    margins, values if ok else None, seconds)

    def _solve_once(self, h: float, settings: Mapping) -> Step:
        if self._problem is None:          # deferred (``build=False``)
            self._problem = self._build()
        status, seconds = self._run(self._problem, h, settings)
        t_opt = self._t.value if status == cp.OPTIMAL else None
        if t_opt is None:
            return Step(h, Outcome.INCONCLUSIVE, status, None, {}, None, seconds)
        t_opt = float(t_opt)
        if t_opt < self.margin:
            return Step(h, Outcome.REFUTED, status, t_opt, {}, None, seconds)
        return self._checked(h, status, t_opt, seconds)

    def canonical_point(self, h: float) -> Step:
        """The minimum-norm certificate at delay ``h``: a unique point.

        The optimum of :meth:`solve_at` is in general not unique (at a
        degenerate GEVP optimum a whole face is optimal), so the point a
        solver returns, and any gain computed from it, depends on the
        solver's path and on the CPU's BLAS kernels. This solve has one
        solution instead: minimise the Euclidean norm of all decision
        variables' entries subject to ``F(x) <= -I`` and ``G(x) >= I`` — the
        projection of 0 onto a closed convex set, unique whenever the
        criterion holds at ``h`` with a positive margin (written as a
        second-order cone, which Clarabel solves more reliably here than the
        equivalent quadratic objective). After an answer other than
        ``optimal`` it is retried with :attr:`canonical_retry_settings`. The
        point is re-checked like any other (relative margins >= ``margin``).

        Returns
        -------
        Step
            CERTIFIED with the point, or INCONCLUSIVE (solver not optimal,
            infeasible at ``h``, or a failed re-check); ``t_opt`` is the
            point's smallest relative margin.
        """
        if self._canonical is None:
            cons = [sym << -eye if blk.sense == "nsd" else sym >> eye
                    for blk, sym, eye in self._symmetric_blocks()]
            size = cp.norm(cp.hstack([cp.vec(v, order="F") for v in self._vars.values()]), 2)
            self._canonical = cp.Problem(cp.Minimize(size), cons)
        status, seconds = self._run(self._canonical, h, CLARABEL_SETTINGS)
        retries = (self.retry_settings if self.canonical_retry_settings is None
                   else self.canonical_retry_settings)
        for extra in retries:
            if status == cp.OPTIMAL:
                break
            status, more = self._run(self._canonical, h, {**CLARABEL_SETTINGS, **extra})
            seconds += more
        if status != cp.OPTIMAL:
            return Step(h, Outcome.INCONCLUSIVE, status, None, {}, None, seconds)
        step = self._checked(h, status, 0.0, seconds)
        return dataclasses.replace(step, t_opt=min(step.recheck.values()))


def guarded_solve(problem: cp.Problem, settings: Mapping | None = None) -> tuple[str, float]:
    """Solve ``problem`` with Clarabel: (cvxpy status or ``"error: ..."``, seconds).

    The one place every LMI of the workbench is solved. A solver failure is an
    answer, not a crash: ``SolverError``, ``ValueError``, ``ArithmeticError``
    and Clarabel's Rust panic (pyo3 ``PanicException``, a ``BaseException``)
    become the status ``"error: <reason>"`` (one line, at most 200 characters),
    which every caller decides as INCONCLUSIVE; ``"inaccurate"`` statuses are
    returned as they are (no warning)."""
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():   # "inaccurate" is an outcome, not a warning
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL,
                          **({} if primal.FULL_UNPACK else {"method": primal.PRIMAL_ONLY}),
                          **dict(settings or {}))
        status = str(problem.status)
    except (cp.error.SolverError, ValueError, ArithmeticError) as exc:  # an answer
        status = f"error: {exc}".splitlines()[0][:200]
    except BaseException as exc:  # Clarabel's Rust panic (pyo3 PanicException) is one
        if type(exc).__name__ != "PanicException":
            raise
        status = f"error: solver panic: {exc}".splitlines()[0][:200]
    return status, time.perf_counter() - t0


#: Probes above an inconclusive (solver-inaccurate) upper end of a bisection
#: before it is accepted as the bracket's end (:func:`bisect_delay`).
ISLAND_SKIPS = 2


def bisect_delay(decide: Callable[[float], Step], *, h_lo: float, h_hi: float,
                 rel_tol: float = 1e-4, max_solves: int = 60, guess: float | None = None,
                 secant: bool = True, max_seconds: float = 3600.0) -> Bracket:
    """Bracketed bisection of a delay criterion (cf. cvxpy's ``bisection.py``).

    The search first brackets the boundary geometrically from ``guess`` (or
    from the geometric mean of ``[h_lo, h_hi]``), then shrinks the bracket
    until ``h_refuted / h_certified <= 1 + rel_tol``. With ``secant=True`` a
    step is proposed from the optimal margins t* of the two largest certified
    delays (sqrt(t*) extrapolated linearly to 0 at the boundary), safeguarded: a proposal outside
    the bracket, or two proposals that did not halve it, fall back to a
    geometric bisection step. Every point is still decided by a real solve,
    so the bracket's meaning does not depend on the proposals. Inconclusive
    steps shrink the search interval like refuted ones but never count as
    refuted; when the bracket closes on an inconclusive step, up to
    :data:`ISLAND_SKIPS` probes between it and the refuted point (or the cap)
    look past it (an inaccurate solve surrounded by certifiable delays), and a
    certified probe reopens the search above.

    Parameters
    ----------
    decide : callable
        ``decide(h) -> Step``, e.g. :meth:`MarginLMI.solve_at`.
    h_lo, h_hi : float
        Search range (s), 0 < h_lo < h_hi, required: the range is in the
        system's own time unit, so there is no absolute default (callers derive
        it from the system's time scale or from a design's cap). ``h_hi``
        certified means the bound is at least ``h_hi`` (reported as the
        bracket ``[h_hi, inf]``).
    rel_tol : float
        Relative width of the final bracket.
    max_solves : int
        Budget of solver calls.
    guess : float, optional
        Expected location of the boundary (s), e.g. from a neighbouring row.
    secant : bool
        Use the margin-secant proposals (see above).
    max_seconds : float
        Wall-clock budget (s): no new solve starts after it (the bracket so
        far is returned; without a certified point it is INCONCLUSIVE).

    Returns
    -------
    Bracket
    """
    if not (0 < h_lo < h_hi < math.inf):
        raise ValueError(f"h_lo = {h_lo!r} s, h_hi = {h_hi!r} s; expected 0 < h_lo < h_hi < inf")
    steps: list[Step] = []
    cert: Step | None = None
    lo, hi = 0.0, math.inf          # certified / first not-certified (for search)
    refuted = math.inf

    def run(h: float) -> Step:
        nonlocal cert, lo, hi, refuted
        s = decide(h)
        steps.append(s)
        if s.outcome is Outcome.CERTIFIED:
            if h > lo:
                lo, cert = h, s
        else:
            hi = min(hi, h)
            if s.outcome is Outcome.REFUTED:
                refuted = min(refuted, h)
        return s

    t0 = time.perf_counter()
    budget = lambda: len(steps) < max_solves and time.perf_counter() - t0 < max_seconds  # noqa
    h = min(max(guess if guess else math.sqrt(h_lo * h_hi), h_lo), h_hi)
    run(h)
    # ten-fold steps; a range wider than 1e12 in 12 steps, so any cap is bracketed
    factor = 1.2 if guess else max(10.0, math.exp((math.log(h_hi) - math.log(h_lo)) / 12))
    while budget():      # geometric bracketing
        if lo == 0.0:
            if h <= h_lo:
                break
            h = max(h / factor, h_lo)
        elif hi == math.inf:
            if h >= h_hi:
                break
            h = min(h * factor, h_hi)
        else:
            break
        run(h)
    stalls, skips = 0, 0
    while True:
        while budget() and lo > 0 and hi < math.inf and hi / lo > 1 + rel_tol:
            width = math.log(hi / lo)
            h = _secant_proposal(steps, lo, hi, rel_tol) if secant and stalls < 2 else None
            if h is None:
                h, stalls = math.sqrt(lo * hi), 0
            run(h)
            stalls = stalls + 1 if math.log(hi / lo) > 0.5 * width else 0
        # an inaccurate solve is not a refutation: when the bracket closed on an
        # inconclusive step well below the refuted point (or the cap), probe above it
        # (a certificate there covers the delays below, so skipping the island is sound)
        top = min(refuted, h_hi)
        if not (lo > 0 and hi < refuted and top / hi > 1 + rel_tol and skips < ISLAND_SKIPS
                and budget()):
            break
        skips += 1
        probe = math.sqrt(hi * top) if top < math.inf else 2.0 * hi
        if run(probe).outcome is not Outcome.CERTIFIED:
            break
        hi = min((st.h for st in steps if st.h > lo and st.outcome is not Outcome.CERTIFIED),
                 default=math.inf)
        stalls = 0
    if time.perf_counter() - t0 >= max_seconds:   # the cap is a reason, kept with the steps
        steps.append(Step(h, Outcome.INCONCLUSIVE,
                          f"error: wall-clock cap of {max_seconds:g} s reached", None, {},
                          None, 0.0))
    if lo > 0:
        outcome = Outcome.CERTIFIED
    elif refuted < math.inf and all(s.outcome is Outcome.REFUTED for s in steps):
        outcome = Outcome.REFUTED
    else:
        outcome = Outcome.INCONCLUSIVE
    return Bracket(lo, refuted, outcome, cert, tuple(steps))


def _secant_proposal(steps: Sequence[Step], lo: float, hi: float, rel_tol: float) -> float | None:
    """Next delay from the margins of the two largest certified delays, aimed
    just past the predicted boundary; None when no useful proposal exists."""
    pts = sorted((s.h, s.t_opt) for s in steps
                 if s.outcome is Outcome.CERTIFIED and s.t_opt is not None)[-2:]
    if len(pts) < 2:
        return None
    (h1, t1), (h2, t2) = pts
    if not t1 > t2 > 0:
        return None
    # near a GEVP optimum t* vanishes roughly quadratically: extrapolate sqrt(t*)
    s1, s2 = math.sqrt(t1), math.sqrt(t2)
    root = h2 + s2 * (h2 - h1) / (s1 - s2)
    step = 1 + 0.5 * rel_tol
    lo_ok, hi_ok = lo * step, hi / step
    if root * step <= lo_ok:          # boundary predicted right above lo: close the bracket
        return lo * (1 + 0.9 * rel_tol)
    cand = root * step
    return cand if cand < hi_ok else None
