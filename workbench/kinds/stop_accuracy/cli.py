"""``workbench simulate`` and ``workbench sweep`` for ``stop-accuracy``
designs (issue 35, items 1 and 3; printing and files only, the computing is
:mod:`.run`).

A case is a speed and a controller, named as its quantities' prefix,
``v<speed>.<controller>`` (e.g. ``v60.profile``), or under a fault
``v<speed>.<controller>.fault[<fault>]``; the default is the first speed's
first controller.

``simulate``: one stop of a case on the nominal plant (or the fault's) at the
design's step (or ``--dt``): its stop error, stop time and stopping point,
and with ``--csv`` its trajectory (``t``, ``x``, ``v``, ``a``, ``command``,
every control period).

``sweep``: the design's ``[montecarlo]`` with ``--samples`` and ``--seed``
(with the design's own values the report's draws and stop errors:
:func:`.run.montecarlo_draws`, every run independent of its batch), on
every case without a fault (or one, ``--case``): per case the share of stops
within the tolerance (Wilson 95 %), the 95th percentile of |error|, the mean
error and the overshoot share. With ``--out DIR`` the runs are computed in
chunks and written to ``DIR/<case>-chunk-NNNN.csv`` (one row per run: its
draws and its stop error, m), ``--resume`` skipping the chunks already there
(:mod:`workbench.features.montecarlo_chunks`).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

__all__ = ["case_names", "simulate_command", "sweep_command", "trajectory_csv"]


def case_names(spec, faults: bool = True) -> list[str]:
    """Every case of the design (with ``faults``: also under each fault)."""
    from .run import speed_key
    out = []
    for s in spec.speeds_kmh:
        for c in spec.controllers:
            out.append(f"{speed_key(s)}.{c.name}")
            if faults:
                out += [f"{speed_key(s)}.{c.name}.fault[{f.name}]" for f in spec.faults]
    return out


def _cases(spec, case, faults: bool):
    """[(name, speed, controller index, fault or None)] of ``--case`` (all
    cases without a fault when None and not ``faults``; else the first)."""
    from ...errors import DesignError
    from .run import speed_key
    every = []
    for s in spec.speeds_kmh:
        for i, c in enumerate(spec.controllers):
            every.append((f"{speed_key(s)}.{c.name}", s, i, None))
            if faults:
                every += [(f"{speed_key(s)}.{c.name}.fault[{f.name}]", s, i, f)
                          for f in spec.faults]
    if case is None:
        return every[:1] if faults else every
    got = [x for x in every if x[0] == case]
    if not got:
        raise DesignError("<cli>", "--case", case, "one of " + ", ".join(x[0] for x in every))
    return got


def _step(spec, dt) -> float:
    """``--dt`` checked: a step of which the control period is a whole multiple."""
    from ...errors import DesignError
    if dt is None:
        return spec.dt
    k = spec.dt_ctrl / dt if isinstance(dt, float) and math.isfinite(dt) and dt > 0 else 0.0
    if not (k >= 1 and abs(k - round(k)) <= 1e-9 * k and spec.t_end / dt <= 2_000_000):
        raise DesignError("<cli>", "--dt", dt, f"a step of which the control period "
                          f"{spec.dt_ctrl:g} s is a whole multiple, at most 2e6 steps over "
                          f"t_end = {spec.t_end:g} s")
    return dt


def simulate_command(design, *, case: str | None, dt: float | None, as_json: bool,
                     csv: str | None = None) -> int:
    """``workbench simulate`` of one case (see the module docstring); exit 0."""
    import time

    from ...report.markdown import fmt
    from ..delay_feedback.cli import print_run
    from .run import compile_laws, simulate_cases, stopping_points
    spec = design.spec
    (name, s, i, fault), = _cases(spec, case, faults=True)
    step = _step(spec, dt)
    t0 = time.perf_counter()
    D = stopping_points(spec)[s]
    tr, _ = simulate_cases(spec, compile_laws(spec), step, [(s, i, fault, D)])
    wall = time.perf_counter() - t0
    nan = lambda x: None if math.isnan(x) else float(x)
    m = {"stop_error_m": nan(tr.x_stop[0] - D), "t_stop_s": nan(tr.t_stop[0]),
         "distance_m": float(D)}
    if csv:
        from ...report.files import atomic_write
        atomic_write(Path(csv), trajectory_csv(tr))
    return print_run({"design": design.name, "case": name, "dt": step, "metrics": m,
                      "wall_s": round(wall, 3)},
                     f"{design.name}: case {name}, {fmt(s)} km/h to D = {fmt(D, 6)} m, dt = "
                     f"{fmt(step)} s", {k: math.nan if v is None else v for k, v in m.items()},
                     as_json)


def trajectory_csv(tr, k: int = 0) -> str:
    """Run ``k`` of recorded traces as CSV: ``t`` (s), ``x`` (m since braking
    began), ``v`` (m/s), ``a`` (m/s^2), ``command`` (m/s^2, the brake command
    the law sent); ``repr`` floats (the file reads back bit for bit)."""
    rows = np.vstack([tr.t, tr.x[:, k], tr.v[:, k], tr.a[:, k], tr.c[:, k]]).T
    return "t,x,v,a,command\n" + "".join(",".join(repr(float(v)) for v in row) + "\n"
                                         for row in rows)


def sweep_command(design, *, samples: int, seed: int, as_json: bool, case: str | None = None,
                  out: str | None = None, resume: bool = False) -> int:
    """``workbench sweep`` of a ``stop-accuracy`` design (see the module
    docstring); exit 0 (stops outside the tolerance are reported, not an
    error)."""
    from ...errors import DesignError
    from ..capabilities import sweep_draws
    from ...features.montecarlo_chunks import Group, check_resume, run_chunks
    from . import MAX_WORK
    from .run import compile_laws, montecarlo_draws, simulate_cases, stopping_points
    spec = design.spec
    mc = sweep_draws(design, samples, seed, 100_000)
    check_resume(out, resume)
    cases = _cases(spec, case, faults=False)
    if samples * len(cases) * spec.t_end / spec.dt > MAX_WORK:
        raise DesignError("<cli>", "--samples", samples, f"at most {MAX_WORK:g} runs x steps")
    draws = montecarlo_draws(spec, mc)
    D = stopping_points(spec)
    laws = compile_laws(spec)
    run = lambda sel, d: simulate_cases(spec, laws, spec.dt,
                                        [(s, i, None, D[s]) for _, s, i, _ in sel], d)
    if out:
        by = {x[0]: x for x in cases}
        got = run_chunks(Path(out), {"design": design.name, "cases": list(by),
                                     "samples": samples, "seed": seed},
                         [Group(name, draws) for name in by],
                         lambda g, d: _chunk(run([by[g.name]], d), None), resume)
        errors = {name: got[name].metrics["error_m"] for name in by}
    else:
        err = _chunk(run(cases, draws), None)[0]["error_m"]
        errors = {x[0]: err[j * samples:(j + 1) * samples] for j, x in enumerate(cases)}
    _print_summary(design, mc, errors, as_json)
    return 0


def _chunk(sim, reasons):
    tr, D = sim
    return {"error_m": tr.x_stop - D}, reasons


def _print_summary(design, mc, errors: dict, as_json: bool) -> None:
    from ...features.montecarlo import MC_QUANTITIES, stop_statistics
    from ...report.markdown import fmt, md_table
    tol = design.spec.tolerance
    st = {k: stop_statistics(e, tol) for k, e in errors.items()}
    if as_json:
        print(json.dumps({"design": design.name, "samples": mc.samples, "seed": mc.seed,
                          "tolerance_m": tol,
                          "cases": {k: {"within": int(s.k), "n": int(s.n)} | {
                              q: _json(getattr(s, a)) for q, a in MC_QUANTITIES.items()}
                              for k, s in st.items()}}, indent=2))
        return
    print(f"{design.name}: Monte Carlo, {mc.samples} runs per case, seed {mc.seed}, "
          f"tolerance {fmt(tol)} m")
    print(md_table(["case", "stops within", "Wilson 95 %", "p95 |error| (m)", "mean (m)",
                    "overshoot share"],
                   [[k, f"{s.k} / {s.n}", f"[{fmt(s.lo, 4)}, {fmt(s.hi, 4)}]",
                     fmt(s.p95, 4), fmt(s.mean, 4), fmt(s.overshoot, 4)]
                    for k, s in st.items()], "lrrrrr"))


def _json(x):
    x = float(x)
    return None if not math.isfinite(x) else x
