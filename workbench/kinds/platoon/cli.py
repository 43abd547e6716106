"""``workbench simulate`` for ``platoon`` designs: one ``[[runs]]`` entry (the
paper's ideal set-up) under its law, its metrics, and with ``--csv`` its
trajectory (printing and files only; the computing is :mod:`.run`).

The step is the design's ``[platoon] T`` (the control period and the
integration step at once), so ``--dt`` is not taken.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

__all__ = ["simulate_command", "trajectory_csv"]


def simulate_command(design, *, case: str | None, as_json: bool, csv: str | None = None) -> int:
    """``workbench simulate``: the run ``case`` (default: the design's first),
    its metrics (worst over the followers) and with ``csv`` its trajectory; exit 0."""
    import time

    from ...errors import DesignError
    from ...report.markdown import fmt
    from ..delay_feedback.cli import print_run
    from .run import _metrics, scenario
    spec = design.spec
    names = [r.name for r in spec.runs]
    if case is not None and case not in names:
        raise DesignError("<cli>", "--case", case, "a run of [[runs]]: " + ", ".join(names))
    rs = spec.run_spec(case or names[0])
    t0 = time.perf_counter()
    sc = scenario(spec)
    run = sc.simulate(rs.law, None if rs.initial_errors is None else np.array(rs.initial_errors))
    wall = time.perf_counter() - t0
    from .realism import accel_end
    prof = sc.profile
    window = (accel_end(prof) + 10.0, float(prof.t[np.nonzero(prof.a < 0)[0][0]]))
    mt = _metrics(run, window, sc.nominal.m, spec.G_w + spec.G_d)
    m = {"max_abs_e": max(mt.max_abs_e), "cruise_abs_e": max(mt.cruise_abs_e),
         "cruise_abs_de": max(mt.cruise_abs_de), "string_ratio": mt.string_ratio,
         "chatter": max(mt.chatter), "sign_rate": max(mt.sign_rate),
         "lumped_ratio": mt.lumped_ratio, "max_speed": max(mt.max_speed)}
    if csv:
        from ...report.files import atomic_write
        atomic_write(Path(csv), trajectory_csv(run))
    return print_run({"design": design.name, "case": rs.name, "law": rs.law, "T": spec.T,
                      "metrics": {k: None if not math.isfinite(v) else v for k, v in m.items()},
                      "wall_s": round(wall, 3)},
                     f"{design.name}: run {rs.name} (law {rs.law}), T = {fmt(spec.T)} s, "
                     f"{spec.n} trains", m, as_json)


def trajectory_csv(run) -> str:
    """Columns ``t`` (s), ``x<i>`` (m), ``v<i>`` (m/s), ``u<i>`` (N) of every
    train and ``e<i>`` (m) of every follower; ``repr`` floats (the file reads
    back bit for bit)."""
    n = run.x.shape[1]
    cols = (["t"] + [f"{c}{i}" for c in ("x", "v", "u") for i in range(1, n + 1)]
            + [f"e{i}" for i in range(2, n + 1)])
    rows = np.column_stack([run.t, run.x, run.v, run.u, run.e])
    return ",".join(cols) + "\n" + "".join(",".join(repr(float(x)) for x in r) + "\n"
                                           for r in rows)
