"""Sampled perturbations of an antiskid run (issue 17, item 6): measurement
noise on v and omega, a gradient profile over distance, a time-varying
input delay.

Each is a pure function of (seed, run index, time or position) through the
counter-based generator of :mod:`workbench.sim.counter_rng`, written here
for numpy (a batch of runs, arrays) and, operation for operation, in
:mod:`workbench.sim.wheel_slip_jit` for the compiled kernel:

* noise -- the controller sees v_m = max(v + sigma_v z_v, v_floor) and
  omega_m = omega + sigma_omega z_omega, z of :func:`~workbench.sim.counter_rng.normal4`
  (unit variance), held over ``every`` samples (the noise is a function of
  time on the sweep's step grid, so a run at dt / 2 sees the same noise);
  its creep ratio is that of (v_m, omega_m), eqs (4)-(5) inverted
  (:func:`measured_state`); the plant is unaffected;
* gradient -- a piecewise-constant slope over distance: segment j (positions
  [j L, (j + 1) L)) has the slope g_lo + (g_hi - g_lo) u_j, u_j uniform of
  (seed, run, j) (:func:`grade_at`); the position integrates v;
* delay -- h(t) = h_lo + (h_hi - h_lo) tri(t / P + phi), tri(x) = |2 frac(x) - 1|
  a triangle wave (period P and phase phi per run), clipped to [h_lo, h_hi]
  (:func:`delay_at`); the applied input is the exact ZOH average of
  u(t - h(t_n)) over step n (:func:`split_delays`, as
  :func:`~workbench.sim.history.split_delay`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .counter_rng import normal4, uniform
from .history import BatchDelayLine
from .wheel_slip import ArrayOps, model_functions, wheel_speed


@dataclass(frozen=True)
class Perturbations:
    """The perturbations of a batch of runs (plain data; per-run arrays).

    Attributes
    ----------
    run : tuple[int, ...]
        Global run index of each run of the batch (the generator's counter).
    keys : dict[str, tuple[int, ...]]
        ``uint64`` keys per run of the streams used (``"v"``, ``"omega"``, ``"grade"``).
    noise_v, noise_omega : float
        Standard deviations of the measurement noise (m/s, rad/s); 0 = none.
    noise_every : int
        Samples each noise value is held (noise period / step).
    grade : tuple[float, float] or None
        Slope range (dimensionless, uphill positive) of the gradient profile.
    segment : float
        Length of a gradient segment (m).
    delay : tuple[float, float] or None
        [h_lo, h_hi] of the time-varying delay (s); None: constant per run.
    period, phase : tuple[float, ...]
        Per run: period (s) and phase (fraction of a period) of h(t).
    """

    run: tuple
    keys: dict
    noise_v: float = 0.0
    noise_omega: float = 0.0
    noise_every: int = 1
    grade: tuple | None = None
    segment: float = 1000.0
    delay: tuple | None = None
    period: tuple = ()
    phase: tuple = ()

    @property
    def noisy(self) -> bool:
        return self.noise_v > 0 or self.noise_omega > 0


def measured_state(v, lam, zv, zw, sv, sw, r_plant, r_ctrl, v_floor):
    """(v_m, lambda_m) the controller sees (module docstring), arrays.

    Parameters
    ----------
    v, lam : array
        True speed (m/s) and creep ratio.
    zv, zw : array
        Unit-variance noise values.
    sv, sw : float
        Noise standard deviations (m/s, rad/s).
    r_plant, r_ctrl : float or array
        Wheel radius of the plant (omega) and of the controller's model (m).
    v_floor : float
        Floor of the measured speed (m/s).
    """
    omega = wheel_speed(v, lam, r_plant, ArrayOps)
    vm = np.maximum(v + sv * zv, v_floor)
    vw = np.maximum((omega + sw * zw) * r_ctrl, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        lm = np.where(vw >= vm, 1.0 - vm / vw, vw / vm - 1.0)
    return vm, lm


def noisy_measure(pt: Perturbations, r_plant, r_ctrl, v_floor: float):
    """The ``measure(v, lam) -> (v_m, lambda_m)`` of a batch with the
    measurement noise of ``pt`` (:func:`measured_state`; radii and floor as
    there), called once a sample: sample k sees noise number
    k // noise_every of each run's "v" and "omega" streams."""
    kv, kw = (np.asarray(pt.keys[c], np.uint64) for c in ("v", "omega"))
    count = [0]

    def measure(v, lam):
        k = count[0] // pt.noise_every
        count[0] += 1
        return measured_state(v, lam, normal4(kv, k), normal4(kw, k), pt.noise_v,
                              pt.noise_omega, r_plant, r_ctrl, v_floor)
    return measure


def grade_at(pos, key, lo: float, hi: float, segment: float):
    """Slope at positions ``pos`` (m, arrays) of the runs with gradient keys ``key``."""
    j = np.floor(np.maximum(pos, 0.0) / segment).astype(np.int64)
    return lo + (hi - lo) * uniform(key, j)


class PlantOnPath:
    """The plant's parameters of each step of a batch of runs along their
    path: on a gradient (``pt.grade``), ``p`` with each run's slope at its
    position appended (:func:`grade_at`) and the graded model functions; else
    ``p`` and the level ones. The positions start at 0 and integrate v.

    Parameters
    ----------
    pt : Perturbations or None
    p : tuple
        The plant's parameters (floats or per-run arrays).
    """

    def __init__(self, pt: Perturbations | None, p: tuple):
        self.pt, self.p, self.pos = pt, p, 0.0
        self.graded = pt is not None and pt.grade is not None
        self.fns = model_functions("numpy", graded=True) if self.graded else \
            model_functions("numpy")

    def params(self, v, dt: float) -> tuple:
        """This step's parameters (at the positions before it), then every
        position advances by ``dt`` v."""
        pp = self.p
        if self.graded:
            pt = self.pt
            pp = (*pp, grade_at(self.pos, np.asarray(pt.keys["grade"], np.uint64), *pt.grade,
                                pt.segment))
        self.pos = self.pos + dt * v
        return pp


def delay_at(t: float, lo: float, hi: float, period, phase):
    """h(t) of each run (s): the clipped triangle wave of the module docstring."""
    x = t / period + phase
    tri = np.abs(2.0 * (x - np.floor(x)) - 1.0)
    return np.minimum(np.maximum(lo + (hi - lo) * tri, lo), hi)


def split_delays(h, dt: float):
    """(N, f) of ``h = (N + f) dt`` per run, snapped within 1e-9 of a whole
    step (as :func:`~workbench.sim.history.split_delay`)."""
    q = h / dt
    n = np.floor(q + 0.5)
    snap = np.abs(q - n) < 1e-9
    fl = np.floor(q)
    return np.where(snap, n, fl).astype(np.int64), np.where(snap, 0.0, q - fl)


class VaryingDelayLine:
    """Input delay line of a batch whose delay varies in time
    (:func:`delay_at`): the interface of
    :class:`~workbench.sim.history.BatchDelayLine`, the delay of step n
    taken at t_n = n dt.

    Parameters
    ----------
    lo, hi : float
        Delay range (s).
    period, phase : (B,) array
    dt : float
    initial : float
        Input before t = 0.
    """

    def __init__(self, lo: float, hi: float, period, phase, dt: float, initial: float):
        self.lo, self.hi, self.dt = lo, hi, dt
        self.period, self.phase = np.asarray(period, float), np.asarray(phase, float)
        N_max = int(split_delays(np.array([hi]), dt)[0][0])
        self._L = N_max + 2
        self._buf = np.full((self._L, self.period.size), float(initial))
        self._cols = np.arange(self.period.size)
        self._n = 0

    def push(self, value, ticks=None) -> None:
        self._buf[self._n % self._L] = value
        self._n += 1

    def delayed(self):
        n = self._n - 1
        N, f = split_delays(delay_at(n * self.dt, self.lo, self.hi, self.period, self.phase),
                            self.dt)
        a = self._buf[(n - N) % self._L, self._cols]
        b = self._buf[(n - N - 1) % self._L, self._cols]
        return (1.0 - f) * a + f * b


def batch_delay_line(pt: Perturbations | None, h, batch: int | None, dt: float, initial):
    """The input delay line of a batch of ``batch`` runs: a
    :class:`VaryingDelayLine` on the varying delay of ``pt``, else a
    :class:`~workbench.sim.history.BatchDelayLine` of the per-run delays
    ``h``; None for a single run (``batch`` None: the loop's own line)."""
    if batch is None:
        return None
    if pt is not None and pt.delay is not None:
        return VaryingDelayLine(*pt.delay, pt.period, pt.phase, dt, initial)
    return BatchDelayLine(np.broadcast_to(h, (batch,)), dt, initial)


#: Entries of the kernel's ``pert`` array (:func:`perturbation_arrays`): what a compiled
#: loop reads of :class:`Perturbations`.
PERT = ("noise_v", "noise_omega", "noise_every", "graded", "grade_lo", "grade_hi", "segment",
        "varying", "h_lo", "h_hi")


def perturbation_arrays(pt, B: int):
    """(keys (B, 3) uint64, pert (:data:`PERT`), period (B,), phase (B,)) of
    the :class:`Perturbations` ``pt`` (None: none), as plain arrays a compiled
    loop of B runs takes (the operations on them are those of
    :mod:`workbench.sim.wheel_slip_jit`)."""
    keys = np.zeros((B, 3), np.uint64)
    period, phase = np.ones(B), np.zeros(B)
    if pt is None:
        return keys, np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]), period, phase
    for j, c in enumerate(("v", "omega", "grade")):
        if c in pt.keys:
            keys[:, j] = np.asarray(pt.keys[c], np.uint64)
    g, d = pt.grade or (0.0, 0.0), pt.delay or (0.0, 0.0)
    if pt.delay is not None:
        period, phase = np.asarray(pt.period, float), np.asarray(pt.phase, float)
    pert = np.array([pt.noise_v, pt.noise_omega, float(pt.noise_every),
                     float(pt.grade is not None), g[0], g[1], pt.segment,
                     float(pt.delay is not None), d[0], d[1]])
    return keys, pert, period, phase
