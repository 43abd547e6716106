"""``workbench simulate`` and ``workbench sweep`` for ``switched-run`` designs
(issue 35, items 1 and 3; printing and files only, the computing is
:mod:`.simulate` and :mod:`.study`).

``simulate``: one scenario at its step (or ``--dt``), its metrics, and with
``--csv`` its trajectory (t, states, commands, phase), as the
``delay-feedback`` command.

``sweep``: the design's ``[montecarlo]`` with ``--samples`` and ``--seed``
(the same draws as the report for the design's own values,
:func:`workbench.features.montecarlo.draw`), one scenario (``--case``). With
``--out DIR`` the runs are computed in chunks and written to
``DIR/<scenario>-chunk-NNNN.csv`` (one row per run: its draws, its metrics,
why it ended), ``--resume`` skipping the chunks already there
(:mod:`workbench.features.montecarlo_chunks`, the machinery of every kind's sweep).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ...features.cli_plumbing import pick_named, timed
from ...features.montecarlo_chunks import CHUNK

__all__ = ["CHUNK", "simulate_command", "sweep_command", "trajectory_csv"]


def _step(spec, sc, dt) -> float:
    """``--dt`` checked: a step of the scenario's horizon of which the delay
    and the control period are whole multiples (as the design's own)."""
    from ...errors import DesignError
    from . import MAX_STEPS, whole_steps
    if dt is None:
        return sc.dt
    ok = isinstance(dt, float) and math.isfinite(dt) and 0 < dt <= sc.t_end / 10 \
        and sc.t_end / dt <= MAX_STEPS
    for what, v in (("the delay h", spec.h),
                    ("the control period", spec.sampled.period if spec.sampled else 0.0)):
        if ok and v and not whole_steps(v, dt):
            raise DesignError("<cli>", "--dt", dt, f"a step of which {what} {v:g} s is a "
                              "whole multiple")
    if not ok:
        raise DesignError("<cli>", "--dt", dt, f"a step in (0, {sc.t_end / 10:g}] s with at "
                          f"most {MAX_STEPS:g} steps over t_end")
    return dt


def simulate_command(design, *, case: str | None, dt: float | None, as_json: bool,
                     csv: str | None = None) -> int:
    """``workbench simulate`` of one scenario: its metrics (with ``csv`` its
    trajectory, :func:`trajectory_csv`); exit 0."""
    from ...report.markdown import fmt
    from ..delay_feedback.cli import print_run
    from .simulate import Compiled, simulate
    spec = design.spec
    sc = pick_named(spec.scenarios, case)
    step = _step(spec, sc, dt)
    b, wall = timed(lambda: simulate(spec, Compiled(spec), sc, step, record=True))
    m = {k: float(v[0]) for k, v in b.metrics.items()}
    if csv:
        from ...report.files import atomic_write
        atomic_write(Path(csv), trajectory_csv(spec, b))
    return print_run({"design": design.name, "case": sc.name, "dt": step,
                      "ended": b.reasons[0],
                      "metrics": {k: None if math.isnan(v) else v for k, v in m.items()},
                      "wall_s": round(wall, 3)},
                     f"{design.name}: scenario {sc.name}, h = {fmt(spec.h)} s, dt = "
                     f"{fmt(step)} s, ended: {b.reasons[0]}", m, as_json)


def trajectory_csv(spec, b) -> str:
    """A recorded run as CSV: ``t`` (s), each state, each command as the
    controller outputs it (it acts h later), in the design's units, and the
    phase's name; ``repr`` floats (the file reads back bit for bit)."""
    from ..delay_feedback.cli import csv_text
    names = [p.name for p in spec.phases]
    return csv_text(spec, b.t, b.x, b.u, [names[int(p)] for p in b.phase])


def sweep_command(design, *, samples: int, seed: int, as_json: bool, case: str | None = None,
                  out: str | None = None, resume: bool = False) -> int:
    """``workbench sweep`` of a ``switched-run`` design (see the module
    docstring): print the share of runs passing each claim on the scenario
    (Wilson 95 %) and the range of every metric; exit 0 (failing runs are
    reported, not an error)."""
    from ...errors import DesignError
    from ...features.montecarlo import drawn_factors
    from ..capabilities import sweep_draws
    from ...features.montecarlo_chunks import Group, check_resume, run_groups
    from . import MAX_WORK
    from .study import MonteCarloRun
    spec = design.spec
    mc = sweep_draws(design, samples, seed, 100_000)
    check_resume(out, resume)
    sc = pick_named(spec.scenarios, case)
    if samples * sc.t_end / sc.dt > MAX_WORK:
        raise DesignError("<cli>", "--samples", samples, f"at most {MAX_WORK:g} samples x "
                          "steps")
    draws = drawn_factors(mc, tuple(spec.plant.parameters))
    got = run_groups([Group(sc.name, draws)], lambda g, d: _run(spec, sc, d), out or None,
                     {"design": design.name, "scenario": sc.name, "samples": samples,
                      "seed": seed}, resume)[sc.name]
    res = MonteCarloRun(samples, seed, draws, got.metrics, tuple(got.reasons))
    _print_summary(design, sc, res, as_json)
    return 0


def _run(spec, sc, draws):
    from .simulate import Compiled
    from .study import drawn_runs
    return drawn_runs(spec, Compiled(spec), sc, draws)


def _print_summary(design, sc, res, as_json: bool) -> None:
    from ...features.montecarlo_stats import finite_span
    from ...report.markdown import fmt, md_table
    from .quantities import scenario_metrics
    from .study import _rate
    rates = [_rate(c, res) for c in design.spec.claims if c.scenario == sc.name]
    units = scenario_metrics(design.spec, sc.name)
    span = {k: finite_span(v) for k, v in res.metrics.items()}
    if as_json:
        print(json.dumps({"design": design.name, "case": sc.name, "samples": res.samples,
                          "seed": res.seed, "diverged": int(np.nansum(res.metrics["diverged"])),
                          "claims": {c.claim_id: {"passes": c.passes, "n": c.n, "lo": c.lo,
                                                  "hi": c.hi} for c in rates},
                          "metrics": {k: {"min": a, "max": b} for k, (a, b) in span.items()}},
                         indent=2))
        return
    print(f"{design.name}: Monte Carlo of scenario {sc.name}, {res.samples} runs, seed "
          f"{res.seed}: {int(np.nansum(res.metrics['diverged']))} diverged or chattered")
    if rates:
        print(md_table(["claim", "runs passing", "Wilson 95 %"],
                       [[c.claim_id, f"{c.passes} / {c.n}", f"[{fmt(c.lo, 4)}, {fmt(c.hi, 4)}]"]
                        for c in rates], "lrr"))
    print(md_table(["metric", "min over runs", "max over runs", "unit"],
                   [[k, fmt(a, 5), fmt(b, 5), units[k]] for k, (a, b) in span.items()],
                   "lrrl"))
