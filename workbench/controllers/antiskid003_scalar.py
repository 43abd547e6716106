"""The single-run (float) paths of :class:`~workbench.controllers.antiskid003.Antiskid003`.

A case run of the antiskid-run study calls the controller once a step and
its predictor's model once per piece of the delay window (about 25 us a step
through the generic code, issue 36 item 4). The generic methods serve a batch
(numpy arrays) and a single run (floats) alike, with ``xp.where`` for every
event; the methods here are their float branches written out: the same
decisions and the same float operations in the same order (bit for bit:
``tests/test_antiskid_run.py`` runs the same scenarios through both), each
done only where its result is kept, with the phase's model chosen once per
sample instead of once per piece.
"""
from __future__ import annotations

import math

from ..sim.wheel_slip import MAX_DLAMBDA, MAX_HALVINGS
from .antiskid003_settings import (ACCEL, BRAKE, BRAKE_IN, CRUISE, DIVERGED, HANDOVER,
                                   STOPPED)

__all__ = ["ScalarSample"]


class ScalarSample:
    """Mixin of :class:`~workbench.controllers.antiskid003.Antiskid003`: the
    float paths of ``__call__``, ``_observe`` and ``_rollout``."""

    def _call_scalar(self, t, x):
        """:meth:`__call__` of a single run: the same decisions and float
        operations in the same order, written out for floats (no
        ``xp.where`` per event)."""
        s = self.s
        v_true, lam_true = x
        v, lam = x if self.measure is None else self.measure(v_true, lam_true)
        ph = self.phase
        to_cruise = ph == ACCEL and v >= s.v_d
        if to_cruise:
            ph = HANDOVER if s.cruise_entry == "creep" else CRUISE
        handed = ph == HANDOVER and abs(lam - s.lambda_d) <= s.handover_band
        if handed:
            ph = CRUISE
        to_brake = ph < BRAKE_IN and t >= s.profile.t_brake
        if to_brake:
            ph = BRAKE_IN if s.brake_entry == "creep" else BRAKE
        if ph == BRAKE_IN and lam <= 0:
            ph = BRAKE
        to_stop = ph in (BRAKE_IN, BRAKE) and v <= s.v_stop
        if to_stop:
            ph = STOPPED
        unres = self.unresolved
        bad = (not abs(lam_true) < s.lam_diverged or unres) and ph < STOPPED
        ev = self.events
        if bad:
            ev.t_diverged, ev.phase_diverged = t, ph
            ev.diverged_how = 1.0 if unres else 0.0
        if handed:
            ev.t_handover_done, ev.v_at_handover, ev.lam_at_handover = t, v, lam
        if bad:
            ph = DIVERGED
        self.phase = ph
        try:
            self._observe(v, lam, ph)
            u, fv, fl = self._laws(t, v, lam, ph)
        except (OverflowError, ZeroDivisionError, ValueError):
            # a model evaluation overflowed (e.g. a predicted creep ratio far
            # outside (-1, 1)): the run has diverged
            ev.t_diverged, ev.phase_diverged = t, ph
            self.phase = ph = DIVERGED
            u = fv = fl = 0.0
        if not abs(u) <= s.u_range and ph < STOPPED:
            # the law has left any physical range: the run has diverged
            ev.t_diverged, ev.phase_diverged, ev.diverged_how = t, ph, 2.0
            self.phase = ph = DIVERGED
            u = fv = fl = 0.0
        if s.compensate and s.predictor != "rollout":   # only eq (2) literal reads them
            self.fv.push(fv, self._ticks)
            self.fl.push(fl, self._ticks)
        self.uline.push(u, self._ticks)
        if self.recorder is not None:
            self.recorder(t, v_true, lam_true, ph, to_cruise, to_brake, to_stop, self._dt_prev)
        self._dt_prev = self.dt
        return u, ph

    def _observe_scalar(self, v, lam, ph):
        """:meth:`_observe` of a single run: the same operations on floats, in
        the same order, each done only where its result is kept."""
        s = self.s
        if ph >= BRAKE_IN:
            self.delta = 0.0 * v
        elif self._prev is not None and s.sampling == "stiff" and s.observer_tau > 0:
            dt = self._dt_prev
            pv, pl, pph = self._prev
            ua = self.uline.delayed()
            if pph == CRUISE:      # the cruise law's model is eq (62)
                c, ve, le = s.lin, pv - s.v_d, pl - s.lambda_d
                den = c["d4"] * ve + c["d5"] * le + c["d6"]
                f20, f2u, j0, ju = c["d1"] * ve + c["d2"] * le + c["d3"], den, c["d2"], c["d5"]
            else:
                _, f20, f2u, j0, ju = self.fns["traction" if pl >= 0 else "braking"](
                    max(pv, s.v_floor), pl, *s.params)
            z = (j0 + ju * ua) * dt
            d = (lam - pl) / (dt * (math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z)) - (
                f20 + f2u * ua)
            new = self.delta + -math.expm1(-dt / s.observer_tau) * (d - self.delta)
            # not in braking (see observer_tau); a non-finite estimate is dropped
            self.delta = 0.0 * v if not abs(new) < 1e6 or ph >= BRAKE_IN else new
        self._prev = (v, lam, ph)

    def _rollout_scalar(self, v, lam, ph, pieces):
        """:meth:`_rollout` of a single run: :meth:`_model_step`'s scalar
        operations in the same order, the phase's model chosen once per
        sample instead of once per piece."""
        s = self.s
        if ph != CRUISE:
            fn = self.fns["braking" if ph == BRAKE else "traction"]
            v_floor, p = s.v_floor, s.params
            for u, d in pieces:
                f1, f20, f2u, j0, ju = fn(max(v, v_floor), lam, *p)
                z = (j0 + ju * u) * d
                nv = v + d * f1
                nl = lam + d * (math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z) * (
                    f20 + f2u * u)
                if not abs(nl - lam) <= MAX_DLAMBDA:     # depth 0 < MAX_HALVINGS: halve
                    hv, hl = _scalar_stiff_step(v, lam, u, d / 2, fn, v_floor, p, 1)
                    nv, nl = _scalar_stiff_step(hv, hl, u, d / 2, fn, v_floor, p, 1)
                v, lam = nv, nl
            return v, lam
        c, v_d, lam_d = s.lin, s.v_d, s.lambda_d
        a1, a2, d1, d2, d3 = c["a1"], c["a2"], c["d1"], c["d2"], c["d3"]
        d4, d5, d6 = c["d4"], c["d5"], c["d6"]
        for u, dt in pieces:
            ve, le = v - v_d, lam - lam_d
            den = d4 * ve + d5 * le + d6
            f2 = d1 * ve + d2 * le + d3 + den * u
            z = (d2 + d5 * u) * dt
            v, lam = v + dt * (a1 * ve + a2 * le), lam + dt * (
                math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z) * f2
        return v, lam


def _scalar_stiff_step(v, lam, u, dt, fn, v_floor, p, depth):
    """:func:`~workbench.sim.wheel_slip.stiff_step` of a single run with the
    model ``fn`` (speed floored at ``v_floor``): the same operations in the
    same order (bit for bit), written out for floats (the predictor's
    rollout calls it every piece of every sample)."""
    f1, f20, f2u, j0, ju = fn(max(v, v_floor), lam, *p)
    z = (j0 + ju * u) * dt
    nv = v + dt * f1
    nl = lam + dt * (math.expm1(z) / z if abs(z) > 1e-8 else 1.0 + 0.5 * z) * (f20 + f2u * u)
    if depth < MAX_HALVINGS and not abs(nl - lam) <= MAX_DLAMBDA:
        hv, hl = _scalar_stiff_step(v, lam, u, dt / 2, fn, v_floor, p, depth + 1)
        return _scalar_stiff_step(hv, hl, u, dt / 2, fn, v_floor, p, depth + 1)
    return nv, nl
