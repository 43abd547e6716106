"""Named modules a ``stop-accuracy`` design may reference: the parts of a
stopping controller that are not expressions (issue 35, item 2).

A law of the kind is an expression of the measured state (parsed, never
evaluated, unit-checked). Five things are not, and are named here (the
fifth, paper 004's command generator ``deceleration_loop``, in
:mod:`.decel_loop`):

``pid``          (``[[controllers]] pid = {...}``, :mod:`.run`): an integrator
                 is internal state that an expression of the present cannot hold.
``smarc``        (``[[controllers]] smarc = {...}``): paper 000's adaptive
                 sliding-mode law, eqs 22 and 26-27
                 (:class:`workbench.controllers.smarc.AdaptiveSlidingModeController`):
                 its mass estimate theta_hat is integrated from the sliding
                 variable, with a projection onto [theta_min, theta_max], so the
                 command depends on the whole past. (The plain SMC, eq 22 with
                 theta fixed, is stateless: a design writes it as an expression.)
``predictor``    (``compensation = { predictor = true }``): the Smith predictor
                 in state form — the controller runs the nominal brake model
                 (:class:`workbench.controllers.stop_predictor.NominalBrakeModel`)
                 on the commands it has sent, and the law sees the state one
                 dead time ahead (and the reference at that time). The model
                 holds the commands in flight and the brake stages' states;
                 with ``gain_correction`` it also low-passes the measured
                 over the modelled deceleration.
``terminal``     (``compensation = { terminal = true }``): from
                 ``[compensation] d_terminal`` metres to go, the command the
                 model predicts stops at D, re-solved every control period by a
                 secant step from the last one (a search over the model's future,
                 and a latch: once in, a run stays in).

``[reference]`` (optional) names the target a tracking law follows:
``model = "ato-trapezoid"`` (:class:`workbench.sim.stopping.TargetCurve`: accelerate
at a_acc, cruise at v_max, brake at a_dec to stop exactly at D); each run
starts where the target starts braking, ``x`` counts from the section's start
(D = the section length) and laws see the target's ``x_d`` (m), ``v_d`` (m/s)
and ``a_d`` (m/s^2, negative while braking) at the (predicted) time.

References
----------
Paper 000 (Yu, Zhang, Zhang 2024), eqs 13-27; O. J. M. Smith, "Closer control
of loops with dead time", Chem. Eng. Prog. 53(5):217-219, 1957.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Compensation", "Reference", "SmarcGains", "Tracking", "named_constants",
           "read_compensation", "read_reference", "read_smarc", "REFERENCE_NAMES", "SMARC_UNITS"]

#: Law names a [reference] adds: name -> unit.
REFERENCE_NAMES = {"x_d": "m", "v_d": "m/s", "a_d": "m/s^2"}
#: ``smarc`` gain -> unit of the constant it names (eq 22: z = c e + e' in m/s;
#: eq 26: theta' = -lam z (x_d'' - c e'), theta dimensionless).
SMARC_UNITS = {"c": "1/s", "k_s": "1/s", "eta": "m/s^2", "phi": "m/s", "lam": "s^2/m^2",
               "theta_min": "1", "theta_max": "1"}


@dataclass(frozen=True)
class Reference:
    """``[reference]``: the ATO target curve (m/s, m/s^2)."""

    v_max: float
    a_acc: float
    a_dec: float

    def curve(self, lengths):
        from ...sim.stopping import TargetCurve
        return TargetCurve.build(lengths, v_max=self.v_max, a_acc=self.a_acc, a_dec=self.a_dec)

    def start(self, D: float):
        """(x0 m, v0 m/s) where the target of a section of length D starts braking."""
        tc = self.curve(np.array([D]))
        x0, v0, _ = tc.at(tc.t_brake)
        return float(x0[0]), float(v0[0])

    def braking(self, D: float, t):
        """(x_d - D, v_d) of the target of a section of length D at the times
        ``t`` (s) from its braking start, and its planned braking time (s)."""
        one = self.curve(np.array([D]))
        tb = one.t_brake[0]
        xd, vd, _ = one.at(t + tb)
        return xd - D, vd, float(one.t_final[0] - tb)


@dataclass(frozen=True)
class Compensation:
    """``[compensation]``: the known-delay compensation of the modules
    ``predictor`` and ``terminal``.

    Attributes
    ----------
    d_terminal : float
        Distance to go (m) at which the predictive terminal stopping law takes over.
    gain_tau : float
        Time constant (s) of the model's brake-gain correction (0: none).
    gain_bounds : (float, float)
        Bounds of that correction.
    """

    d_terminal: float
    gain_tau: float
    gain_bounds: tuple[float, float]


@dataclass(frozen=True)
class SmarcGains:
    """The constants' names of a controller's ``smarc`` table (:data:`SMARC_UNITS`)."""

    names: dict

    def values(self, constants) -> dict:
        return {k: constants[v].value for k, v in self.names.items()}


def read_reference(root):
    """``[reference]`` (a :class:`Reference`) or None."""
    if not root.has("reference"):
        return None
    t = root.table("reference")
    t.string("model", choices=("ato-trapezoid",))
    ref = Reference(t.quantity("v_max", "m/s", positive=True, hi=100.0).value,
                    t.quantity("a_acc", "m/s^2", positive=True, hi=3.0).value,
                    t.quantity("a_dec", "m/s^2", positive=True, hi=3.0).value)
    t.finish()
    return ref


def read_compensation(root):
    """``[compensation]`` (a :class:`Compensation`) or None."""
    if not root.has("compensation"):
        return None
    cp = root.table("compensation")
    b = cp.numbers("gain_bounds", positive=True, what="bounds [lo, hi] (-)")
    if len(b) != 2 or not b[0] <= 1.0 <= b[1]:
        raise cp.fail("gain_bounds", list(b), "two bounds [lo, hi] with lo <= 1 <= hi")
    out = Compensation(cp.quantity("d_terminal", "m", positive=True, hi=500.0).value,
                       cp.quantity("gain_tau", "s", nonneg=True, hi=60.0).value, (b[0], b[1]))
    cp.finish()
    return out


def named_constants(st, constants, units: dict) -> dict:
    """key -> constant name of a module's table ``st``: every key of ``units``
    names a constant of ``[constants]`` in that unit (pint, scale included)."""
    from ..delay_feedback.units import parse_unit
    if not constants:
        raise st.fail(next(iter(units)), st.raw(next(iter(units)), None),
                      "a constant of [constants] (none)")
    names = {k: st.string(k, choices=sorted(constants)) for k in units}
    for k, name in names.items():
        q = constants[name]
        a, b = parse_unit(q.unit, "", "").to_base_units(), parse_unit(units[k], "", "")
        if not (a.dimensionality == b.dimensionality and a.magnitude == b.to_base_units().magnitude):
            raise st.fail(k, name, f"a constant in {units[k]} (it is in {q.unit})")
    return names


def read_smarc(t, constants) -> SmarcGains:
    """A controller's ``smarc = { c = "const", ... }``: every gain of
    :data:`SMARC_UNITS` names a constant of that unit."""
    st = t.table("smarc")
    names = named_constants(st, constants, SMARC_UNITS)
    st.finish()
    v = SmarcGains(names).values(constants)
    if not (v["c"] > 0 and v["k_s"] > 0 and v["eta"] >= 0 and v["phi"] >= 0 and v["lam"] > 0
            and 0 < v["theta_min"] < 1.0 < v["theta_max"]):
        raise st.fail("c", names["c"], "constants with c, k_s, lam > 0, eta, phi >= 0 and "
                      "0 < theta_min < 1 < theta_max")
    return SmarcGains(names)


class Tracking:
    """The runtime of the modules over a batch: the reference of every run,
    the nominal brake model of the runs with a predictor or a terminal
    phase, and one SMARC per controller that has one.

    Parameters
    ----------
    spec : StopAccuracySpec
    groups : list of (controller, run indices)
    D : ndarray
        Stopping point of every run (m).
    """

    def __init__(self, spec, groups, D):
        from ...controllers.smarc import AdaptiveSlidingModeController
        from ...controllers.smc import SlidingGains
        from ...controllers.stop_predictor import NominalBrakeModel
        n = D.size
        self.spec, self.D = spec, D
        self.tc = spec.reference.curve(D) if spec.reference else None
        self.tb = self.tc.t_brake if self.tc is not None else None
        self.smarc = {}
        pred, term, tau = np.zeros(n, bool), np.zeros(n, bool), np.zeros(n)
        for c, idx in groups:
            if c.smarc is not None:
                g = c.smarc.values(spec.constants)
                gains = SlidingGains(g["c"], g["k_s"], g["eta"], g["phi"])
                self.smarc[c.name] = AdaptiveSlidingModeController(
                    gains, dt=spec.dt_ctrl, theta0=np.ones(idx.size), lam=g["lam"],
                    theta_min=g["theta_min"], theta_max=g["theta_max"])
            pred[idx], term[idx] = c.predictor, c.terminal
            if c.gain_correction and (c.predictor or c.terminal):
                tau[idx] = spec.compensation.gain_tau
        self.M = np.flatnonzero(pred | term)
        self.pm, self.tm = np.flatnonzero(pred[self.M]), term[self.M]
        if self.M.size:
            comp = spec.compensation
            self.model = NominalBrakeModel(spec.base(), self.M.size, dt_ctrl=spec.dt_ctrl,
                                           gain_tau=tau[self.M], gain_bounds=comp.gain_bounds)
            self.in_term = np.zeros(self.M.size, bool)
            self.last = np.zeros(self.M.size)

    def state(self, t, o):
        """(x, v, reference dict) the laws see: the measured or predicted state
        and the reference at t (or one dead time later where predicted)."""
        x, v, h = o.x.copy(), o.v.copy(), np.zeros(self.D.size)
        M, pm = self.M, self.pm
        if M.size:
            self.model.update(o.v[M], o.a[M])
            if pm.size:
                mx, mv, mh = self.model.predict(o.x[M], o.v[M])
                x[M[pm]], v[M[pm]], h[M[pm]] = mx[pm], mv[pm], mh[pm]
        if self.tc is None:
            return x, v, {}
        xd, vd, ad = self.tc.at(t + self.tb + h)
        return x, v, {"x_d": xd, "v_d": vd, "a_d": ad}

    def smarc_command(self, name, idx, x, v, ref):
        """Brake command (m/s^2) of controller ``name``'s SMARC on its runs."""
        e, de = x[idx] - ref["x_d"][idx], v[idx] - ref["v_d"][idx]
        return -self.smarc[name].step(e, de, ref["a_d"][idx])

    def finish(self, c, o):
        """The terminal phase on the clipped commands ``c``; the commands sent
        recorded in the model."""
        M = self.M
        if not M.size:
            return c
        spec = self.spec
        self.in_term |= self.tm & (self.D[M] - o.x[M] < spec.compensation.d_terminal)
        rows = np.flatnonzero(self.in_term & ~o.stopped[M])
        if rows.size:
            guess = np.where(self.last[rows] > 0, self.last[rows], c[M[rows]])
            c[M[rows]] = self.model.stopping_command(o.x[M], o.v[M], self.D[M], rows, guess,
                                                     c_lo=0.0, c_hi=spec.c_max)
        c = np.where(o.stopped, 0.0, c)
        self.last = np.where(self.in_term, c[M], 0.0)
        self.model.sent(c[M])
        return c
