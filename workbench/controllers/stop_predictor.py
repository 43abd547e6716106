"""Known-delay compensation for station stopping: a nominal brake model run
inside the controller (a Smith predictor in state form) and a predictive
terminal stopping law built on it.

The brake of paper 000 has known transmission delays (T1 electric, T3 air,
Table 1) followed by lags, and a hand-over from the electric to the slower
air stage at ``v_ho``. A command sent now acts only after the delay, so a
controller that feeds back the *current* state reacts to errors it can no
longer correct; at the stop this gives the systematic overshoot of the
uncompensated laws. :class:`NominalBrakeModel` keeps the controller's copy of
the brake: the commands already sent (in flight), and the brake states they
produce in the nominal model (:func:`workbench.sim.stopping.brake_step`,
i.e. the one sympy model of :mod:`workbench.plants.brake000` with the design's
nominal parameters). From the *measured* position and speed it predicts

* the state one dead time ahead (:meth:`NominalBrakeModel.predict`), which
  only the commands in flight decide: a tracking law fed with this state and
  with the target at the same future time sees no dead time in its loop when
  the model is exact (the Smith-predictor property [Smi57]); and
* where the train would stop if the command sent now were held
  (:meth:`NominalBrakeModel.stop_positions`), for several candidate
  commands at once: :meth:`NominalBrakeModel.stopping_command` picks the
  one predicted to stop at the stopping point (receding horizon: re-solved
  every control period from the new measurement).

The measured deceleration corrects the model's brake gain: ``kappa_hat``
is the low-passed ratio of the measured brake deceleration (measured minus
nominal resistance) to the model's, so a heavier train, a weaker brake or a
gradient shift the prediction instead of biasing the stop.

References
----------
.. [Smi57] Smith O.J.M., "Closer control of loops with dead time", Chemical
   Engineering Progress 53(5), 217-219, 1957.
.. [000] Yu, Zhang, Zhang, Urban Rapid Rail Transit 37(4), 2024, eqs 1-10, Table 1.
"""
from __future__ import annotations

import math

import numpy as np

from ..plants.brake000 import resistance
from ..sim.stopping import brake_step, standstill

#: Longest step (s) of the controller's model; a control period is split into
#: ceil(dt_ctrl / MODEL_STEP) equal steps.
MODEL_STEP = 0.1


class NominalBrakeModel:
    """The controller's nominal brake model over ``n`` runs (vectorised).

    Parameters
    ----------
    params : dict
        Nominal brake parameters (floats, SI; :data:`PARAMETER_UNITS`).
    n : int
        Number of runs.
    dt_ctrl : float
        Control period (s); the delays are rounded to whole periods.
    gain_tau : float or ndarray
        Time constant (s) of the low-pass on ``kappa_hat`` (per run, or one for
        all); 0 freezes it at 1 (no gain correction).
    gain_bounds : (float, float)
        Bounds of ``kappa_hat``.
    """

    def __init__(self, params: dict, n: int, *, dt_ctrl: float, gain_tau=1.0,
                 gain_bounds: tuple[float, float] = (0.5, 1.5)):
        gain_tau = np.broadcast_to(np.asarray(gain_tau, float), (n,))
        if not (dt_ctrl > 0 and np.all(gain_tau >= 0)
                and 0 < gain_bounds[0] <= 1 <= gain_bounds[1]):
            raise ValueError("expected dt_ctrl > 0, gain_tau >= 0, gain bounds around 1")
        self.p = {k: float(v) for k, v in params.items()}
        self.n, self.dt_ctrl = n, float(dt_ctrl)
        self.m1 = max(1, round(self.p["T1"] / dt_ctrl))    # dead times in control periods
        self.m3 = max(1, round(self.p["T3"] / dt_ctrl))
        self.sub = math.ceil(dt_ctrl / MODEL_STEP - 1e-9)
        self.h = dt_ctrl / self.sub
        self.hist = np.zeros((max(self.m1, self.m3) + 1, n))   # commands sent, oldest first
        self.b_e, self.b_a = np.zeros(n), np.zeros(n)
        self.cap = np.full(n, np.inf)
        self.kappa_hat = np.ones(n)
        self.gain_tau, self.gain_bounds = gain_tau, gain_bounds
        self.on_air = np.full(n, self.p["v_ho"] > 0)
        self._v = None

    # -- bookkeeping ------------------------------------------------------------
    def sent(self, c) -> None:
        """Record the command sent at this control instant (after :meth:`update`)."""
        self.hist = np.roll(self.hist, -1, axis=0)
        self.hist[-1] = c

    def update(self, v, a) -> None:
        """Advance the model's brake states over the last control period (the
        commands then reaching each stage are in :attr:`hist`), then correct
        ``kappa_hat`` with the measured acceleration ``a`` (m/s^2) at speed
        ``v`` (m/s)."""
        v = np.asarray(v, float)
        if self._v is not None:
            ce, ca = self.hist[-1 - self.m1], self.hist[-1 - self.m3]
            for _ in range(self.sub):
                _, self.b_e, self.b_a, self.cap = brake_step(
                    self._v, self.b_e, self.b_a, self.cap, ce, ca, 0.0, 1.0, self.p, self.h,
                    self.on_air)
        self._v = v.copy()
        if np.any(self.gain_tau > 0):
            model = self.p["P1"] * self.b_e + self.b_a
            meas = -np.asarray(a, float) - resistance(v, 0.0, self.p)
            ok = (model > 0.2) & (v > 0) & (self.gain_tau > 0)
            ratio = np.clip(meas / np.where(ok, model, 1.0), *self.gain_bounds)
            w = self.dt_ctrl / (self.gain_tau + self.dt_ctrl)
            self.kappa_hat = np.where(ok, self.kappa_hat + w * (ratio - self.kappa_hat),
                                      self.kappa_hat)

    # -- predictions ------------------------------------------------------------
    def _roll(self, x, v, future, periods: int, rows=None):
        """Integrate the model from the measured (x, v) over ``periods``
        control periods; the command sent k periods from now is ``future``
        (shape (K, m)) for k >= 0, the recorded ones before. Returns x, v,
        the standstill position (nan while moving) of shape (K, m)."""
        rows = slice(None) if rows is None else rows
        tile = lambda z: np.broadcast_to(np.asarray(z, float)[rows], future.shape).copy()
        x, v = tile(x), tile(v)
        b_e, b_a, cap = tile(self.b_e), tile(self.b_a), tile(self.cap)
        kap, on_air = tile(self.kappa_hat), np.broadcast_to(self.on_air[rows], future.shape)
        hist = self.hist[:, rows]
        x_stop = np.full(future.shape, np.nan)
        for j in range(periods):
            ce = hist[j - self.m1] if j < self.m1 else future
            ca = hist[j - self.m3] if j < self.m3 else future
            ce, ca = np.broadcast_to(ce, future.shape), np.broadcast_to(ca, future.shape)
            for _ in range(self.sub):
                dv, b_e, b_a, cap = brake_step(v, b_e, b_a, cap, ce, ca, 0.0, kap, self.p,
                                               self.h, on_air)
                v_new = np.maximum(v + self.h * dv, 0.0)
                x_new = x + 0.5 * (v + v_new) * self.h
                hit = np.isnan(x_stop) & (v_new <= 0.0) & (v > 0.0)
                if hit.any():
                    x_stop = np.where(hit, standstill(x, v, dv, x_new, self.h)[0], x_stop)
                x, v = x_new, v_new
            if np.all(~np.isnan(x_stop) | (v <= 0.0)):
                break
        return x, v, np.where(np.isnan(x_stop) & (v <= 0.0), x, x_stop)

    def dead_time(self, v) -> np.ndarray:
        """Dead time (s) of the stage that acts at speed ``v``: T1 above the
        hand-over speed, T3 below."""
        return np.where(np.asarray(v) > self.p["v_ho"], self.m1, self.m3) * self.dt_ctrl

    def predict(self, x, v):
        """Position (m) and speed (m/s) one dead time ahead (:meth:`dead_time`),
        decided by the commands already in flight; and that horizon (s)."""
        hor = self.dead_time(v)
        out_x, out_v = np.empty(self.n), np.empty(self.n)
        for m in np.unique(np.round(hor / self.dt_ctrl).astype(int)):
            sel = np.flatnonzero(np.round(hor / self.dt_ctrl).astype(int) == m)
            xs, vs, _ = self._roll(x, v, np.zeros((1, sel.size)), int(m), rows=sel)
            out_x[sel], out_v[sel] = xs[0], vs[0]
        return out_x, out_v, hor

    def stop_positions(self, x, v, commands, rows, *, t_max: float = 40.0) -> np.ndarray:
        """Predicted standstill position (m) of each run in ``rows`` if the
        command sent now were held, for every candidate (``commands``, shape
        (K, len(rows)), m/s^2); runs still moving at ``t_max`` get +inf."""
        periods = int(round(t_max / self.dt_ctrl))
        _, v_end, xs = self._roll(x, v, np.asarray(commands, float), periods, rows=rows)
        return np.where(v_end > 0, np.inf, xs)

    def stopping_command(self, x, v, stop_at, rows, c_guess, *, c_lo: float, c_hi: float,
                         spread: float = 0.05, t_max: float = 20.0) -> np.ndarray:
        """The held command (m/s^2) predicted to stop the runs ``rows`` at
        ``stop_at`` (m): one secant step from ``c_guess`` (shape (len(rows),),
        e.g. the last command) on the predicted overshoot at c_guess -/+
        ``spread``; the result is clipped to [c_lo, c_hi]. Re-solved every
        control period, the step converges as the stop approaches."""
        c_guess = np.clip(np.asarray(c_guess, float), c_lo + spread, c_hi - spread)
        lo, hi = c_guess - spread, c_guess + spread
        xs = self.stop_positions(x, v, np.stack([lo, hi]), rows, t_max=t_max)
        target = np.asarray(stop_at, float)[rows]
        o_lo, o_hi = xs[0] - target, xs[1] - target          # + = stops beyond
        finite = np.isfinite(o_lo) & np.isfinite(o_hi) & (o_lo > o_hi)
        a, b = np.where(finite, o_lo, 1.0), np.where(finite, o_hi, 0.0)
        root = lo + (hi - lo) * a / (a - b)
        c = np.where(finite, root, np.where(o_hi > 0, hi + 3 * spread, c_guess))
        return np.clip(c, c_lo, c_hi)
