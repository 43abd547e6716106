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
* :func:`safe_k2_range` -- a certified switching rule for eq (75): the gains
  k2 (k1 kept) for which the printed switch state (v_d, lambda_opt) is
  CERTIFIED (the best verdict over the weight grid, w: the deciding weight),
  the edge between the largest certified grid value and the next bisected,
  and gains given for comparison (003's Table 3 rows, with their own k1)
  judged the same way. The rule is *sufficient*: a state outside every
  certified level set may still converge; the "fate" says what the delay-free
  trajectory from it does within :data:`T_JUDGE` ("diverges": lambda reaches
  0.9, the wheel spins; "undecided": neither that nor a certified level set).

Only the closed loop (law (61) at v_d on the adhesion plant, its domain and
the |lambda| = 0.9 divergence event), the weight grid and the k2
parameterisation are paper 003's and stay here: a
:class:`workbench.features.basin_loop.GainLoop`, whose general methods give
the modal problems, the switch states' verdicts, the best verdict over the
grid, the sampled starts, the trajectories' fates and the gain sweep
(:meth:`~workbench.features.basin_loop.GainLoop.sweep`); the figure is
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
from ...features.basin_loop import GainBasin, GainLoop
from ...features.basin_points import GainSweep
from ...features.basin_trajectory import limit_event
from ...plants.adhesion import NumericAdhesion, adhesion_model
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
class CruiseBasin(GainBasin):
    """Basin of the cruise law for one design (no rendering): the
    :class:`~workbench.features.basin_loop.GainBasin` in the error coordinates
    (``w``: the weight of the fast mode in P = modal_P(A + B K, [1, w]);
    ``trajectories``: from each switch state, then from the seeded grid) and
    the cruise point (m/s, creep ratios)."""

    v_d: float
    lambda_d: float
    lambda_opt: float


#: |lambda| at which a delay-free trajectory has diverged (the runs' own test).
LAM_DIVERGED = ControllerSettings.lam_diverged
#: Time step (s) of a trajectory's drawn path: the dense output on this fixed
#: grid (:func:`workbench.features.basin_trajectory.drawn_path`), for every
#: fate (issue 36 item 5: a failing trajectory's accepted steps bunch up where
#: it diverges and move by ~1e-7 s under a 3-ulp change of the start).
PATH_DT = 0.01
#: Horizon (s) of the delay-free trajectory from a switch state judged for a gain.
T_JUDGE = 10.0


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
    return CruiseBasin(best.K, best.w, best.check, best.trajectories, v_d, lam_d, lam_opt)


def safe_k2_range(values: dict, v_d: float, k1: float, point, *, grid, compare=(),
                  bisect: int = 4, seed: int = 0) -> GainSweep:
    """Cruise gains k2 (k1 kept) for which ``point`` lies in a certified basin
    (module docstring; :meth:`workbench.features.basin_loop.GainLoop.sweep`).

    Parameters
    ----------
    values : dict
        Nominal plant constants (SI) the controller is built on.
    v_d : float
        Cruise speed (m/s).
    k1 : float
        First gain entry, kept along the sweep.
    point : (v, lambda)
        Switch state (absolute), e.g. (v_d, lambda_opt) for eq (75) as printed.
    grid : sequence of float
        k2 values judged.
    compare : sequence of (label, (k1, k2))
        Gains judged for comparison (e.g. 003 Table 3).
    bisect : int
        Bisection steps on the edge of the certified range.
    seed : int
        Seed of the falsifier.

    Returns
    -------
    GainSweep
        Of k2 (entry 1) with k1 = ``gain[0]`` kept; ``grid_min`` the smallest k2 of the grid.
    """
    vals = _values(values)
    loop, lam_d, _ = cruise_loop(vals, float(v_d))
    # the designs that differ only in the plant's mass share the controller's
    # nominal model, hence this sweep: computed once per run (run folder)
    return loop.sweep((k1, 0.0), (point[0] - v_d, point[1] - lam_d), 1, grid, T_JUDGE,
                      point=point, compare=compare, bisect=bisect, seed=seed,
                      share=("antiskid_basin.k2_sweep", (vals, float(v_d))))
