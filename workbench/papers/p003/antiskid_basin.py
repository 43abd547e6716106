"""Basin of attraction of paper 003's cruise law (61) and the phase-switch checks.

The loop: the adhesion plant (eq 12 for lambda >= 0, eq 15 below, as in the
runs) under the cruise law (61), written in the error coordinates
(v_e, lambda_e) = (v - v_d, lambda - lambda_d) of eq (19), *delay-free*:

    u = (-d3 + K E) / (d4 v_e + d5 lambda_e + d6),

i.e. the loop seen under exact prediction (paper 003, Theorems 2-3 argue on
this loop for laws (64) and (69)). Law (61) as printed feeds the *current*
error to the numerator (K E(t)) and the prediction to the denominator, so
the true loop keeps a delayed term B K E(t - h); its local stability is the
LMI certificate's subject (Theorem 1), the basin here is that of the loop
without it. Both are needed for a switch to be safe.

Results:

* :func:`cruise_basin` -- certified level set of V = E' P E, P the modal
  Lyapunov matrix of A + B K (:func:`workbench.roa.modal_P`, weights
  [1, w] on the slow speed mode and the fast creep mode, w from a small grid
  chosen to certify the switch states: P_source "optimised"), the verdict
  for the switch states, sampled delay-free trajectories (figure);
* :func:`switch_in_basin` -- the best verdict over the weight grid for one
  switch state and gain (used by :func:`~.antiskid_basin_k2.safe_k2_range`).

Only the closed loop (law (61) at v_d on the adhesion plant, its domain and
the |lambda| = 0.9 divergence event) and the weight grid are paper 003's and
stay here; the gain loop's derivatives and modal problem
(:mod:`workbench.features.basin_loop`), the switch states' verdicts, the
best verdict over the grid and the sampled starts
(:mod:`workbench.features.basin_points`, on :mod:`~workbench.features.basin_select`
and :mod:`~workbench.features.basin_sweep`), trajectories and fates
(:mod:`workbench.features.basin_trajectory`) and the figure
(:mod:`workbench.features.basin_plot`) are the general basin feature's.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (12),
   (15), (19), (23), (61), (75); Theorems 1-3; Table 3.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
import sympy as sp

from ...controllers.antiskid003_settings import ControllerSettings
from ...errors import ModelError
from ...features.basin_loop import at_gain, derivatives, modal_problem
from ...features.basin_points import PointVerdict, check_points, point_in_basin, sampled_starts
# EAGER_ENV: re-exported, the switch of every staged certificate below (benchmarks, tests)
from ...features.basin_select import EAGER_ENV  # noqa: F401
from ...features.basin_trajectory import Trajectory, integrate, limit_event, trajectory
from ...plants.adhesion import NumericAdhesion, adhesion_model
from ...plants.lambdify_cache import lambdify
from ...roa import estimate_basin
from ...roa.check import BasinCheck
from ...symbolic.linearise import linearise_cruise

#: Weights w of the fast (creep-ratio) mode against the slow (speed) mode
#: tried for P = modal_P(A + B K, [1, w]).
W_GRID = (10.0, 100.0, 1e3, 1e4)
#: Domain of the model the basin may use: lambda in [LAM_LO, LAM_HI], v >= V_MIN.
LAM_LO, LAM_HI, V_MIN = -0.5, 0.5, 1.0
LOOP = ("adhesion plant (eq 12 / eq 15) under the cruise law (61), delay-free: the loop under "
        "exact prediction (paper 003, Theorems 2-3), with the predicted error also in the "
        "numerator; the delayed term B K E(t - h) of law (61) as printed is the subject of the "
        "LMI certificate (Theorem 1), not of this basin")


@dataclass(frozen=True)
class CruiseBasin:
    """Basin of the cruise law for one design (no rendering).

    Attributes
    ----------
    check : BasinCheck
        Estimate and the verdict for each switch state (error coordinates).
    K : tuple
    q : float
        Weight w of the fast mode in P = modal_P(A + B K, [1, w]).
    lambda_d, lambda_opt, v_d : float
    trajectories : tuple of Trajectory
        Sampled trajectories (seeded grid) and one from each switch state.
    """

    check: BasinCheck
    K: tuple
    q: float
    v_d: float
    lambda_d: float
    lambda_opt: float
    trajectories: tuple


@lru_cache(maxsize=8)
def _loop_symbolic(values: tuple, v_d: float):
    """(f, (jacobian, hessians), states, gain symbols, linearisation, lambda_d,
    lambda_opt) of the delay-free cruise loop with the gain (k1, k2) as
    symbols: derived once per plant and cruise speed."""
    vals = dict(values)
    plant = NumericAdhesion.from_dict(vals)
    lam_d = plant.cruise_lambda(v_d)
    lin = linearise_cruise(plant, v_d, lam_d)
    c = lin.coefficients
    mdl = adhesion_model()
    ve, le = sp.symbols("v_e lambda_e", real=True)
    k1, k2 = sp.symbols("k_1 k_2", real=True)
    at = {mdl.v: sp.Float(v_d) + ve, mdl.lam: sp.Float(lam_d) + le}
    sub = lambda e: mdl.substitute(e, vals).subs(at)
    F = lambda x: sp.Float(float(x))
    u = (F(-c["d3"]) + k1 * ve + k2 * le) / (F(c["d4"]) * ve + F(c["d5"]) * le + F(c["d6"]))
    (y1, y2, y3), (z1, z2, z3) = mdl.traction, mdl.braking
    trac = sp.Float(lam_d) + le >= 0
    f = [sp.Piecewise((sub(y1), trac), (sub(z1), True)),
         sp.Piecewise((sub(y2) + sub(y3) * u, trac), (sub(z2) + sub(z3) * u, True))]
    states = (ve, le)
    return f, derivatives(f, states), states, (k1, k2), lin, lam_d, plant.lambda_opt()


@lru_cache(maxsize=8)
def _loop(values: tuple, v_d: float, K: tuple):
    """(f, derivatives, states, A_cl, lambda_d, lambda_opt) at the gain K
    (once per gain: the weights of the grid and the fate share it)."""
    f, derivs, states, ks, lin, lam_d, lam_opt = _loop_symbolic(values, v_d)
    f, derivs = at_gain(f, derivs, ks, K)
    A_cl = lin.A + lin.B @ np.array([K], float)
    return f, derivs, states, A_cl, lam_d, lam_opt


def _domain(v_d: float, lam_d: float):
    return ((V_MIN - v_d, LAM_LO - lam_d), (v_d, LAM_HI - lam_d))


def _cruise_problem(values, v_d, K, points, w, c_search=None):
    """(problem, level searched) of :func:`estimate_cruise`."""
    f, derivs, states, A_cl, lam_d, _ = _loop(values, v_d, tuple(K))
    return modal_problem(f, states, (0.0, 0.0), A_cl, [1.0, w], derivs=derivs,
                         names=("v - v_d (m/s)", "lambda - lambda_d"), points=points,
                         domain=_domain(v_d, lam_d), c_search=c_search)


def estimate_cruise(values, v_d, K, points, w, *, seed=0, c_search=None):
    """Basin estimate with P = modal_P(A + B K, [1, w]) (slow mode weight 1,
    fast mode w); c_search: 4 x the largest level of ``points`` (capped by
    the model's domain) unless given."""
    prob, c = _cruise_problem(values, v_d, K, points, w, c_search)
    return prob, estimate_basin(prob, c, seed=seed)


def cruise_basin(values: dict, v_d: float, K, switch_points, *, seed: int = 0,
                 n_traj: int = 24, t_traj: float = 3.0) -> CruiseBasin:
    """Certified basin of law (61) and the verdict for each switch state
    (:func:`workbench.features.basin_points.check_points` over :data:`W_GRID`).

    Parameters
    ----------
    values : dict
        Plant constants (SI, keys of PARAMETER_UNITS), the nominal model the
        controller is built on.
    v_d : float
        Cruise speed (m/s).
    K : (k1, k2)
        Cruise gain.
    switch_points : sequence of (label, (v, lambda))
        States (absolute coordinates) where law (61) takes over.
    seed : int
        Seed of the falsifier and of the sampled trajectories.
    n_traj : int
        Sampled trajectories for the figure.
    t_traj : float
        Their horizon (s).
    """
    vals = tuple(sorted((k, float(v)) for k, v in values.items()))
    lam_d, lam_opt = _loop_symbolic(vals, v_d)[5:7]
    pts = [(lab, (float(v) - v_d, float(l) - lam_d)) for lab, (v, l) in switch_points]
    best = check_points(W_GRID, lambda q, xs: _cruise_problem(vals, v_d, K, xs, q), pts,
                        loop=LOOP, seed=seed)
    if best is None:
        raise ModelError(f"cruise loop with K = {tuple(K)} has no Hurwitz linearisation")
    q, prob, check = best
    est = check.estimate
    # the sampled starts: a box around the switch states (2 x |v_e| + 1 m/s,
    # 1.5 x |lambda_e| + 0.02)
    starts = sampled_starts([x for _, x in pts], n_traj, seed=seed, scale=(2, 1.5),
                            pad=(1.0, 0.02), default=(2, 0.1))
    fm = lambdify(prob.states, list(prob.f), "math")
    inside = lambda p: prob.V(p) <= est.c_certified
    trajs = tuple(_trajectory(fm, x0, lam_d, t_traj, inside) for x0 in starts)
    return CruiseBasin(check, tuple(float(k) for k in K), q, v_d, lam_d, lam_opt, trajs)


#: |lambda| at which a delay-free trajectory has diverged (the runs' own test).
LAM_DIVERGED = ControllerSettings.lam_diverged


def _spin(lam_d: float):
    """Terminal event: |lambda| reaches LAM_DIVERGED (the wheel spins or locks)."""
    return limit_event(1, LAM_DIVERGED, lam_d)


def _delay_free(fn, x0, lam_d: float, T: float):
    """The delay-free loop x' = fn(x) from x0 over [0, T]
    (:func:`workbench.features.basin_trajectory.integrate`, max step 0.05 s),
    stopped when |lambda| reaches 0.9."""
    return integrate(fn, x0, T, events=[_spin(lam_d)], max_step=0.05, dense=True)


#: Time step (s) of a trajectory's drawn path: the dense output on this fixed
#: grid (:func:`workbench.features.basin_trajectory.drawn_path`), for every
#: fate (issue 36 item 5: a failing trajectory's accepted steps bunch up where
#: it diverges and move by ~1e-7 s under a 3-ulp change of the start).
PATH_DT = 0.01


def _trajectory(fn, x0, lam_d: float, T: float, inside_at) -> Trajectory:
    """One delay-free trajectory from x0 (:func:`_delay_free`) and its fate:
    "converges" (a solver step satisfies ``inside_at``), "diverges" (lambda
    leaves (-0.9, 0.9) or the step fails), else "undecided" within T."""
    return trajectory(fn, x0, T, inside_at, events=[_spin(lam_d)], escape="diverges",
                      max_step=0.05, path_dt=PATH_DT)


def switch_in_basin(values: dict, v_d: float, K, point, *, seed: int = 0,
                    t_sim: float = 10.0) -> PointVerdict:
    """Is the switch state ``point`` (absolute (v, lambda)) inside a certified
    basin of law (61) with gain K? Best verdict over :data:`W_GRID` (w: the
    deciding weight), and the fate of the delay-free trajectory from it
    ("diverges": lambda reaches 0.9, the wheel spins; "undecided": neither
    that nor a certified level set within 10 s)
    (:func:`workbench.features.basin_points.point_in_basin`)."""
    vals = tuple(sorted((k, float(v)) for k, v in values.items()))
    f, _, states, _, lam_d, _ = _loop(vals, v_d, tuple(K))
    x = (float(point[0]) - v_d, float(point[1]) - lam_d)
    return point_in_basin(W_GRID, lambda w, xs: _cruise_problem(vals, v_d, K, xs, w), x,
                          lambdify(states, f, "math"), t_sim, events=[_spin(lam_d)],
                          max_step=0.05, seed=seed)


def cruise_lambda_d(values: tuple, v_d: float) -> float:
    """lambda_d of the cruise loop (``values`` as sorted (name, value) pairs)."""
    return _loop_symbolic(values, v_d)[5]
