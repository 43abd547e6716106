"""The CFDL diagnostics of a ``tracking`` design's MFAC controller.

The chosen MFAC run is examined against the assumptions of the CFDL-MFAC
analysis (Hou & Jin 2011): the share of samples where the estimate's reset
fired, by condition; the range of the estimate; the *realised* pseudo-partial
derivative dy(k+1) / du(k) of the run (samples with |du| > epsilon), whose
sign the analysis assumes fixed and whose size it assumes bounded; the poles
of the control law with the PPD frozen at its median, around the sampled
linearised plant with its delay; and the cost's sensitivity to each gain.

References
----------
.. [HJ11] Hou Z., Jin S., "A novel data-driven control approach for a class of
   discrete-time nonlinear systems", IEEE Trans. Control Syst. Technol. 19(6),
   2011, pp. 1549-1558.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...controllers.mfac import (RESET_CONDITIONS, MFAC, MFACGains, frozen_loop_poles,
                                 frozen_ppd_poles)
from ...plants.train002 import linear_model
from ...sim.tracking import TrackingRun
from .spec import Reading

__all__ = ["PPDStats", "SENSITIVITY_KEYS", "before_stop", "frozen", "frozen_integrator",
           "mean_before_stop",
           "most_sensitive", "ppd_stats", "sensitivity"]

SENSITIVITY_KEYS = ("eta", "mu", "rho", "lam")


def before_stop(run: TrackingRun) -> np.ndarray:
    """(N, K) mask of the samples before each run's stop (all when it did not stop)."""
    stop = np.where(np.isfinite(run.stop_time), run.stop_time, np.inf)
    return run.t[None, :] < stop[:, None]


@dataclass(frozen=True)
class PPDStats:
    """The chosen MFAC run against the CFDL assumptions (see the module docstring).

    Attributes
    ----------
    samples : int
        Samples up to the stop with an estimate (k >= 2).
    reset_rate : float
        Share of them where the reset fired; ``by_condition`` per condition
        (a sample may meet several), and ``"at_limit"``: fired by a small
        du(k-1) with the command u(k-1) at a limit.
    saturated : float
        Share of samples with the command at a limit.
    phi_min, phi_max : float
        Range of the estimate in use.
    updates : int
        Samples with |du(k)| > epsilon (where the realised PPD is defined).
    data_sign_agreement, data_median, data_p95 : float
        Share of those where dy(k+1) / du(k) has the sign of phi(1); median and
        95th percentile of its magnitude.
    t, phi, data_t, data_ppd : numpy.ndarray
        Histories for the figure.
    """

    samples: int
    reset_rate: float
    by_condition: dict
    saturated: float
    phi_min: float
    phi_max: float
    updates: int
    data_sign_agreement: float
    data_median: float
    data_p95: float
    t: np.ndarray
    phi: np.ndarray
    data_t: np.ndarray
    data_ppd: np.ndarray



def mean_before_stop(flags: np.ndarray, mask: np.ndarray) -> np.ndarray:
    n = mask[:, :flags.shape[1]].sum(axis=1)
    return np.where(n > 0, (flags * mask[:, :flags.shape[1]]).sum(axis=1) / np.maximum(n, 1),
                    np.nan)



def ppd_stats(reading: Reading, run: TrackingRun, ctl: MFAC) -> PPDStats:
    K = int(before_stop(run)[0].sum())             # samples before the stop
    flags = {k: ctl.record(k)[0, :max(K - 1, 0)] for k in ("reset", *RESET_CONDITIONS)}
    phi = ctl.record("phi")[0, :max(K - 1, 0)]
    u, y = run.u[0, :K], run.v[0, :K]
    tr = reading.train
    limit = (u <= tr.u_min) | (u >= tr.u_max)
    flags["at_limit"] = flags["small_du"] & limit[:max(K - 1, 0)]
    du, dy = np.diff(u)[:-1], np.diff(y)[1:]          # du(k), dy(k+1) for k = 1 .. K-2
    upd = np.abs(du) > reading.epsilon
    data = dy[upd] / du[upd]
    sign1 = np.sign(ctl.phi1[0])
    sat = np.mean(limit) if K else math.nan
    mean = lambda x: float(np.mean(x)) if x.size else math.nan
    return PPDStats(
        int(phi.size), mean(flags["reset"]),
        {k: mean(flags[k]) for k in (*RESET_CONDITIONS, "at_limit")},
        float(sat), float(phi.min()), float(phi.max()), int(upd.sum()),
        mean(np.sign(data) == sign1), float(np.median(np.abs(data))) if data.size else math.nan,
        float(np.percentile(np.abs(data), 95)) if data.size else math.nan,
        run.t[1:K], phi, run.t[1:K - 1][upd], data)


def frozen(spec, reading: Reading, v_ref: float, mg: dict, phi: float):
    """(G, spectral radius) of the eq 7 law with the PPD frozen at ``phi`` around
    the ZOH-sampled linearised plant at ``v_ref`` with its delay (whole samples)."""
    from scipy.signal import cont2discrete, ss2tf
    G = mg["rho"] * phi / (mg["lam"] + phi * phi)
    d = reading.train.delay / spec.Ts
    if abs(d - round(d)) > 1e-9:
        return G, None
    A, B, C = linear_model(reading.train, v_ref)
    Ad, Bd, Cd, Dd, _ = cont2discrete((A, B, C, np.zeros((1, 1))), spec.Ts, method="zoh")
    num, den = ss2tf(Ad, Bd, Cd, Dd)
    den = np.polymul(den, np.r_[1.0, np.zeros(int(round(d)))])
    poles = frozen_loop_poles(G, np.trim_zeros(num[0], "f"), den)
    return G, float(np.max(np.abs(poles)))


def frozen_integrator(tun, Ts: float) -> tuple:
    """(G, roots) of the eq 7 law at the chosen point of an MFAC tuning ``tun``
    with its PPD frozen at phi(1), on a sampled pure integrator
    (:func:`~workbench.controllers.mfac.frozen_ppd_poles`: G = rho phi /
    (lambda + phi^2); the roots multiply to 1)."""
    g = tun.chosen_params()
    gains = MFACGains(g["lam"], g["rho"], g["eta"], g["mu"], g["phi1"])
    return (g["rho"] * g["phi1"] / (g["lam"] + g["phi1"] ** 2),
            frozen_ppd_poles(gains, g["phi1"], Ts))


def sensitivity(tun) -> dict:
    """Per parameter: the largest relative change of the weighted cost when that
    parameter alone moves to a neighbouring grid value (inf: a neighbour did not
    stop; a neighbour that is not reproducible is left out, nan when none is left)."""
    i = tun.chosen
    base = tun.cost[i]
    out = {}
    for key in SENSITIVITY_KEYS:
        j = tun.keys.index(key)
        others = np.delete(np.arange(len(tun.keys)), j)
        same = np.all(tun.params[:, others] == tun.params[i, others], axis=1)
        vals = np.unique(tun.params[same, j])
        pos = int(np.searchsorted(vals, tun.params[i, j]))
        nb = [vals[p] for p in (pos - 1, pos + 1) if 0 <= p < len(vals)]
        rows = [np.flatnonzero(same & (tun.params[:, j] == x))[0] for x in nb]
        rows = [r for r in rows if tun.reproducible is None or tun.reproducible[r]]
        out[key] = max((abs(tun.cost[r] - base) / base for r in rows),
                       default=math.nan if nb else 0.0)   # nan: no reproducible neighbour
    return out


def most_sensitive(sens: dict) -> str:
    """The parameter with the largest finite sensitivity (nan: not measured)."""
    return max(sens, key=lambda k: sens[k] if not math.isnan(sens[k]) else -math.inf)
