"""Figures of a ``tracking`` design (pure functions of its results; a
controller the reading does not have is left out)."""
from __future__ import annotations

import numpy as np

from ...report.markdown import fmt
from .run import ReadingResult, TrackingResult
from .spec import OBJECTIVES

AXIS = {"stop_error": "stop error (m)", "punctuality": "punctuality |T_t − T_o| (s)",
        "comfort": "RMS jerk (m/s³)", "energy": "traction energy (J/kg)"}
#: the 2-D projections of the 4-objective fronts that the figure shows
PROJECTIONS = (("stop_error", "comfort"), ("punctuality", "energy"))
COLOURS = {"MFAC": "tab:blue", "PID": "tab:orange"}
#: objectives that can be exactly 0 are drawn on a symlog axis, linear below this (their unit)
SYMLOG = {"punctuality": 1e-2}


def _front_2d(P: np.ndarray) -> np.ndarray:
    """Rows of a 2-column array that no other row dominates, sorted by column 0."""
    P = P[np.all(np.isfinite(P), axis=1)]
    P = P[np.lexsort((P[:, 1], P[:, 0]))]
    keep, best = [], np.inf
    for row in P:
        if row[1] < best:
            keep.append(row)
            best = row[1]
    return np.array(keep).reshape(-1, 2)


def plot_pareto(fig, r: ReadingResult) -> None:
    """Two projections of both controllers' grids: every reproducible run (dots;
    the others' objectives are no results), the 4-D Pareto front (rings), its
    2-D front (step line) and the chosen point (star)."""
    axes = fig.subplots(1, len(PROJECTIONS))
    for ax, (x, y) in zip(axes, PROJECTIONS):
        ix, iy = OBJECTIVES.index(x), OBJECTIVES.index(y)
        for name, tun in r.tunings:
            c = COLOURS[name]
            P = tun.objectives[:, [ix, iy]]
            ok = np.all(np.isfinite(P), axis=1) & tun.reproducible
            ax.scatter(P[ok, 0], P[ok, 1], s=4, color=c, alpha=0.15, lw=0)
            F = P[tun.front]
            ax.scatter(F[:, 0], F[:, 1], s=14, facecolors="none", edgecolors=c, lw=0.6,
                       label=f"{name} front (4-D)")
            f2 = _front_2d(P[tun.reproducible])
            ax.step(f2[:, 0], f2[:, 1], where="post", color=c, lw=1)
            ax.scatter(*P[tun.chosen], marker="*", s=160, color=c, edgecolors="k", lw=0.6,
                       zorder=5, label=f"{name} chosen")
        for setter, name in ((ax.set_xscale, x), (ax.set_yscale, y)):
            if name in SYMLOG:      # a punctuality of exactly 0 stays visible
                setter("symlog", linthresh=SYMLOG[name])
            else:
                setter("log")
        ax.set_xlabel(AXIS[x])
        ax.set_ylabel(AXIS[y])
    axes[0].legend(fontsize=6, loc="best")
    fig.suptitle(f"reading '{r.reading.name}'", fontsize=9)


def plot_tracking(fig, res: TrackingResult) -> None:
    """Speed error and net acceleration of the chosen points, one column per reading."""
    axes = fig.subplots(2, len(res.readings), sharex=True, squeeze=False)
    for j, r in enumerate(res.readings):
        m = r.main
        for run, name in ((m.mfac, "MFAC"), (m.pid, "PID")):
            if run is None:
                continue
            axes[0, j].plot(run.t, (run.v[0] - run.target[0]) * 3.6, lw=0.8,
                            color=COLOURS[name], label=name)
            axes[1, j].plot(run.t, run.a[0], lw=0.6, color=COLOURS[name], label=name)
        axes[1, j].plot(m.profile.t, m.profile.a, "k--", lw=0.8, label="target")
        axes[0, j].set_title(f"reading '{r.reading.name}'", fontsize=9)
        axes[1, j].set_xlabel("time (s)")
    axes[0, 0].set_ylabel("speed error (km/h)")
    axes[1, 0].set_ylabel("net acceleration (m/s²)")
    axes[0, 0].legend(fontsize=7)
    axes[1, 0].legend(fontsize=7)


def jerk_1s(run, i: int = 0):
    """(t, jerk) of batch element ``i``: (a(k + m) - a(k)) / (m Ts) over 1 s
    windows, the quantity of the peak-jerk constraint (``Objectives.peak_jerk``),
    up to the stop, at the window's end."""
    dt = run.t[1] - run.t[0]
    m = max(1, int(round(1.0 / dt)))
    keep = run.t[m:] < run.stop_time[i] if np.isfinite(run.stop_time[i]) else slice(None)
    return run.t[m:][keep], ((run.a[i, m:] - run.a[i, :-m]) / (m * dt))[keep]


def plot_jerk(fig, res: TrackingResult, limit: float | None) -> None:
    """Jerk (1 s windows) of the chosen points against the comfort limit, one
    panel per reading."""
    axes = fig.subplots(1, len(res.readings), sharey=True, squeeze=False)[0]
    for ax, r in zip(axes, res.readings):
        for run, name in ((r.main.mfac, "MFAC"), (r.main.pid, "PID")):
            if run is None:
                continue
            t, j = jerk_1s(run)
            ax.plot(t, j, lw=0.7, color=COLOURS[name], label=name)
        if limit is not None:
            for s in (1, -1):
                ax.axhline(s * limit, color="r", ls="--", lw=0.9,
                           label=f"limit ±{limit:g} m/s³" if s > 0 else None)
        ax.set_title(f"reading '{r.reading.name}'", fontsize=9)
        ax.set_xlabel("time (s)")
    axes[0].set_ylabel("jerk, 1 s windows (m/s³)")
    axes[0].legend(fontsize=7)


def plot_ppd(fig, res: TrackingResult) -> None:
    """Per reading: the estimate in use and the realised PPD dy(k+1)/du(k) of
    the chosen MFAC run, with phi(1) and the plant's DC gain."""
    axes = fig.subplots(1, len(res.readings), squeeze=False)[0]
    for ax, r in zip(axes, res.readings):
        s = r.ppd
        pos, neg = s.data_ppd > 0, s.data_ppd <= 0
        ax.scatter(s.data_t[pos], s.data_ppd[pos], s=5, color="tab:green",
                   label="realised PPD > 0")
        ax.scatter(s.data_t[neg], -s.data_ppd[neg], s=5, color="tab:red", marker="x", lw=0.6,
                   label="realised PPD ≤ 0 (magnitude)")
        ax.plot(s.t, s.phi, color="tab:blue", lw=0.8, label="estimate in use")
        ax.axhline(r.mfac.chosen_params()["phi1"], color="tab:blue", ls=":", lw=0.8,
                   label="φ(1)")
        ax.axhline(r.dc_gain, color="k", ls="--", lw=0.8, label="DC gain")
        ax.set_yscale("log")
        ax.set_xlabel("time (s)")
        ax.set_title(f"reading '{r.reading.name}'", fontsize=9)
    axes[0].set_ylabel("PPD ((m/s) per unit command)")
    axes[0].legend(fontsize=6)


def plot_line(fig, res: TrackingResult) -> None:
    """Stop error per section of the chosen points, one panel per reading."""
    axes = fig.subplots(1, len(res.readings), sharey=True, squeeze=False)[0]
    for ax, r in zip(axes, res.readings):
        comps = (r.main, *r.line)
        names = [c.section.name.replace(" (synthetic)", "*") for c in comps]
        x = np.arange(len(comps))
        for ctrl, off in (("MFAC", -0.2), ("PID", 0.2)):
            if ctrl not in dict(r.tunings):
                continue
            vals = [c.value(ctrl, "stop_error") for c in comps]
            ax.bar(x + off, [v if np.isfinite(v) else np.nan for v in vals], 0.4, label=ctrl,
                   color=COLOURS[ctrl])
        ax.axhline(res.stop_tolerance, color="k", ls="--", lw=1,
                   label=f"tolerance {fmt(res.stop_tolerance)} m")
        ax.set_yscale("log")
        ax.set_xticks(x, names, rotation=60, ha="right", fontsize=7)
        ax.set_title(f"reading '{r.reading.name}'", fontsize=9)
    axes[0].set_ylabel("stop error (m)")
    axes[0].legend(fontsize=7)
