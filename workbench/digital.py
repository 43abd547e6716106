"""Digital implementation certificates: the largest sampling interval (and network
delay) that keeps a state-feedback loop stable, certified and checked exactly.

:func:`implementation` puts three independent answers side by side for
x' = A x + B u, u(t) = K x(t_k) held (ZOH) from t_k + tau_k:

* **certified** (an LMI with a numpy re-check): the largest T_max such that
  the loop is exponentially stable for EVERY sequence of sampling intervals
  in [T_min, T_max] (and every delay sequence in [tau_min, tau_max]);
  - without network delay: one quadratic Lyapunov function for all lifted
    maps, proved over the continuum of intervals
    (:mod:`workbench.lmi.sampled`, Fujioka 2009; Oishi & Fujioka 2010);
  - with network delay: the input-delay approach (Fridman 2010): the held
    input is K x(t - tau(t)) with tau(t) = t - t_k in [tau_min, T_max + tau_max]
    (packets in order), certified for any time-varying delay in that interval
    by :func:`workbench.lmi.varying.certified_varying_delay` (unknown
    derivative); T_certified = h2 - tau_max, on the grid of printed values
    (:data:`PRINTED_DIGITS`);
* **exact periodic** (no LMI): the stable set of constant periods T at the
  constant delays tau_min and tau_max, from the spectral radius of the lifted
  map (:mod:`workbench.margins.sampled`); its first unstable T bounds every
  aperiodic certificate from above;
* **jitter falsifier**: alternating intervals T1, T2 whose two-period map has
  spectral radius above 1 — an unstable admissible sequence.

The outcome for a requested range is CERTIFIED (the certified bound covers
it), REFUTED (a periodic or alternating counterexample lies inside it) or
INCONCLUSIVE (with the reason).

References
----------
Fridman, E. (2010). A refined input delay approach to sampled-data control.
Automatica 46(2), 421-427.
Fujioka, H. (2009). Stability analysis of systems with aperiodic
sample-and-hold devices. Automatica 45(3), 771-775.
Hetel, L. et al. (2017). Recent developments on the stability of systems with
aperiodic sampling: an overview. Automatica 76, 309-335.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from .jsonable import to_json as jsonable
from .lmi.core import DEFAULT_MARGIN, Outcome
from .printed_grid import directed, sig_round
from .margins.sampled import PeriodicStableSet, alternating_radius, periodic_stable_set

__all__ = ["ImplementationResult", "implementation", "synthesize_sampled"]

#: Points of the exact periodic scan and of each axis of the jitter scan.
PERIODIC_GRID, JITTER_GRID = 240, 24
#: The exact scan keeps at most this many inputs in flight (T >= tau / MAX_QUEUE).
MAX_QUEUE = 48
#: Significant digits of the printed T_certified: with network delay it is decided
#: on that grid (the grid value above the bisection's end, certified by a solve
#: there, else the end, printed rounded down), so a last-bit difference in the
#: search cannot move the printed digit (issue 36).
PRINTED_DIGITS = 3
#: Declared range of a sampling period (s), as a design's ``[implementation]``
#: (:data:`workbench.features.sampled.T_RANGE`, issue 32).
T_RANGE = (1e-6, 1e3)


@dataclass(frozen=True)
class ImplementationResult:
    """Certified and exact sampling bounds of one loop (see the module docstring).

    Attributes
    ----------
    method : str
        ``"lifted-quadratic"`` or ``"input-delay"``.
    sampling : (float, float) or None
        Requested interval range [T_min, T_max] (s); None: only the bounds.
    periodic : bool
        The request was one period T (``sampling = T``).
    network_delay : (float, float)
        [tau_min, tau_max] (s).
    decay_rate : float
        Required decay rate (1/s) carried by the certificate (0: none).
    T_certified, T_refuted : float
        Bracket of the certified T_max (s): every interval sequence in
        [T_min, T_certified] is proved stable; the criterion failed at T_refuted.
    outcome : Outcome
    reason : str
    recheck : dict[str, float]
        Relative margins of the certificate's blocks, recomputed with numpy.
    margin : float
        Named relative margin.
    stable_sets : tuple[PeriodicStableSet, ...]
        Exact periodic stable sets at the constant delays tau_min, tau_max.
    first_unstable : float
        Smallest constant period found unstable at either delay (s).
    jitter : tuple or None
        (T1, T2, growth) of the shortest alternating counterexample found.
    K : numpy.ndarray
    """

    method: str
    sampling: tuple[float, float] | None
    periodic: bool
    network_delay: tuple[float, float]
    decay_rate: float
    T_certified: float
    T_refuted: float
    outcome: Outcome
    reason: str
    recheck: dict = field(repr=False)
    margin: float
    stable_sets: tuple[PeriodicStableSet, ...] = field(repr=False)
    first_unstable: float
    jitter: tuple | None
    K: np.ndarray = field(repr=False)

    @property
    def ratio(self) -> float:
        """T_certified / first unstable periodic T (<= 1 by theory); nan when no
        unstable period was found in the scanned range."""
        return (self.T_certified / self.first_unstable if math.isfinite(self.first_unstable)
                else math.nan)

    @property
    def at_cap(self) -> bool:
        """The certified bound is the search cap (a lower bound only)."""
        return self.T_certified > 0 and math.isinf(self.T_refuted)

    @property
    def recheck_passed(self) -> bool:
        return bool(self.recheck) and min(self.recheck.values()) >= self.margin

    def quantities(self) -> dict[str, object]:
        """Claim quantities (``implementation.<key>``), rounded so that they
        reproduce on every CPU: the certified bound and the ratio down to 3
        significant digits, the lowest certified rate (Hz) up to 3, the exact
        period to 5."""
        cert = _sig(self.T_certified, 3, math.floor)
        return {"T_certified": cert, "T_exact": _sig(self.first_unstable, 5, round),
                "ratio": None if math.isnan(self.ratio) else _sig(self.ratio, 3, math.floor),
                "outcome": self.outcome.value,
                "rate_certified": _sig(1.0 / cert, 3, math.ceil) if cert > 0 else math.inf}

    def to_json(self, **kwargs) -> str:
        """The result as a JSON string (:meth:`to_dict`; ``kwargs`` go to
        :func:`json.dumps`)."""
        import json
        return json.dumps(self.to_dict(), **kwargs)

    #: The published fields, :func:`workbench.jsonable.to_json`.
    JSON_FIELDS = {**{k: k for k in ("method", "sampling", "periodic", "network_delay",
                                     "decay_rate", "T_certified", "T_refuted", "outcome",
                                     "reason", "recheck", "margin", "first_unstable")},
                   "ratio": lambda r: None if math.isnan(r.ratio) else r.ratio,
                   "stable_sets": lambda r: [{"tau": s.tau, "intervals": s.intervals}
                                             for s in r.stable_sets],
                   "jitter": "jitter", "K": "K"}

    def to_dict(self) -> dict:
        """A JSON-ready dict (``"inf"`` for infinite values)."""
        return jsonable(self)

    def _repr_markdown_(self) -> str:
        return render_markdown(self)


def _sig(x: float, digits: int, how) -> float:
    """x rounded with ``how`` (floor, ceil or round) to ``digits`` significant digits."""
    if not (math.isfinite(x) and x > 0):
        return x
    return float(f"{sig_round(x, digits, how, 1e-12 if how is math.floor else 0.0):.{digits + 2}g}")


def render_markdown(r: ImplementationResult) -> str:
    """The result as a Markdown table (digits that reproduce: 4 significant,
    certified bounds rounded down)."""
    from .report.markdown import fmt, fmt_floor, margin_text, md_table
    tau = r.network_delay
    req = ("—" if r.sampling is None else f"T = {fmt(r.sampling[1])}" if r.periodic
           else f"T_k in [{fmt(r.sampling[0])}, {fmt(r.sampling[1])}]")
    sets = "; ".join(f"tau = {fmt(s.tau)}: " + (", ".join(
        f"({fmt(a)}, {fmt(b)})" for a, b in s.intervals) or "none") for s in r.stable_sets)
    jit = ("none found" if r.jitter is None else
           f"T1 = {fmt(r.jitter[0])}, T2 = {fmt(r.jitter[1])} (growth {fmt(r.jitter[2], 3)})")
    cert = fmt_floor(r.T_certified, 3) if r.T_certified > 0 else "0"
    cert = f"≥ {cert} (search cap)" if r.at_cap else cert
    rows = [["request", req + f", network delay [{fmt(tau[0])}, {fmt(tau[1])}] s, ZOH"],
            ["outcome", f"**{r.outcome.value}** — {r.reason}"],
            ["method", r.method
             + (f", decay rate {fmt(r.decay_rate)} 1/s" if r.decay_rate else "")],
            ["certified T_max (s), every interval sequence",
             f"[{cert}, {fmt(_sig(r.T_refuted, 3, math.ceil), 3)}]"],
            ["re-check (numpy)", ("passed" if r.recheck_passed else "**failed**")
             + f", smallest block margin {margin_text(min(r.recheck.values()))}"
             if r.recheck else "—"],
            ["exact: first unstable periodic T (s)", fmt(r.first_unstable, 5)],
            ["exact: stable periods (s)", sets],
            ["ratio certified / exact", _ratio_text(r)],
            ["jitter falsifier (alternating T1, T2)", jit]]
    return md_table(["", "value"], rows, "ll")


def _plant(sys, B):
    """(A, B) from a continuous StateSpace or arrays, shape-checked (ValueError)."""
    from .margins._input import real_matrix, square
    if hasattr(sys, "A") and hasattr(sys, "B") and not isinstance(sys, np.ndarray):
        if B is not None:
            raise ValueError("B given together with a StateSpace; pass one or the other")
        if getattr(sys, "dt", 0) not in (0, None):
            raise ValueError(f"sys.dt = {sys.dt!r}; expected a continuous-time system (dt = 0)")
        sys, B = sys.A, sys.B
    A = square(sys, "A")
    if B is None:
        raise ValueError("B is required when sys is a matrix")
    B = real_matrix(np.reshape(B, (-1, 1)) if np.ndim(B) == 1 else B, "B")
    if B.shape[0] != A.shape[0]:
        raise ValueError(f"B has shape {B.shape}; expected ({A.shape[0]}, m)")
    return A, B


def _loop(sys, B, K):
    """(A, B, K), shape-checked (ValueError)."""
    from .margins._input import real_matrix
    A, B = _plant(sys, B)
    K = real_matrix(np.reshape(K, (1, -1)) if np.ndim(K) == 1 else K, "K")
    n, m = A.shape[0], B.shape[1]
    if K.shape != (m, n):
        raise ValueError(f"K has shape {K.shape}; expected ({m}, {n})")
    return A, B, K


def _ratio_text(r: ImplementationResult) -> str:
    """The ratio rounded down, or why there is none."""
    from .report.markdown import fmt, fmt_floor
    if math.isnan(r.ratio):
        top = max(s.T_range[1] for s in r.stable_sets)
        return f"— (no unstable constant period up to {fmt(top)} s)"
    return fmt_floor(r.ratio, 3) if r.ratio > 0 else "0"


def _sampling(sampling) -> tuple[tuple[float, float] | None, bool]:
    if sampling is None:
        return None, False
    a, b = T_RANGE
    if np.ndim(sampling) == 0:
        T = float(sampling)
        if not a <= T <= b:
            raise ValueError(f"sampling = {sampling!r}; expected a period T (s) in [{a:g}, {b:g}]")
        return (0.0, T), True
    lo, hi = (float(v) for v in sampling)
    if not (0 <= lo <= hi and a <= hi <= b):
        raise ValueError(f"sampling = {sampling!r}; expected [T_min, T_max] with "
                         f"0 <= T_min <= T_max, T_max in [{a:g}, {b:g}] (s)")
    return (lo, hi), False


def _delays(network_delay) -> tuple[float, float]:
    if np.ndim(network_delay) == 0:
        network_delay = (network_delay, network_delay)
    lo, hi = (float(v) for v in network_delay)
    if not (0 <= lo <= hi and math.isfinite(hi)):
        raise ValueError(f"network_delay = {network_delay!r}; expected [tau_min, tau_max] "
                         "with 0 <= tau_min <= tau_max (s)")
    return lo, hi


def _certify(A, B, K, T_min, taus, alpha, margin, T_hi, rel_tol):
    """(method, T_certified, T_refuted, recheck, note)."""
    if taus[1] == 0.0:
        from .lmi.sampled import certified_sampling_bound
        sb = certified_sampling_bound(A, B, K, T_min=T_min, alpha=alpha, T_hi=T_hi,
                                      rel_tol=rel_tol, margin=margin)
        br = sb.bracket
        rc = {} if br.certificate is None else dict(br.certificate.recheck)
        return "lifted-quadratic", br.h_certified, br.h_refuted, rc, ""
    from .lmi.scaling import balancing
    from .lmi.varying import VaryingDelayLMI, certified_varying_delay
    S = balancing(A + B @ K)                 # diagonal powers of two: exact similarity
    Sinv = np.diag(1.0 / np.diag(S))
    loop = (Sinv @ A @ S, Sinv @ B @ K @ S)
    vb = certified_varying_delay(*loop, h1=taus[0], mu=None, windows="fixed",
                                 h_hi=T_hi + taus[1], rel_tol=rel_tol, margin=margin)
    br = vb.bracket
    rc = {} if br.certificate is None else dict(br.certificate.recheck)
    note = (" (the input-delay criterion carries no decay rate; stability only)"
            if alpha > 0 else "")
    T_cert, T_ref = max(br.h_certified - taus[1], 0.0), br.h_refuted - taus[1]
    up = directed(T_cert, up=True, sig=PRINTED_DIGITS)
    if 0 < T_cert < up < T_ref:              # the printed grid value, certified itself
        lmi = VaryingDelayLMI(*loop, h1=taus[0], mu=None, windows="fixed", margin=margin)
        step = lmi.solve_at(up + taus[1])
        if step.outcome is Outcome.CERTIFIED:
            T_cert, rc = up, dict(step.recheck)
    return "input-delay", T_cert, T_ref, rc, note


def _jitter(A, B, K, T_top: float, tau: float) -> tuple | None:
    """Shortest alternating counterexample (T1 < T2 <= T_top, tau < T1) on a grid."""
    best = None
    Ts = np.linspace(T_top / JITTER_GRID, T_top, JITTER_GRID)
    for j, T2 in enumerate(Ts):
        for T1 in Ts[:j]:
            if tau >= T1:
                continue
            g = alternating_radius(A, B, K, float(T1), float(T2), tau)
            if g > 1 and (best is None or T2 < best[1]):
                best = (float(T1), float(T2), g)
        if best is not None:
            return best
    return best


def implementation(sys, K, *, B=None, sampling=None, network_delay=(0.0, 0.0),
                   hold: Literal["zoh"] = "zoh", decay_rate: float = 0.0,
                   T_hi: float | None = None, margin: float = DEFAULT_MARGIN,
                   rel_tol: float = 1e-4) -> ImplementationResult:
    """Certified and exact sampling bounds of u = K x implemented digitally.

    Parameters
    ----------
    sys : control.StateSpace or (n, n) array_like
        Continuous-time plant (its A, B) or the matrix A (then pass ``B``).
    K : (m, n) array_like
        State-feedback gain, u = K x.
    B : (n, m) array_like, optional
        Input matrix when ``sys`` is an array.
    sampling : float or (float, float), optional
        A period T (s) or an aperiodic range [T_min, T_max] (s) to decide;
        None: only compute the bounds.
    network_delay : float or (float, float)
        Delay from sampling to actuation, [tau_min, tau_max] (s).
    hold : {"zoh"}
        Zero-order hold (the only hold implemented).
    decay_rate : float
        Required decay rate alpha (1/s) of the certificate (delay-free case).
    T_hi : float, optional
        Search cap on T_max (s); default 100 / (||A|| + ||B K||) or 4 T_max.
    margin : float
        Named relative LMI margin.
    rel_tol : float
        Relative width of the certified bracket.

    Returns
    -------
    ImplementationResult
    """
    if hold != "zoh":
        raise ValueError(f"hold = {hold!r}; expected 'zoh'")
    A, B, K = _loop(sys, B, K)
    req, periodic = _sampling(sampling)
    taus = _delays(network_delay)
    if not decay_rate >= 0:
        raise ValueError(f"decay_rate = {decay_rate!r}; expected >= 0 (1/s)")
    scale = 1.0 / (np.linalg.norm(A, 2) + np.linalg.norm(B @ K, 2))
    if T_hi is None:
        T_hi = max(100 * scale, 4 * req[1]) if req else 100 * scale
    elif not (isinstance(T_hi, (int, float, np.floating)) and not isinstance(T_hi, bool) and
              0 < T_hi < math.inf and (req is None or T_hi >= req[1])):
        raise ValueError(f"T_hi = {T_hi!r}; expected a finite search cap (s)" +
                         (f" at least the required T_max = {req[1]:g}" if req else " above 0"))
    T_min = 0.0 if (req is None or periodic) else req[0]
    method, T_cert, T_ref, rc, note = _certify(A, B, K, T_min, taus, decay_rate, margin,
                                               T_hi, rel_tol)
    top = max(4 * T_cert, 2 * req[1] if req else 0.0, 4 * scale)
    lo = min(top / PERIODIC_GRID, req[0] if req and req[0] > 0 else top / PERIODIC_GRID,
             1e-2 * scale)
    sets = tuple(periodic_stable_set(A, B, K, tau=t, T_max=top, grid=PERIODIC_GRID,
                                     T_min=max(lo, t / MAX_QUEUE))
                 for t in sorted(set(taus)))
    first = min(s.first_unstable for s in sets)
    jit = _jitter(A, B, K, 0.999 * min(first, top), taus[0])   # T2 periodic-stable
    outcome, reason = _decide(req, periodic, T_min, T_cert, sets, first, jit, taus)
    return ImplementationResult(method, req, periodic, taus, float(decay_rate), T_cert, T_ref,
                                outcome, reason + note, rc, margin, sets, first, jit, K)


def _decide(req, periodic, T_min, T_cert, sets, first, jit, taus):
    from .report.markdown import fmt, fmt_floor
    tc = fmt_floor(T_cert, 3) if T_cert > 0 else "0"
    if req is None:
        return ((Outcome.CERTIFIED, f"certified up to {tc} s") if T_cert > 0
                else (Outcome.INCONCLUSIVE, "nothing certified"))
    T_req = req[1]
    if T_cert >= T_req:
        return Outcome.CERTIFIED, (f"every interval sequence up to {tc} s "
                                   f"(>= {fmt(T_req)} s) is proved stable")
    bad = [s for s in sets if s.T_range[0] <= T_req and not s.contains(T_req)]
    if periodic and bad:
        return Outcome.REFUTED, (f"the constant period {fmt(T_req)} s is unstable at "
                                 f"the constant delay {fmt(bad[0].tau)} s (exact lifted map)")
    if T_min <= first <= T_req:
        return Outcome.REFUTED, (f"the constant period {fmt(first)} s in the range is unstable "
                                 "(exact lifted map)")
    if jit is not None and jit[1] <= T_req and jit[0] >= T_min:
        return Outcome.REFUTED, (f"the alternating intervals {fmt(jit[0])}, {fmt(jit[1])} s "
                                 "grow (jitter counterexample)")
    return Outcome.INCONCLUSIVE, (f"certified only up to {tc} s < {fmt(T_req)} s, "
                                  "and no counterexample was found")


def synthesize_sampled(sys, *, T_max: float, B=None, digits: int = 4,
                       margin: float = DEFAULT_MARGIN) -> ImplementationResult:
    """A gain for every sampling interval in (0, T_max], re-certified as returned.

    The gain comes from the gridded convex LMI of
    :func:`workbench.lmi.sampled_synthesis.synthesize_sampled_gain`, rounded to
    ``digits`` significant digits; that rounded gain is then decided by
    :func:`implementation` with ``sampling = (0, T_max)`` (certificate over the
    continuum, exact periodic set, jitter falsifier). When the synthesis LMI
    has no point, the result is INCONCLUSIVE with the solver's answer and
    K = 0 (nothing certified).

    Parameters
    ----------
    sys : control.StateSpace or (n, n) array_like
        Plant (its A, B) or A (then pass ``B``).
    T_max : float
        Required largest sampling interval (s).
    B : array_like, optional
    digits : int
        Significant digits of the gain.
    margin : float
        Named relative margin of the certificate.

    Returns
    -------
    ImplementationResult
    """
    from .lmi.sampled_synthesis import synthesize_sampled_gain
    if isinstance(T_max, bool) or not isinstance(T_max, (int, float, np.floating)) or \
            not T_RANGE[0] <= T_max <= T_RANGE[1]:
        raise ValueError(f"T_max = {T_max!r}; expected a sampling interval (s) in "
                         f"[{T_RANGE[0]:g}, {T_RANGE[1]:g}]")
    if isinstance(digits, bool) or not isinstance(digits, int) or not 1 <= digits <= 12:
        raise ValueError(f"digits = {digits!r}; expected a whole number of significant "
                         "digits in [1, 12]")
    A, B = _plant(sys, B)
    K, status, t = synthesize_sampled_gain(A, B, T_max, digits=digits)
    if K is None:
        zero = np.zeros((B.shape[1], A.shape[0]))
        return ImplementationResult("lifted-quadratic synthesis", (0.0, float(T_max)), False,
                                    (0.0, 0.0), 0.0, 0.0, math.inf, Outcome.INCONCLUSIVE,
                                    f"the synthesis LMI has no point (status {status}, t = {t})",
                                    {}, margin, (), math.inf, None, zero)
    return implementation(A, K, B=B, sampling=(0.0, float(T_max)), margin=margin)
