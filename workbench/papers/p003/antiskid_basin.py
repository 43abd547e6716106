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
stay here: a :class:`workbench.features.basin_loop.GainLoop`, whose general
methods give the modal problems, the switch states' verdicts, the best verdict
over the grid, the sampled starts and the trajectories' fates; the figure is
:mod:`workbench.features.basin_plot`'s.

References
----------
.. [003] Cai L., Yue Y., Huang D., "Antiskid control of high-speed trains
   with input delay", Control Theory & Applications 43(3), 2026: eqs (12),
   (15), (19), (23), (61), (75); Theorems 1-3; Table 3.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import sympy as sp

from ...controllers.antiskid003_settings import ControllerSettings
from ...errors import ModelError
from ...features.basin_loop import GainLoop
from ...features.basin_points import PointVerdict
from ...features.basin_trajectory import integrate, limit_event
from ...plants.adhesion import NumericAdhesion, adhesion_model
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


#: |lambda| at which a delay-free trajectory has diverged (the runs' own test).
LAM_DIVERGED = ControllerSettings.lam_diverged
#: Time step (s) of a trajectory's drawn path: the dense output on this fixed
#: grid (:func:`workbench.features.basin_trajectory.drawn_path`), for every
#: fate (issue 36 item 5: a failing trajectory's accepted steps bunch up where
#: it diverges and move by ~1e-7 s under a 3-ulp change of the start).
PATH_DT = 0.01


@lru_cache(maxsize=8)
def cruise_loop(values: tuple, v_d: float) -> tuple:
    """(GainLoop, lambda_d, lambda_opt) of the delay-free cruise loop in the
    error coordinates, the gain (k1, k2) as symbols (``values``: the plant's
    constants as sorted (name, value) pairs); derived once per plant and
    cruise speed. Its escape: |lambda| reaches :data:`LAM_DIVERGED` (the wheel
    spins or locks), integrated with steps of at most 0.05 s."""
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
    loop = GainLoop(f, (ve, le), (k1, k2), lin.A, lin.B, (0.0, 0.0),
                    ("v - v_d (m/s)", "lambda - lambda_d"),
                    ((V_MIN - v_d, LAM_LO - lam_d), (v_d, LAM_HI - lam_d)), W_GRID,
                    lambda w: [1.0, w], (limit_event(1, LAM_DIVERGED, lam_d),), max_step=0.05,
                    loop=LOOP)
    return loop, lam_d, plant.lambda_opt()


def _values(values: dict) -> tuple:
    return tuple(sorted((k, float(v)) for k, v in values.items()))


def cruise_basin(values: dict, v_d: float, K, switch_points, *, seed: int = 0,
                 n_traj: int = 24, t_traj: float = 3.0) -> CruiseBasin:
    """Certified basin of law (61) and the verdict for each switch state
    (:meth:`workbench.features.basin_loop.GainLoop.basin` over :data:`W_GRID`).

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
    loop, lam_d, lam_opt = cruise_loop(_values(values), v_d)
    pts = [(lab, (float(v) - v_d, float(l) - lam_d)) for lab, (v, l) in switch_points]
    # the sampled starts: a box around the switch states (2 x |v_e| + 1 m/s,
    # 1.5 x |lambda_e| + 0.02)
    best = loop.basin(tuple(K), pts, n_traj=n_traj, T=t_traj, scale=(2, 1.5), pad=(1.0, 0.02),
                      default=(2, 0.1), seed=seed, path_dt=PATH_DT)
    if best is None:
        raise ModelError(f"cruise loop with K = {tuple(K)} has no Hurwitz linearisation")
    q, check, trajs = best
    return CruiseBasin(check, tuple(float(k) for k in K), q, v_d, lam_d, lam_opt, trajs)


def delay_free(fn, x0, lam_d: float, T: float):
    """The delay-free loop x' = fn(x) from x0 over [0, T] (max step 0.05 s,
    dense output), stopped when |lambda| reaches 0.9 (the solver's own steps:
    tests/test_basin_perturb.py)."""
    return integrate(fn, x0, T, events=[limit_event(1, LAM_DIVERGED, lam_d)], max_step=0.05,
                     dense=True)


def switch_in_basin(values: dict, v_d: float, K, point, *, seed: int = 0,
                    t_sim: float = 10.0) -> PointVerdict:
    """Is the switch state ``point`` (absolute (v, lambda)) inside a certified
    basin of law (61) with gain K? Best verdict over :data:`W_GRID` (w: the
    deciding weight), and the fate of the delay-free trajectory from it
    ("diverges": lambda reaches 0.9, the wheel spins; "undecided": neither
    that nor a certified level set within 10 s)
    (:meth:`workbench.features.basin_loop.GainLoop.judge`)."""
    loop, lam_d, _ = cruise_loop(_values(values), v_d)
    return loop.judge(tuple(K), (float(point[0]) - v_d, float(point[1]) - lam_d), t_sim,
                      seed=seed)
