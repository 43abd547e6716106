"""Fixed-step simulation of closed loops with input and state delays.

Two entry points:

:func:`simulate_linear_dde`
    x' = A x + A_d x(t - h) (+ B u with a ZOH input), constant initial
    function; Heun's method (explicit trapezoid) with the delayed state read
    from a linear interpolation of the stored grid. Second order when
    h >= dt; used for the step-halving study (:func:`step_halving`) against
    the exact method-of-steps solution of x' = -a x(t - h)
    (:func:`exact_scalar_dde`) and for the linear cross-checks of the LMI
    delay bounds.
:func:`simulate_closed_loop`
    Generic sampled loop: at each step a controller maps (t_n, x_n) to u_n,
    u_n enters a :class:`~workbench.sim.history.DelayLine` and the plant is
    advanced over [t_n, t_n + dt) with the exact average of the delayed ZOH
    input, u(t - h). Plants supply their own one-step map (so a stiff plant
    can use an exponential or implicit step). States may be floats or numpy
    arrays (a batch of runs in one pass).

    Optionally on a refined mesh: the step is dt / 2**k with the level k
    chosen at each step from the state (e.g. from a plant's fastest rate),
    the histories kept per step in a :class:`~workbench.sim.history.TimedDelayLine`.
    Halving dt halves every step of the mesh, so step-halving studies
    still compare a mesh with its refinement.

Results are :class:`SimResult` (time, states, inputs, phase arrays), which
convert to ``control.TimeResponseData``.

References
----------
.. [BZ03] Bellen A., Zennaro M., *Numerical Methods for Delay Differential
   Equations*, Oxford 2003, ch. 3 (method of steps, continuous extensions).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import numpy as np

from .history import DelayLine, TimedDelayLine


@dataclass(frozen=True)
class SimResult:
    """Arrays of one simulated run (recorded every ``record_every`` steps).

    Attributes
    ----------
    t : (K,) numpy.ndarray
        Time (s).
    x : (n, K) numpy.ndarray
        States.
    u : (m, K) numpy.ndarray
        Controller output u(t) (computed at t).
    u_applied : (m, K) numpy.ndarray
        Input acting on the plant, u(t - h) (step average).
    phase : (K,) numpy.ndarray of int
        Controller phase (0 when the loop has a single phase).
    state_names, input_names : tuple[str, ...]
    dt : float
        Integration step (s).
    """

    t: np.ndarray
    x: np.ndarray
    u: np.ndarray
    u_applied: np.ndarray
    phase: np.ndarray
    state_names: tuple[str, ...] = ()
    input_names: tuple[str, ...] = ()
    dt: float = 0.0
    extra: dict = field(default_factory=dict, compare=False)

    def to_time_response(self):
        """The run as ``control.TimeResponseData`` (outputs = states)."""
        import control
        return control.TimeResponseData(
            self.t, self.x, self.x, self.u_applied, issiso=False,
            state_labels=list(self.state_names) or None,
            output_labels=list(self.state_names) or None,
            input_labels=list(self.input_names) or None)


# -- linear delay-differential equations ---------------------------------------------
def simulate_linear_dde(A, Ad, h: float, x0, t_end: float, dt: float, *,
                        record_every: int = 1) -> SimResult:
    """Simulate x' = A x + A_d x(t - h), x(theta) = x0 on [-h, 0].

    The step is shortened to h / N, N = ceil(h / dt), so that delayed values
    fall on the grid; Heun's method then reads

        x_{k+1} = M x_k + P x_{k-N} + Q x_{k-N+1},
        M = I + dt A + dt^2 A^2 / 2,  P = dt A_d / 2 + dt^2 A A_d / 2,  Q = dt A_d / 2,

    second order in dt (checked by :func:`step_halving`).

    Parameters
    ----------
    A, Ad : (n, n) array_like
        Instantaneous and delayed state matrices.
    h : float
        Delay (s), > 0.
    x0 : (n,) array_like
        Constant initial function.
    t_end, dt : float
        Horizon and largest step (s).
    record_every : int
        Keep one step in this many.

    Returns
    -------
    SimResult
        ``u`` and ``u_applied`` are empty (m = 0); ``dt`` is the step used.
    """
    A, Ad = np.atleast_2d(np.asarray(A, float)), np.atleast_2d(np.asarray(Ad, float))
    if not (h > 0 and dt > 0):
        raise ValueError(f"h = {h!r}, dt = {dt!r}; expected positive delay and step (s)")
    N = max(int(math.ceil(h / dt - 1e-9)), 1)
    dt = h / N
    n = A.shape[0]
    I = np.eye(n)
    M = I + dt * A + 0.5 * dt * dt * A @ A
    P = 0.5 * dt * Ad + 0.5 * dt * dt * A @ Ad
    Q = 0.5 * dt * Ad
    n_steps = int(round(t_end / dt))
    X = np.empty((n_steps + N + 1, n))
    X[:N + 1] = np.asarray(x0, float).reshape(-1)   # x_{-N}, ..., x_0
    Mt, Pt, Qt = M.T.copy(), P.T.copy(), Q.T.copy()
    for k in range(N, n_steps + N):
        X[k + 1] = X[k] @ Mt + X[k - N] @ Pt + X[k - N + 1] @ Qt
    X = X[N:]
    idx = np.arange(0, n_steps + 1, record_every)
    return SimResult(idx * dt, X[idx].T, np.zeros((0, idx.size)), np.zeros((0, idx.size)),
                     np.zeros(idx.size, int), dt=dt)


def exact_scalar_dde(a: float, h: float, t) -> np.ndarray:
    """Exact solution of x' = -a x(t - h), x = 1 on [-h, 0] (method of steps).

    On [(n-1) h, n h] the solution is the polynomial
    sum_{k=0}^{n} (-a)^k (t - (k-1) h)^k / k!  [BZ03, ch. 3].
    """
    t = np.atleast_1d(np.asarray(t, float))
    out = np.empty_like(t)
    for i, ti in enumerate(t):
        n = max(int(math.floor(ti / h)) + 1, 1)
        s = 0.0
        for k in range(n + 1):
            s += (-a) ** k * max(ti - (k - 1) * h, 0.0) ** k / math.factorial(k)
        out[i] = s
    return out


@dataclass(frozen=True)
class HalvingRow:
    """One step size of a step-halving study."""

    dt: float
    error: float          # max |x - x_exact| on the horizon
    order: float | None   # log2(error(2 dt) / error(dt))


def step_halving(a: float, h: float, t_end: float, dts: Sequence[float]) -> tuple[HalvingRow, ...]:
    """Max error of :func:`simulate_linear_dde` on x' = -a x(t - h) against
    :func:`exact_scalar_dde`, for each step in ``dts`` (halving), with the
    observed order of convergence."""
    rows, prev = [], None
    for dt in dts:
        r = simulate_linear_dde([[0.0]], [[-a]], h, [1.0], t_end, dt)
        err = float(np.max(np.abs(r.x[0] - exact_scalar_dde(a, h, r.t))))
        order = None if prev is None else math.log2(prev / err)
        rows.append(HalvingRow(dt, err, order))
        prev = err
    return tuple(rows)


def envelope_ratio(r: SimResult, period: float) -> float:
    """max |x| over the last ``period`` seconds / max |x| over the first
    ``period`` seconds after one delay-free period: > 1 grows, < 1 decays."""
    nrm = np.linalg.norm(r.x, axis=0)
    t = r.t
    first = nrm[(t >= period) & (t < 2 * period)]
    last = nrm[t >= t[-1] - period]
    return float(np.max(last) / np.max(first))


# -- generic sampled closed loop ----------------------------------------------------
def simulate_closed_loop(step: Callable, control: Callable, x0, *, h: float, dt: float,
                         t_end: float, u_init, record_every: int = 1,
                         done: Callable | None = None, line=None,
                         level: Callable | None = None, k_max: int = 0) -> SimResult:
    """Sampled closed loop with input delay: x_{n+1} = step(x_n, u(t - h), t_n, dt_n).

    Parameters
    ----------
    step : callable
        ``step(x, u_applied, t, dt) -> x_next`` (x a tuple of floats/arrays).
    control : callable
        ``control(t, x, inputs) -> (u, phase)``; ``inputs`` (the delay
        buffer) holds the past controller outputs (for predictors).
    x0 : tuple
        Initial state.
    h, dt, t_end : float
        Input delay, (base) step, horizon (s).
    u_init : float or numpy.ndarray
        Input on [-h, 0).
    record_every : int
        Keep one sample per this many base steps dt (the first and the last
        sample are always kept).
    done : callable, optional
        ``done(t, x, phase) -> bool`` ends the run early.
    line : DelayLine-like, optional
        Input delay buffer to use instead of ``DelayLine(h, dt, u_init)``
        (e.g. a :class:`~workbench.sim.history.BatchDelayLine`); fixed step only.
    level, k_max : callable, int
        Refined mesh (``k_max > 0``): each step is dt / 2**level(x), level
        in [0, k_max]. Time is then counted in ticks of dt / 2**k_max, so
        step ends are exact; the controller is told each step before it is
        called, ``control.set_step(ticks, tick)``, and the buffer is a
        :class:`~workbench.sim.history.TimedDelayLine`. With ``k_max = 0``
        every step is dt.
    """
    tick = dt / 2 ** k_max
    if line is None:
        line = DelayLine(h, dt, u_init) if k_max == 0 else TimedDelayLine(h / tick, tick, u_init)
    elif k_max:
        raise ValueError("a refined mesh keeps its own TimedDelayLine (line must be None)")
    set_step = getattr(control, "set_step", None) if k_max else None
    T_end = int(round(t_end / tick))
    rec = record_every * 2 ** k_max
    x, T, n_prev = tuple(x0), 0, 1
    Ts, Xs, U, UA, P = [], [], [], [], []
    while True:
        n = 1 if k_max == 0 else min(2 ** (k_max - min(max(int(level(x)), 0), k_max)),
                                     max(T_end - T, 1))
        t = T * tick
        if set_step is not None:
            set_step(n, tick)
        u, phase = control(t, x, line)
        line.push(u, n)
        ua = line.delayed()
        last = T >= T_end or (done is not None and done(t, x, phase))
        if T % rec < n_prev or last:  # the first step end at or after each multiple
            Ts.append(t); Xs.append(x); U.append(u); UA.append(ua); P.append(phase)
        if last:
            break
        x = step(x, ua, t, n * tick)
        T, n_prev = T + n, n
    return SimResult(np.array(Ts), np.array(Xs, float).T, np.atleast_2d(np.array(U, float)),
                     np.atleast_2d(np.array(UA, float)), np.array(P, int), dt=dt)
