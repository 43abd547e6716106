"""``workbench simulate`` for ``tracking`` designs: one plant reading
(``--case``, default the design's first) tuned on the main pair, and its
chosen points' objectives; with ``--csv`` their trajectories (printing and
files only; the computing is :func:`.run.run_reading`).

The steps are the design's ``[simulation]`` Ts and dt (the tuning is decided
at them), so ``--dt`` is not taken.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["simulate_command", "trajectory_csv"]

METRICS = ("stop_error", "punctuality", "comfort", "energy", "peak_jerk", "rms_speed_error")


def simulate_command(design, *, case: str | None, as_json: bool, csv: str | None = None) -> int:
    """``workbench simulate``: the reading ``case`` (default: the design's
    first), each controller's chosen gains and its objectives on the main
    pair, and with ``csv`` the chosen runs' trajectories; exit 0."""
    import time

    from ...errors import DesignError
    from ...report.markdown import fmt
    from ..delay_feedback.cli import print_run
    from .run import run_reading
    spec = design.spec
    names = [r.name for r in spec.readings]
    if case is not None and case not in names:
        raise DesignError("<cli>", "--case", case, "a plant reading: " + ", ".join(names))
    reading = spec.readings[names.index(case) if case is not None else 0]
    t0 = time.perf_counter()
    r = run_reading(spec, reading)
    wall = time.perf_counter() - t0
    m, gains = {}, {}
    for c, tun in r.tunings:
        gains[c] = tun.chosen_params()
        for k in METRICS:
            m[f"{c.lower()}.{k}"] = r.main.value(c, k)
    if csv:
        from ...report.files import atomic_write
        atomic_write(Path(csv), trajectory_csv(r.main))
    return print_run({"design": design.name, "case": reading.name, "section": spec.main.name,
                      "gains": gains, "Ts": spec.Ts, "dt": spec.dt,
                      "metrics": {k: None if not math.isfinite(v) else v for k, v in m.items()},
                      "wall_s": round(wall, 3)},
                     f"{design.name}: reading {reading.name}, chosen points on "
                     f"{spec.main.name} ("
                     + "; ".join(f"{c}: " + ", ".join(f"{k} = {fmt(v, 3)}" for k, v in g.items())
                                 for c, g in gains.items())
                     + f"), Ts = {fmt(spec.Ts)} s, dt = {fmt(spec.dt)} s", m, as_json)


def trajectory_csv(comp) -> str:
    """Columns ``t`` (s), ``target`` (m/s) and per controller ``v_<c>`` (m/s),
    ``s_<c>`` (m), ``a_<c>`` (m/s^2), ``u_<c>`` (command) of a comparison's
    chosen runs, one row per control sample; ``repr`` floats (the file reads
    back bit for bit). Runs that ended earlier are padded with nan."""
    runs = [(c, x) for c, x in (("mfac", comp.mfac), ("pid", comp.pid)) if x is not None]
    K = max(x.t.size for _, x in runs)
    t = next(x.t for _, x in runs if x.t.size == K)
    pad = lambda y: np.concatenate([y, np.full(K - y.size, np.nan)])
    cols, data = ["t", "target"], [t, pad(runs[0][1].target[0])]
    for c, x in runs:
        for f in ("v", "s", "a", "u"):
            cols.append(f"{f}_{c}")
            data.append(pad(getattr(x, f)[0]))
    rows = np.column_stack(data)
    return ",".join(cols) + "\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                           for row in rows)
