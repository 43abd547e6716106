"""Certified delay-bound synthesis (paper 003, Theorem 1 + Remark 3).

:func:`synthesize_delay_bound` sweeps eps, bisects the delay for each with
the DPP problem built once, takes the canonical (well-posed) gain of each
row (:mod:`workbench.lmi.gain`: minimum-norm certificate at
``gain_fraction * h_certified``, K rounded to ``gain_digits`` significant
digits, then certified on its own with K fixed), and cross-checks every gain
with the exact delay margins of :mod:`workbench.margins`.

Numerical conditioning: A of the antiskid linearisation mixes m/s and a
dimensionless creep ratio (entries from 4e-2 to 6e1). The LMI is solved in
coordinates E = T E~ with T = diag of powers of two from LAPACK's balancing
(``scipy.linalg.matrix_balance``), which is exact in floating point; the
free-weighting criterion is invariant under this congruence, the re-check
runs in the same coordinates, and K is mapped back (K = K~ T^{-1}).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .forked_stage import ForkedStage
from .jsonable import json_method
from .lmi.core import DEFAULT_MARGIN, IMPLIED, Bracket, Outcome, bisect_delay
from .lmi.diagnosis import synthesis_reason, uncontrollable_mode
from .lmi.freeweighting003 import FreeWeighting003, FreeWeighting003FixedK
from .lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION, CanonicalGain, canonical_gain
from .lmi.primal import precompile
from .lmi.scaling import balancing
from .margins import DelayMargin, delay_margin_eig, delay_margin_siso, stability_windows


@dataclass(frozen=True)
class SynthesisSettings:
    """Numerical settings of the certified bisection.

    Attributes
    ----------
    margin : float
        Named relative LMI definiteness margin (see :mod:`workbench.lmi.core`).
    rel_tol : float
        Relative width of the final bracket [h_certified, h_refuted].
    h_min, h_max : float
        Delay search range (s).
    max_solves : int
        Solver budget per row.
    gain_fraction : float
        The canonical gain is taken at ``gain_fraction * h_certified``.
    gain_digits : int
        Significant digits of the canonical gain.
    """

    margin: float = DEFAULT_MARGIN
    rel_tol: float = 1e-4
    h_min: float = 1e-4
    h_max: float = 100.0
    max_solves: int = 60
    gain_fraction: float = DEFAULT_FRACTION
    gain_digits: int = DEFAULT_DIGITS

    def bisection(self) -> dict:
        """Keyword arguments of :func:`~workbench.lmi.core.bisect_delay`."""
        return dict(h_lo=self.h_min, h_hi=self.h_max, rel_tol=self.rel_tol,
                    max_solves=self.max_solves)


#: Declared range of a delay search cap h_max (s), in design files and the API alike.
H_MAX_RANGE = (1e-3, 1e4)


def check_search_options(h_max, margin, rel_tol) -> None:
    """ValueError naming the first of ``h_max`` (s, in :data:`H_MAX_RANGE`),
    ``margin`` (in (0, 0.01)) and ``rel_tol`` (in (0, 0.1]) out of its range,
    with the design files' range (the API's check of a search's options)."""
    lo, hi = H_MAX_RANGE
    for name, v, ok, what in (
            ("h_max", h_max, lambda x: lo <= x <= hi, f"a number (s) in [{lo:g}, {hi:g}]"),
            ("margin", margin, lambda x: 0 < x < 1e-2, "a number in (0, 0.01)"),
            ("rel_tol", rel_tol, lambda x: 0 < x <= 0.1, "a number in (0, 0.1]")):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not ok(float(v)):
            raise ValueError(f"{name} = {str(v)[:60]}; expected {what} (as in design files)")


@dataclass(frozen=True)
class SynthesisRow:
    """One eps of the sweep (one row of the paper's Table 3).

    Attributes
    ----------
    eps : float
    h_certified, h_refuted : float
        Bracket (s) of the criterion: certified by an optimal solve with a
        passing re-check / refuted by an optimal solve (``inf``: none refuted
        in range). Theorem 1 of paper 003 is a delay-range criterion: the
        gain of the certificate at h_certified is certified for every
        constant delay in [0, h_certified] (an interval certificate).
    K : tuple[float, ...] or None
        Canonical gain (original coordinates, rounded to the settings'
        ``gain_digits``); see :mod:`workbench.lmi.gain`.
    status : Outcome
        CERTIFIED when the bracket is certified and the canonical gain
        certifies a positive delay on its own.
    exact : DelayMargin or None
        Exact delay margin of x' = A x + B K x(t - h) (eigenvalue method).
    exact_siso : DelayMargin or None
        Same, from python-control's crossovers (independent method).
    recheck_min : float or None
        Smallest relative re-check margin of the canonical certificate.
    solves : int
    seconds : float
    statuses : tuple[str, ...]
        Outcome letter per solve (c / r / i), in order.
    recheck : dict[str, float]
        Relative re-check margin of every LMI block of the canonical
        certificate (at ``gain.h_design``).
    certificate : dict[str, numpy.ndarray]
        Decision variables of the canonical certificate (balanced
        coordinates, see module docstring).
    gain : CanonicalGain or None
        The canonical gain with its own certified bracket.
    windows : tuple of (lo, hi)
        Exact stable windows of x' = A x + B K x(t - h) (canonical K) within
        [0, h_max] (``hi = inf``: stable for every larger delay).
    reason : str
        Why the row is not certified (an uncontrollable mode, the solver
        status, the block that failed its re-check, ...); empty otherwise.
    """

    eps: float
    h_certified: float
    h_refuted: float
    K: tuple[float, ...] | None
    status: Outcome
    exact: DelayMargin | None
    exact_siso: DelayMargin | None
    recheck_min: float | None
    solves: int
    seconds: float
    statuses: tuple[str, ...] = field(repr=False)
    recheck: dict = field(default_factory=dict, repr=False)
    certificate: dict = field(default_factory=dict, repr=False)
    gain: CanonicalGain | None = field(default=None, repr=False)
    windows: tuple = ()
    reason: str = ""

    @property
    def certified_interval(self) -> tuple[float, float] | None:
        """[0, h_gain] (s): the canonical gain is certified for every constant
        delay in it (paper 003 Theorem 1 is a delay-range criterion); None
        without a certified gain."""
        h = self.h_gain
        return (0.0, h) if h else None

    @property
    def h_gain(self) -> float | None:
        """Delay (s) the canonical gain certifies on its own (None: no gain)."""
        return None if self.gain is None else self.gain.h_certified

    @property
    def ratio(self) -> float | None:
        """h_certified / exact margin (0 when the exact margin is infinite)."""
        if self.exact is None or self.exact.h == 0:
            return None
        return 0.0 if math.isinf(self.exact.h) else self.h_certified / self.exact.h

    #: The JSON of a synthesis row (:func:`workbench.jsonable.to_json`).
    JSON_FIELDS = {"eps": "eps", "h_certified": "h_certified", "h_refuted": "h_refuted",
                   "K": "K", "h_gain": "h_gain", "h_design": "gain.h_design",
                   "exact_margin": "exact.h", "stable_windows": "windows",
                   "certified_interval": "certified_interval", "status": "status",
                   "solves": "solves", "seconds": lambda r: round(r.seconds, 4),
                   "reason": "reason"}
    to_json = json_method


def _balanced(A, B):
    """(A~, B~, T, T^{-1}) with A~ = T^{-1} A T, B~ = T^{-1} B (see module docstring)."""
    A, B = np.asarray(A, float), np.asarray(B, float).reshape(np.shape(A)[0], -1)
    T = balancing(A)
    Tinv = np.diag(1.0 / np.diag(T))
    return Tinv @ A @ T, Tinv @ B, T, Tinv


class _SharedFixedK:
    """``fixed(K)`` of :func:`canonical_gain` for an eps sweep: ONE
    :class:`FreeWeighting003FixedK` with the gain and eps as parameters, set
    for each call, instead of a new LMI (and a new cvxpy compilation) per eps
    (issue 36, item 4). Same LMI, same numpy re-check; only the compiled
    problem is reused. ``WORKBENCH_SYNTH_UNSHARED=1`` selects the old path
    (one new LMI per call; ``benchmarks/check_times.py --synthesize``)."""

    def __init__(self, crit: FreeWeighting003, margin: float):
        self.crit, self.margin, self.lmi = crit, margin, None
        self.unshared = os.environ.get("WORKBENCH_SYNTH_UNSHARED") == "1"

    def __call__(self, Kt) -> FreeWeighting003FixedK:
        if self.unshared:
            return FreeWeighting003FixedK(self.crit.A, self.crit.B, self.crit.eps, K=Kt,
                                          margin=self.margin)
        if self.lmi is None:
            self.lmi = FreeWeighting003FixedK(self.crit.A, self.crit.B, self.crit.eps, K=Kt,
                                              margin=self.margin, shared=True)
        else:
            self.lmi.set_eps(self.crit.eps)
            self.lmi.set_gain(Kt)
        return self.lmi


#: Run each eps's tie-break (canonical gain) and exact margins in one forked
#: worker process while the next eps is bisected here
#: (:class:`~workbench.forked_stage.ForkedStage`; issue 36, item 4). The
#: bisection of eps i + 1 depends only on the bracket of eps i (its guess),
#: never on a gain, so no probe moves; the worker is a fork taken before any
#: solve, its parameters are set by :func:`_row`'s own calls (eps by
#: ``set_eps``, the delay by every solve) and Clarabel keeps no state between
#: solves, so every solve sees the same data and gives the same bits. Before
#: the first row the worker compiles the shared fixed-gain LMI (a DPP
#: compilation does not depend on the parameter values) and imports
#: python-control (unless this process has: it does from its second sweep on).
#: False, or the environment variable ``WORKBENCH_SYNTH_SERIAL=1``, runs
#: everything here, one eps after the other (``benchmarks/synthesize_delay_bound.py``).
PIPELINE = True


def _import_siso() -> None:
    """The lazy import of :func:`~workbench.margins.delay_margin_siso` (python-control)."""
    try:
        import control  # noqa: F401
    except ImportError:
        pass


def _row(eps, br: Bracket, crit: FreeWeighting003, A, B, T,
         settings: SynthesisSettings, fixed: Callable | None = None) -> SynthesisRow:
    K = exact = exact_siso = rmin = gain = None
    windows = ()
    recheck, cert = {}, {}
    status, steps = br.outcome, list(br.steps)
    if br.certificate is not None:
        gain = canonical_gain(
            crit, br.h_certified,
            fixed or _SharedFixedK(crit, settings.margin), T, fraction=settings.gain_fraction, digits=settings.gain_digits,
            refuted_from=br.h_refuted, **settings.bisection())
        steps.append(gain.point)
        if gain.analysis is not None:
            steps += gain.analysis.steps
        if gain.K is None or gain.outcome is not Outcome.CERTIFIED:
            status = Outcome.INCONCLUSIVE
        if gain.K is not None:
            recheck, cert = dict(gain.point.recheck), dict(gain.point.certificate)
            rmin = min(recheck.values())
            K = tuple(float(k) for k in gain.K.ravel())
            exact = delay_margin_eig(A, B @ gain.K)
            windows = tuple((a, b if math.isinf(b) else min(b, settings.h_max))
                            for a, b in stability_windows(A, B @ gain.K, settings.h_max))
            if B.shape[1] == 1:
                exact_siso = delay_margin_siso(A, B, gain.K)
    reason = ("" if status is Outcome.CERTIFIED else
              synthesis_reason(br, gain, margin=settings.margin, h_cap=settings.h_max))
    return SynthesisRow(float(eps), br.h_certified, br.h_refuted, K, status, exact,
                        exact_siso, rmin, sum(not s.solver_status.startswith(IMPLIED) for s in steps),
                        sum(s.seconds for s in steps),
                        tuple(s.outcome.value[0] for s in br.steps), recheck, cert, gain,
                        windows, reason)


def synthesize_delay_bound(A, B, eps_values, settings: SynthesisSettings = SynthesisSettings()
                           ) -> tuple[SynthesisRow, ...]:
    """Sweep eps of problem (60) of paper 003 and certify each delay bound.

    Parameters
    ----------
    A : (n, n) array_like
        Error-system matrix (eq 32).
    B : (n, m) array_like
        Input matrix (eq 32).
    eps_values : sequence of float
        Remark 3's scalar (R = eps L), each > 0.
    settings : SynthesisSettings

    Returns
    -------
    tuple of SynthesisRow
        In the order of ``eps_values``.
    """
    A, B = np.asarray(A, float), np.asarray(B, float).reshape(np.shape(A)[0], -1)
    diag = uncontrollable_mode([(A, B)])
    if diag is not None:                 # diagnosed before any solve
        return tuple(SynthesisRow(float(e), 0.0, math.inf, None, Outcome.INFEASIBLE, None, None,
                                  None, 0, 0.0, (), reason=diag.reason) for e in eps_values)
    At, Bt, T, _ = _balanced(A, B)
    crit = FreeWeighting003(At, Bt, eps_values[0], margin=settings.margin)
    fixed = _SharedFixedK(crit, settings.margin)

    def row(eps, br):                   # the tie-break and exact margins of one eps
        crit.set_eps(eps)
        return _row(eps, br, crit, A, B, T, settings, fixed)

    def warm():      # in the worker, while the first eps is bisected here
        if not fixed.unshared:
            lmi = fixed(np.zeros((B.shape[1], A.shape[0])))
            lmi.set_delay(settings.h_max)
            precompile(lmi._problem)
        if B.shape[1] == 1:
            _import_siso()
    if B.shape[1] == 1 and ForkedStage.started:
        _import_siso()   # a later sweep in this process: once here, not in every worker
    stage = (ForkedStage.start(row, len(eps_values), warm=warm)
             if PIPELINE and os.environ.get("WORKBENCH_SYNTH_SERIAL") != "1" else None)
    rows, guess = [], None
    try:
        for eps in eps_values:
            crit.set_eps(eps)
            br = bisect_delay(crit.solve_at, guess=guess, **settings.bisection())
            if br.h_certified > 0:
                guess = br.h_certified
            if stage is None:
                rows.append(row(eps, br))
            else:
                stage.submit(eps, br)
    except BaseException:
        if stage is not None:
            stage.close(finish=False)
        raise
    return tuple(rows) if stage is None else stage.results(row)


def certify_given_gain(A, B, K, eps: float, settings: SynthesisSettings = SynthesisSettings()
                       ) -> Bracket:
    """Largest delay the criterion of problem (60) certifies for a *given* K
    (V = K L fixed), e.g. a gain printed in a paper."""
    At, Bt, T, _ = _balanced(A, B)
    crit = FreeWeighting003FixedK(At, Bt, eps, K=np.atleast_2d(K) @ T, margin=settings.margin)
    return bisect_delay(crit.solve_at, **settings.bisection())


def eps_for_bound(A, B, h_target: float, eps_lo: float, eps_hi: float, *,
                  settings: SynthesisSettings = SynthesisSettings(), rel_tol: float = 1e-3
                  ) -> float | None:
    """The eps at which problem (60)'s certified bound equals ``h_target``.

    Bisection on eps in [eps_lo, eps_hi], assuming the bound grows with eps
    there (checked at the ends; ``None`` when ``h_target`` is not bracketed).
    """
    At, Bt, _, _ = _balanced(A, B)
    crit = FreeWeighting003(At, Bt, eps_lo, margin=settings.margin)

    def h_of(eps):
        crit.set_eps(eps)
        return bisect_delay(crit.solve_at, guess=h_target, **settings.bisection()).h_certified

    lo, hi = eps_lo, eps_hi
    if not (h_of(lo) <= h_target <= h_of(hi)):
        return None
    while hi - lo > rel_tol * hi:
        mid = 0.5 * (lo + hi)
        if h_of(mid) < h_target:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)
