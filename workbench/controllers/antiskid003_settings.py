"""Data of paper 003's antiskid controller (75): phases, the braking
creep-speed profile (eqs 76-78) and the controller settings.

Kept apart from :mod:`workbench.controllers.antiskid003` (the controller
itself) so that design readers, the Monte Carlo payloads and the reports use
the data without loading the controller's numerics.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

ACCEL, HANDOVER, CRUISE, BRAKE_IN, BRAKE, STOPPED, DIVERGED = range(7)
PHASE_NAMES = ("acceleration", "handover to cruise", "cruise", "handover to braking",
               "braking", "stopped", "diverged")
#: Why a run was declared diverged (``PhaseEvents.diverged_how``).
DIVERGED_HOW = ("|lambda| at its limit: spin or lock", "step not resolved", "torque out of range")


@dataclass(frozen=True)
class CreepSpeedProfile:
    """Desired creep speed in braking, eqs (76)-(78) (m/s).

    v_s*(t) = max(vs_min, (c0 - c1 (t - t_brake)) lambda_allow sqrt(v^2 + 1))
    while omega > omega_switch, else 0.
    """

    t_brake: float
    c0: float = 0.06
    c1: float = 0.08
    lambda_allow: float = 0.07
    vs_min: float = -0.15
    omega_switch: float = 3.0

    def __call__(self, t, v, vdot, omega, xp):
        """(v_s*, d v_s*/dt) at time t, speed v, acceleration vdot, wheel speed omega."""
        root = xp.sqrt(v * v + 1.0)
        slope = self.c0 - self.c1 * (t - self.t_brake)
        raw = slope * self.lambda_allow * root
        draw = self.lambda_allow * (-self.c1 * root + slope * v * vdot / root)
        on = omega > self.omega_switch
        free = raw > self.vs_min
        vs = xp.where(on, xp.where(free, raw, self.vs_min), 0.0)
        dvs = xp.where(on & free if xp.batch else (on and free), draw, 0.0)
        return vs, dvs


@dataclass(frozen=True)
class ControllerSettings:
    """Data of controller (75).

    Attributes
    ----------
    params : tuple[float, ...]
        Model constants the controller uses (nominal), in :data:`~workbench.sim.wheel_slip.PARAM_ORDER`.
    v_d, lambda_d, lambda_opt : float
        Cruise speed (m/s), cruise creep ratio, peak-adhesion creep ratio.
    K : tuple[float, float]
        Cruise gain of eq (61).
    lin : dict[str, float]
        a1, a2, d1..d6 of the cruise linearisation (eqs 18, 23).
    k_ac, k_de : float
        Gains of eqs (64), (69) (1/s).
    h_model : float
        Delay the predictor compensates (s).
    profile : CreepSpeedProfile
    compensate : bool
        False: the same laws fed the current state (no predictor).
    sampling : {"stiff", "zoh"}
        How a continuous law is held over a sample. "zoh": the printed value.
        "stiff": the creep ratio reacts to a held torque within a fraction of
        a sample at low speed (time constant ~ v/4000 s), so the printed
        value held for dt realises the continuous law's rate only when
        dt |J| << 1; "stiff" holds u with f20 + f2u u = g / phi1(dt J),
        g = f20 + f2u u_printed, which moves the creep ratio of the
        exponential step by dt g (the continuous law's rate) for any dt J.
    predictor : {"rollout", "recursive"}
        How eq (2) is evaluated: "rollout" runs the phase's model from x(t)
        through the inputs of the last h seconds; "recursive" sums the stored
        f(P(s), u(s)) of past predictions (the literal form of eq 2).
        The recursive form's error obeys e(t) = int_{t-h}^t J e(s) ds, a
        neutral-type equation, and is not robust when J (the creep-ratio
        Jacobian) is stiff, i.e. at low speed.
    cruise_entry : {"speed", "creep"}
        "speed" (eq 75 as printed): cruise law from the moment v >= v_d.
        "creep" (workbench variant): at v >= v_d, first eq (64) with target
        lambda_d instead of lambda_opt; the cruise law takes over once
        |lambda - lambda_d| <= ``handover_band``.
    brake_entry : {"time", "creep"}
        "time" (as printed): braking law (69) from t_brake. "creep"
        (variant): eq (64) with target -``handover_band`` until lambda <= 0,
        where the braking form (eq 15) that eq (69) is built on applies.
    v_stop, v_floor : float
        End of run and speed floor in denominators (m/s).
    lam_diverged : float
        |lambda| at which the run is declared diverged and ended (the
        creep ratio of eq 4 lies in (-1, 1); near +-1 the wheel spins or locks).
        A run is also declared diverged when a law commands |u| > ``u_range``
        or a plant step cannot be resolved
        (a sub-step of dt / 2**MAX_HALVINGS still moves lambda by more than
        MAX_DLAMBDA): the applied torque has left any physical range (e.g.
        law (69) evaluated on the traction side, where its e^{b lambda} terms
        blow up) and the state after that step is not a trajectory of the
        model at any step size; no metric uses it.
    u_range : float
        |u| (N m) above which a commanded torque is out of any physical range
        and the run is declared diverged (inf: never); the designs set it to
        a multiple of the peak adhesion torque mu(lambda_opt) m g r.
    observer_tau : float
        Time constant (s) of the estimate of the model mismatch delta =
        lambda'_plant - lambda'_model that ``sampling = "stiff"`` needs (0:
        none). The stiff hold scales the model's rate g by 1/phi1(dt J); the
        plant's rate is g + delta, and scaling only g leaves delta scaled by
        phi1(dt J) = 1 + dt J / 2 + ..., which moves the loop's fixed points
        by O(dt) when the plant differs from the model (the mass +-5 %
        designs: the slow cruise transient, v - v_d at t_brake, converged only
        at first order). With the estimate the hold realises g + delta, whose
        zeros are the continuous loop's. Estimated in traction and cruise
        only; in braking (speed, hence delta, changing on the time scale of
        the estimate) the plain stiff hold is kept.
    """

    params: tuple
    v_d: float
    lambda_d: float
    lambda_opt: float
    K: tuple
    lin: dict
    k_ac: float
    k_de: float
    h_model: float
    profile: CreepSpeedProfile
    compensate: bool = True
    sampling: str = "stiff"
    predictor: str = "rollout"
    cruise_entry: str = "speed"
    brake_entry: str = "time"
    handover_band: float = 0.002
    v_stop: float = 0.05
    v_floor: float = 0.01
    lam_diverged: float = 0.9
    u_range: float = math.inf
    observer_tau: float = 0.2
