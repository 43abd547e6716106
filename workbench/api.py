"""Python API: certified delay bounds and delayed simulations on python-control objects.

In a notebook::

    import control, workbench
    sys = control.ss([[0, 1], [0, -1]], [[0], [1]], [[1, 0]], [[0]])
    res = workbench.delay_bound(sys, method="bessel-legendre", N=3)
    res            # renders as Markdown (bracket, K, re-check, exact set)
    res.to_json()
    resp = workbench.simulate_delay(sys, res.K, h=0.5, x0=[1, 0], t_end=20)

:func:`delay_bound` synthesises a state-feedback gain K for x' = A x + B u(t - h)
(or, given ``Ad``, analyses x' = A x + A_d x(t - h)), returns the certified
bracket [h_certified, h_refuted], the numpy re-check of the certificate and the
exact stability set of the loop (independent of the LMIs). The computing is
the workbench's own: :mod:`workbench.synthesis` (paper 003's problem (60)),
:mod:`workbench.lmi.tight_synthesis` (Wirtinger synthesis),
:mod:`workbench.lmi.analysis` (Bessel-Legendre analysis, Seuret & Gouaisbaut
2015), :mod:`workbench.margins` (exact margin and windows) and
:mod:`workbench.sim.delay`.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Literal, Sequence

import numpy as np

from .jsonable import to_json as jsonable

Method = Literal["bessel-legendre", "wirtinger", "free-weighting-003", "jensen",
                 "free-weighting", "delay-independent"]
_SYNTHESIS = ("bessel-legendre", "wirtinger", "free-weighting-003")
_ANALYSIS = ("bessel-legendre", "wirtinger", "jensen", "free-weighting", "delay-independent")


#: A state past this magnitude has diverged (the simulation stops there).
DIVERGED = 1e150
#: Largest |entry| of a matrix the API accepts.
MAX_ENTRY = 1e12
#: Largest system order (states, inputs) the API accepts.
MAX_ORDER = 200
#: Most steps (t_end / dt, or h / dt in the delay buffer) of a simulation.
MAX_STEPS = 10_000_000


def _matrix(M, name: str, rows: int | None = None, cols: int | None = None) -> np.ndarray:
    """A finite real 2-D float array, shape-checked (ValueError otherwise)."""
    if type(M).__name__ in ("TransferFunction", "FrequencyResponseData"):
        raise ValueError(f"{name} is a control.{type(M).__name__}; expected a StateSpace "
                         "(convert with control.ss(sys)) or a real matrix")
    try:
        arr = np.asarray(M)
    except Exception as exc:   # ragged lists and the like
        raise ValueError(f"{name}: could not be read as a matrix ({exc})") from None
    if np.iscomplexobj(arr):
        if np.any(np.imag(arr) != 0):
            raise ValueError(f"{name} has complex entries; expected a real matrix")
        arr = np.real(arr)
    if arr.ndim == 1 and cols == 1:
        arr = arr.reshape(-1, 1)
    if arr.ndim != 2 or arr.dtype.kind not in "biuf":
        raise ValueError(f"{name} has shape {arr.shape} and dtype {arr.dtype}; expected a "
                         "2-D real numeric matrix")
    arr = arr.astype(float)
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} has non-finite entries; expected finite numbers")
    if (rows is not None and arr.shape[0] != rows) or (cols is not None and arr.shape[1] != cols):
        raise ValueError(f"{name} has shape {arr.shape}; expected "
                         f"({rows if rows is not None else 'any'}, "
                         f"{cols if cols is not None else 'any'})")
    if arr.size == 0:
        raise ValueError(f"{name} is empty; expected at least one entry")
    if not np.max(np.abs(arr)) <= MAX_ENTRY:     # Clarabel panics far past it
        raise ValueError(f"{name} has an entry of magnitude {np.max(np.abs(arr)):.3g}; "
                         f"expected at most {MAX_ENTRY:g} (rescale the model's units)")
    if max(arr.shape) > MAX_ORDER:
        raise ValueError(f"{name} has shape {arr.shape}; expected at most {MAX_ORDER} rows "
                         "and columns (the LMIs grow as the cube of the order)")
    return arr


def _system(sys, B):
    """(A, B) from a StateSpace or from arrays."""
    if type(sys).__name__ in ("TransferFunction", "FrequencyResponseData"):
        raise ValueError(f"sys is a control.{type(sys).__name__}; expected a StateSpace "
                         "(convert with control.ss(sys)) or the matrix A")
    if hasattr(sys, "A") and hasattr(sys, "B") and not isinstance(sys, np.ndarray):
        if B is not None:
            raise ValueError("B given together with a StateSpace; pass one or the other")
        dt = getattr(sys, "dt", 0)
        if dt not in (0, None):
            raise ValueError(f"sys.dt = {dt!r}; expected a continuous-time system (dt = 0)")
        if np.any(np.asarray(getattr(sys, "D", 0.0), dtype=complex) != 0):
            raise ValueError("sys has D != 0 (a feedthrough); expected D = 0: the bound is of "
                             "u = K x(t - h), with A and B only (pass control.ss(A, B, C, 0))")
        sys, B = sys.A, sys.B
    A = _matrix(sys, "A")
    if A.shape[0] != A.shape[1]:
        raise ValueError(f"A has shape {A.shape}; expected a square matrix")
    return A, B


@dataclass(frozen=True)
class DelayBoundResult:
    """A certified delay bound with its gain, re-check and the exact set.

    Attributes
    ----------
    method : str
    N : int or None
        Bessel-Legendre order (None for other methods).
    h_certified, h_refuted : float
        The bracket (s): certified by an optimal solve whose numpy re-check
        passed / refuted by an optimal solve (``inf``: none refuted up to
        ``h_max``). 0 when nothing was certified. For a synthesis it is the
        bracket of the returned K itself (rounded, then certified with K
        fixed), never the unrounded solver gain's.
    status : str
        ``"certified"``, ``"inconclusive"``, ``"refuted"`` or ``"infeasible"``
        (an uncontrollable mode with Re >= 0, diagnosed before any solve).
    certificate_kind : str
        ``"every delay in [0, h]"`` or ``"at h"``.
    K : numpy.ndarray or None
        Synthesised gain (u = K x), None for an analysis.
    A, Ad : numpy.ndarray
        The loop x' = A x + A_d x(t - h) that was certified (A_d = B K).
    recheck : dict[str, float]
        Relative margin of every LMI block of the certificate, recomputed
        with numpy by a fresh criterion object: the bracket's certificate
        (analysis; Bessel-Legendre with the returned K), or the certificate
        of the returned, rounded K with K fixed at h_certified (Wirtinger,
        problem (60)).
    recheck_passed : bool
        Every block margin >= ``margin``.
    margin : float
    exact_margin : float
        Exact delay margin h* (s) of the loop (``inf``: stable for every delay).
    exact_agreement : str
        The two exact methods' agreement (``agree``/``disagree``/``single-method``).
    windows : tuple[tuple[float, float], ...]
        Exact stability windows up to ``horizon`` (s).
    horizon : float
    at_cap : bool
        The bound is the search cap ``h_max`` (a lower bound only).
    certifies : str
        What the certificate is about: for a synthesis, the returned K itself
        (rounded to its printed digits, then certified with K fixed), so
        ``h_certified`` is that K's own bound, never the unrounded solver
        gain's.
    reason : str
        Why the status is not ``"certified"`` (solver status, the block that
        failed the re-check and its margin, an uncontrollable mode, ...);
        empty when certified.
    """

    method: str
    N: int | None
    h_certified: float
    h_refuted: float
    status: str
    certificate_kind: str
    K: np.ndarray | None
    A: np.ndarray = field(repr=False)
    Ad: np.ndarray = field(repr=False)
    recheck: dict = field(repr=False)
    recheck_passed: bool
    margin: float
    exact_margin: float
    exact_agreement: str
    windows: tuple
    horizon: float
    at_cap: bool
    certifies: str = ""
    reason: str = ""

    def to_json(self, **kwargs) -> str:
        """The result as a JSON string (:meth:`to_dict`; ``kwargs`` go to
        :func:`json.dumps`, e.g. ``indent=2``)."""
        import json
        return json.dumps(self.to_dict(), **kwargs)

    #: The published fields (all but the matrices A, Ad), :func:`workbench.jsonable.to_json`.
    JSON_FIELDS = {k: k for k in ("method", "N", "h_certified", "h_refuted", "status",
                                  "certificate_kind", "K", "recheck", "recheck_passed",
                                  "margin", "exact_margin", "exact_agreement", "windows",
                                  "horizon", "at_cap", "certifies", "reason")}

    def to_dict(self) -> dict:
        """A JSON-ready dict (``"inf"`` for infinite values)."""
        return jsonable(self)

    def _repr_markdown_(self) -> str:
        from .report.markdown import fmt, margin_text, md_table
        cap = (lambda h: f"≥ {fmt(h, 4)} (cap)" if self.at_cap else fmt(h, 5))
        K = ("—" if self.K is None else "[" + "; ".join(
            ", ".join(fmt(float(k), 4) for k in row) for row in self.K) + "]")
        name = self.method + (f" (N = {self.N})" if self.N is not None else "")
        win = ", ".join(f"({fmt(a, 5)}, {fmt(b, 5)})" for a, b in self.windows) or "none"
        rows = [["method", name], ["status", f"**{self.status}**"],
                ["certified bracket (s)", f"[{cap(self.h_certified)}, {fmt(self.h_refuted, 5)}]"],
                ["certificate", self.certificate_kind + (f" ({self.certifies})"
                                                         if self.certifies else "")],
                ["K", K],
                ["re-check (numpy)", ("passed" if self.recheck_passed else "**failed**")
                 + f", smallest block margin {margin_text(min(self.recheck.values()))}"
                 if self.recheck else "—"],
                ["exact margin h* (s)", fmt(self.exact_margin, 5) + f" ({self.exact_agreement})"],
                [f"exact stability windows up to {fmt(self.horizon)} s", win]]
        if self.reason:
            rows.insert(2, ["reason", self.reason])
        return md_table(["", "value"], rows, "ll")


def _analysis(method, A, Ad, N, margin, rel_tol, h_max):
    """Certified bracket of an analysis criterion (solved in the balanced, canonical
    coordinates of :mod:`workbench.lmi.coordinates`), and the numpy re-check of its
    certificate by a fresh criterion object.

    Bessel-Legendre of order N is decided as the hierarchy 0, 1, ..., N, each
    order's search starting from the previous bound and never reporting less
    (:func:`~workbench.lmi.hierarchy.bessel_legendre_auto`: a certificate of a
    lower order at h is one of order N, SG15 Theorem 4), so the bound is
    monotone in N by construction."""
    from .lmi.analysis import certified_delay, make_criterion
    from .lmi.hierarchy import bessel_legendre_auto
    if method == "bessel-legendre":       # (every criterion balances the loop itself)
        auto = bessel_legendre_auto(A, Ad, math.inf, N_max=N, N_through=N, rel_tol=rel_tol,
                                    margin=margin, h_hi=h_max)
        bound = auto.bounds[-1]
        order = N if bound.certified_by is None else bound.certified_by
    else:
        bound = certified_delay(make_criterion(method, A, Ad, margin=margin),
                                rel_tol=rel_tol, h_hi=h_max)
        order = None
    br = bound.bracket
    if br.certificate is None or br.certificate.certificate is None:
        return br, {}
    crit = make_criterion(method, A, Ad, N=order, margin=margin)
    return br, crit.recheck(br.certificate.certificate, br.certificate.h)


def delay_bound(sys, B=None, *, Ad=None, method: Method = "bessel-legendre", N: int = 3,
                eps: Sequence[float] = (0.1, 0.2, 0.35), h_max: float = 10.0,
                margin: float | None = None, rel_tol: float = 1e-3,
                horizon: float | None = None) -> DelayBoundResult:
    """Certified delay bound of a delayed state-feedback loop (synthesis or analysis).

    Parameters
    ----------
    sys : control.StateSpace or (n, n) array_like
        A continuous-time system (its A, B are used) or the matrix A.
    B : (n, m) array_like, optional
        Input matrix when ``sys`` is an array: a gain K is synthesised for
        x' = A x + B K x(t - h).
    Ad : (n, n) array_like, optional
        Instead of B: analyse x' = A x + A_d x(t - h) (no synthesis).
    method : {"bessel-legendre", "wirtinger", "free-weighting-003", "jensen", "free-weighting", "delay-independent"}
        Synthesis: ``"free-weighting-003"`` (paper 003, problem (60), over
        ``eps``; certificate for every delay in [0, h]), ``"wirtinger"``
        (Seuret & Gouaisbaut 2013 Theorem 5 with Fridman's descriptor slack,
        eps searched; certificate at h) or ``"bessel-legendre"`` (the
        Wirtinger gain, certified by the Bessel-Legendre analysis of order
        ``N``, Seuret & Gouaisbaut 2015). Analysis (``Ad`` given): any but
        ``"free-weighting-003"``.
    N : int
        Bessel-Legendre order (>= 0), used by ``"bessel-legendre"``.
    eps : sequence of float
        Problem (60)'s scalars (``"free-weighting-003"`` only); the row
        with the largest bound is returned.
    h_max : float
        Delay search cap (s).
    margin : float, optional
        Relative LMI definiteness margin (default: the workbench's).
    rel_tol : float
        Relative width of the bracket.
    horizon : float, optional
        Horizon (s) of the exact stability windows (default: max(4 h_max... ) =
        ``max(2 * h_certified, 1)``).

    Returns
    -------
    DelayBoundResult

    Raises
    ------
    ValueError
        Bad shapes, non-finite or complex entries, a discrete-time system, an
        unknown method or option.
    """
    from .lmi.core import DEFAULT_MARGIN
    from .margins import exact_margin, stability_windows
    from .synthesis import check_search_options
    margin = DEFAULT_MARGIN if margin is None else margin
    check_search_options(h_max, margin, rel_tol)
    if isinstance(N, bool) or not isinstance(N, (int, np.integer)) or not 0 <= N <= 8:
        raise ValueError(f"N = {N!r}; expected an integer order in [0, 8]")
    A, B = _system(sys, B)
    n = A.shape[0]
    if (B is None) == (Ad is None):
        raise ValueError("expected exactly one of B (synthesis; or a StateSpace) and Ad "
                         "(analysis)")
    from .lmi.diagnosis import inconclusive_reason
    certifies = ""
    if Ad is not None:
        if method not in _ANALYSIS:
            raise ValueError(f"method = {method!r}; expected one of {', '.join(_ANALYSIS)} "
                             "for an analysis (Ad given)")
        Ad = _matrix(Ad, "Ad", n, n)
        br, recheck = _analysis(method, A, Ad, N, margin, rel_tol, h_max)
        K, kind = None, "at h"
        h_c, h_r, status = br.h_certified, br.h_refuted, br.outcome.value
        reason = inconclusive_reason(br, margin=margin, h_cap=h_max)
    else:
        if method not in _SYNTHESIS:
            raise ValueError(f"method = {method!r}; expected one of {', '.join(_SYNTHESIS)} "
                             "for a synthesis (B given)")
        B = _matrix(B, "B", n, None if np.ndim(B) == 2 else 1)
        K, h_c, h_r, status, recheck, kind, reason = _synthesis(method, A, B, N, eps, margin,
                                                                rel_tol, h_max)
        Ad = np.zeros((n, n)) if K is None else B @ K
        if K is not None:
            certifies = (f"K as returned, rounded to {_digits()} significant digits, "
                         "certified with K fixed")
    passed = bool(recheck) and all(v >= margin for v in recheck.values())
    if status == "certified" and not passed:
        status = "inconclusive"
        bad = min(recheck.items(), key=lambda kv: kv[1]) if recheck else ("—", math.nan)
        reason = (f"block {bad[0]!r} failed the fresh numpy re-check: relative margin "
                  f"{bad[1]:.3g} < {margin:g}")
    if status not in ("certified", "refuted", "infeasible") and not reason:
        reason = "no certified delay in the search range"
    horizon = float(horizon) if horizon is not None else max(2.0 * (h_c if math.isfinite(h_c)
                                                                    else 1.0), 1.0)
    ex = exact_margin(A, Ad)
    win = tuple(stability_windows(A, Ad, horizon))
    return DelayBoundResult(method, N if method == "bessel-legendre" else None, float(h_c),
                            float(h_r), status, kind, K, A, Ad, dict(recheck), passed,
                            float(margin), float(ex.h), ex.outcome.value, win, horizon,
                            bool(h_c >= h_max), certifies, reason)


def _digits() -> int:
    from .lmi.gain import DEFAULT_DIGITS
    return DEFAULT_DIGITS


def _synthesis(method, A, B, N, eps, margin, rel_tol, h_max):
    """(K, h_certified, h_refuted, status, recheck, certificate kind, reason).

    The bracket is always the one of the returned K itself (rounded, then
    certified with K fixed: the same LMI with V = K Y, or the Bessel-Legendre
    analysis of order N), never the synthesis LMI's bracket of the unrounded
    solver gain; ``recheck`` is that certificate's, re-evaluated by a fresh
    criterion object. An uncontrollable mode with Re >= 0 is diagnosed before
    any solve (status ``"infeasible"``)."""
    from .lmi.diagnosis import inconclusive_reason, uncontrollable_mode
    from .lmi.gain import DEFAULT_DIGITS, DEFAULT_FRACTION
    diag = uncontrollable_mode([(A, B)])
    kind = "every delay in [0, h]" if method == "free-weighting-003" else "at h"
    if diag is not None:
        return None, 0.0, math.inf, "infeasible", {}, kind, diag.reason   # nothing solved
    if method == "free-weighting-003":
        from .synthesis import SynthesisSettings, synthesize_delay_bound
        eps = tuple(float(e) for e in eps)
        if not eps or not all(math.isfinite(e) and e > 0 for e in eps):
            raise ValueError(f"eps = {eps!r}; expected positive numbers")
        st = SynthesisSettings(margin=margin, rel_tol=rel_tol, h_max=h_max)
        rows = synthesize_delay_bound(A, B, eps, st)
        r = max(rows, key=lambda r: (r.h_gain or 0.0, r.h_certified))
        K = None if r.K is None else np.array(r.K).reshape(B.shape[1], -1)
        if r.gain is None or r.gain.analysis is None:
            return None, 0.0, r.h_refuted, r.status.value, {}, kind, r.reason
        from .lmi.freeweighting003 import FreeWeighting003FixedK
        an = r.gain.analysis
        recheck = {}
        if an.certificate is not None:   # a fresh criterion object re-checks it
            from .lmi.scaling import balancing
            T = balancing(A)
            Tinv = np.diag(1.0 / np.diag(T))
            crit = FreeWeighting003FixedK(Tinv @ A @ T, Tinv @ B, r.eps, K=K @ T, margin=margin)
            recheck = crit.recheck(an.certificate.certificate, an.certificate.h)
        return (K, an.h_certified, an.h_refuted, an.outcome.value, recheck, kind,
                inconclusive_reason(an, margin=margin, h_cap=h_max))
    from .lmi.tight_synthesis import recheck_gain, synthesize_tight
    t = synthesize_tight(A, B, h_max=h_max, margin=margin, rel_tol=rel_tol,
                         gain_fraction=DEFAULT_FRACTION, gain_digits=DEFAULT_DIGITS)
    if t.K is None:
        return None, 0.0, t.bracket.h_refuted, "inconclusive", {}, kind, t.reason
    if method == "wirtinger":
        an = t.gain.analysis
        return (t.K, an.h_certified, an.h_refuted, an.outcome.value, recheck_gain(A, B, t),
                kind, inconclusive_reason(an, margin=margin, h_cap=h_max))
    br, recheck = _analysis("bessel-legendre", A, B @ t.K, N, margin, rel_tol, h_max)
    return (t.K, br.h_certified, br.h_refuted, br.outcome.value, recheck, kind,
            inconclusive_reason(br, margin=margin, h_cap=h_max))


def simulate_delay(sys, K, *, h: float, x0, t_end: float, dt: float = 1e-3, B=None):
    """Simulate the loop x' = A x + B u(t - h), u = K x, with a constant delay.

    Parameters
    ----------
    sys : control.StateSpace or (n, n) array_like
        The system (or A, with ``B`` given).
    K : (m, n) array_like
        State-feedback gain.
    h : float
        Input delay (s), >= 0 (0: the delay-free reference). The input is
        u = 0 on [-h, 0).
    x0 : (n,) array_like
        Initial state.
    t_end, dt : float
        Horizon and step (s); classical Runge-Kutta 4 with the delayed input
        held over each step (its exact average, :mod:`workbench.sim.history`).
    B : (n, m) array_like, optional
        With an array ``sys``.

    Returns
    -------
    control.TimeResponseData
        States (also the outputs) and the applied input u(t - h). A loop
        that diverges (a state past 1e150 in magnitude) stops there: the
        response ends at that time, its attribute ``diverged`` is
        ``(t, state name)`` (None when it did not diverge), and a
        RuntimeWarning says so; no NaN is returned.

    Raises
    ------
    ValueError
        Bad shapes, non-finite entries, negative h, non-positive dt or t_end,
        more than :data:`MAX_STEPS` steps.
    """
    from dataclasses import replace

    from .sim.delay import simulate_closed_loop
    A, B = _system(sys, B)
    n = A.shape[0]
    if B is None:
        raise ValueError("B is missing; pass a StateSpace or A and B")
    B = _matrix(B, "B", n, None if np.ndim(B) == 2 else 1)
    K = _matrix(K, "K", B.shape[1], n)
    x0 = _matrix(np.reshape(np.asarray(x0, dtype=float), (-1, 1)) if np.size(x0) else x0,
                 "x0", n, 1).ravel()
    for name, v in (("h", h), ("t_end", t_end), ("dt", dt)):
        low = 0 <= v if name == "h" else 0 < v
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (low and v < math.inf):
            sign = "non-negative" if name == "h" else "positive"
            raise ValueError(f"{name} = {v!r:.200}; expected a {sign} finite number (s)")
    if dt > t_end / 10:
        raise ValueError(f"dt = {dt!r}; expected at most t_end / 10 = {t_end / 10:g} s")
    if max(t_end, h) / dt > MAX_STEPS:
        raise ValueError(f"max(t_end, h) / dt = {max(t_end, h) / dt:.3g} steps (t_end = "
                         f"{t_end:g} s, h = {h:g} s, dt = {dt:g} s); expected at most "
                         f"{MAX_STEPS:g}")

    def f(x, u):
        return A @ x + B @ u

    def step(x, ua, t, s):
        x, ua = np.asarray(x, float), np.atleast_1d(ua)
        if not np.all(np.abs(x) <= DIVERGED):
            return tuple(x)     # diverged: held (cut off below), no overflow
        k1 = f(x, ua)
        k2 = f(x + 0.5 * s * k1, ua)
        k3 = f(x + 0.5 * s * k2, ua)
        k4 = f(x + s * k3, ua)
        return tuple(x + s / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4))

    r = simulate_closed_loop(step, lambda t, x, line: (K @ np.asarray(x, float), 0),
                             tuple(x0), h=float(h), dt=float(dt), t_end=float(t_end),
                             u_init=np.zeros(B.shape[1]),
                             done=lambda t, x, phase: not np.all(np.abs(x) <= DIVERGED))
    size = r.t.size
    fix = lambda U: np.asarray(U, float).reshape(size, -1).T
    r = replace(r, u=fix(r.u), u_applied=fix(r.u_applied),
                state_names=tuple(f"x{i + 1}" for i in range(n)),
                input_names=tuple(f"u{i + 1}" for i in range(B.shape[1])))
    out = np.flatnonzero(~np.all(np.abs(r.x) <= DIVERGED, axis=0))
    diverged = None
    if out.size:
        k = int(out[0])
        i = int(np.flatnonzero(~(np.abs(r.x[:, k]) <= DIVERGED))[0])
        diverged = (float(r.t[k]), r.state_names[i])
        warnings.warn(f"the loop diverged: |{diverged[1]}| > {DIVERGED:g} at t = "
                      f"{diverged[0]:.6g} s; the response ends there", RuntimeWarning,
                      stacklevel=2)
        r = replace(r, t=r.t[:k + 1], x=r.x[:, :k + 1], u=r.u[:, :k + 1],
                    u_applied=r.u_applied[:, :k + 1], phase=r.phase[:k + 1])
    resp = r.to_time_response()
    resp.diverged = diverged
    return resp
