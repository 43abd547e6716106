"""``workbench synthesize delay-bound`` and ``workbench simulate`` for
``delay-feedback`` designs (printing only; the computing is
:mod:`.run`)."""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np

from .requirements_render import gain_text


def synthesis_table(rows, settings) -> str:
    """The printed table of a problem (60) eps sweep (``workbench synthesize
    delay-bound``), with its notes; one function for every design kind, so
    the same rows print the same digits."""
    from ...report.markdown import fmt, md_table
    digits = settings.gain_digits
    table = [[fmt(r.eps), fmt(r.h_certified, 5), fmt(r.h_refuted, 5),
              "—" if r.K is None else "[" + ", ".join(fmt(k, digits) for k in r.K) + "]",
              fmt(r.h_gain, 4), fmt(r.exact.h if r.exact else None, 5),
              fmt(r.exact_siso.h if r.exact_siso else None, 5),
              fmt(r.ratio, 3), r.status.value] for r in rows]
    out = [md_table(["eps", "h_certified: on [0, h] (s)", "h_refuted", "K (canonical)",
                     "K certified on [0, h] (s)", "h* (eig)", "h* (pyctrl)", "ratio", "status"],
                    table, "rrrlrrrrl"),
           "Interval certificates: Theorem 1 of paper 003 proves stability for every constant "
           "delay in [0, h] (h* = end of the exact stable window from 0).",
           f"K (canonical): the minimum-norm certificate at {fmt(settings.gain_fraction)} "
           f"x h_certified, rounded to {digits} significant digits, then certified on its own "
           "with K fixed (h certified by K)."]
    if any(r.exact and math.isinf(r.exact.h) for r in rows):
        out.append("h* = inf: no characteristic root reaches the imaginary axis for any delay "
                   "— the loop is stable for every constant delay; h_certified is the limit "
                   "of the LMI criterion, not of the loop.")
    return "\n".join(out)


def print_sweep(name: str, header: str, rows, settings, as_json: bool) -> int:
    """Print an eps sweep's rows under ``header`` (:func:`synthesis_table`),
    or as JSON; exit 0 if every row is certified, else 1."""
    if as_json:
        print(json.dumps({"design": name, "rows": [r.to_json() for r in rows]}, indent=2))
    else:
        print(header)
        print(synthesis_table(rows, settings))
    return 0 if all(r.status.value == "certified" for r in rows) else 1


def loop_sweep_command(design, *, eps=None, as_json: bool = False) -> int:
    """``workbench synthesize delay-bound`` of a study that owns its loop: the
    sweep over ``eps`` (default the spec's ``sweep``,
    :class:`workbench.features.sweep_study.SweepSpec`) on the (A, B) of the
    study's ``loop(design) -> (A, B, header)``, printed under ``header``
    (:func:`print_sweep`); exit 0 if every row is certified, else 1."""
    from .. import REGISTRY
    from ...synthesis import synthesize_delay_bound
    A, B, header = REGISTRY[design.kind].loop(design)
    sw = design.spec.sweep
    rows = synthesize_delay_bound(A, B, tuple(eps) if eps else sw.eps, sw.settings)
    return print_sweep(design.name, header, rows, sw.settings, as_json)


def _op_text(spec, op) -> str:
    from ...report.markdown import fmt
    vals = op.as_dict(spec.plant)
    return ", ".join(f"{k} = {fmt(v, 6)}" + (" (solved)" if k in op.solved else "")
                     for k, v in vals.items())


def synthesize_command(design, *, eps=None, as_json: bool = False) -> int:
    """Print the synthesis of a ``delay-feedback`` design; exit 0 if certified, else 1."""
    from ...report.markdown import fmt, md_table
    from .run import nominal_point, synthesise
    spec = design.spec
    if eps:
        if spec.synthesis.method != "free-weighting-003":
            from ...errors import DesignError
            raise DesignError("<cli>", "--eps", list(eps), "no --eps: the design's method "
                              f"{spec.synthesis.method!r} searches eps itself")
        spec = replace(spec, synthesis=replace(spec.synthesis, eps=tuple(eps)))
    model, values, op, A, B = nominal_point(spec)
    points = tuple(nominal_point(spec, v)[3:] for v in spec.vertices)
    if spec.synthesis.method == "requirements":
        from .requirements_render import requirements_table
        from .run import synthesise_requirements
        s = synthesise_requirements(spec, model, values, op, A, B, points)
        r = s.requirements
        ok = all(row.verdict == "PASS" for row in r.rows)
        if as_json:
            print(json.dumps({"design": design.name, **r.as_dict()}, indent=2))
        else:
            print(f"{design.name}: designed to requirements at {_op_text(spec, op)}")
            print(requirements_table(spec, r))
        return 0 if ok else 1
    s = replace(synthesise(spec, A, B, points), required=spec.delay.h_max,
                h_cap=spec.synthesis.settings.h_max)
    st = spec.synthesis.settings
    if spec.synthesis.method == "free-weighting-003":
        return print_sweep(design.name, f"{design.name}: problem (60) of paper 003 on the "
                           f"linearisation at {_op_text(spec, op)}", s.rows, st, as_json)
    from ...margins import exact_margin
    ex = exact_margin(A, B @ s.K) if s.K is not None else None
    ok = s.status == "certified"
    if as_json:
        inf = lambda x: "inf" if isinstance(x, float) and math.isinf(x) else x
        print(json.dumps({"design": design.name, "method": s.method, "eps": s.eps,
                          "h_certified": s.h_certified, "h_refuted": inf(s.h_refuted),
                          "K": None if s.K is None else s.K.tolist(), "h_gain": s.h_gain,
                          "h_analysis": s.h_analysis, "status": s.status,
                          "reason": s.reason,
                          "exact_margin": None if ex is None else inf(ex.h)}, indent=2))
        return 0 if ok else 1
    what = {"wirtinger": "Wirtinger synthesis (Seuret & Gouaisbaut 2013), eps searched",
            "bessel-legendre": "Wirtinger synthesis, gain certified by the Bessel-Legendre "
                               f"analysis of order N = {spec.synthesis.order}",
            "robust-descriptor": f"one gain over {len(points)} vertices (Jensen/descriptor "
                                 "synthesis), eps searched"}[s.method]
    print(f"{design.name}: {what}, at {_op_text(spec, op)}")
    cap = lambda h: "—" if h is None else (f">= {fmt(st.h_max, 4)} (cap)" if h >= st.h_max
                                           else fmt(h, 4))
    print(md_table(["method", "eps", "h_certified", "h_refuted", "K (canonical)",
                    "h certified by K", f"h, Bessel-Legendre N = {spec.synthesis.order}",
                    "h* (exact)", "status"],
                   [[s.method, fmt(s.eps, 3), cap(s.h_certified), fmt(s.h_refuted, 4),
                     gain_text(s.K, st.gain_digits), cap(s.h_gain), cap(s.h_analysis),
                     fmt(None if ex is None else ex.h, 4), s.status]], "lrrrlrrrl"))
    print("Certificate: " + ("for every constant delay in [0, h]" if s.all_delays else
                             "at the delay h (not for smaller delays; see the exact windows)")
          + ". K: canonical gain (minimum-norm certificate at "
          f"{fmt(st.gain_fraction)} x h_certified, {st.gain_digits} significant digits).")
    if s.reason:
        print(("Not certified: " if not ok else "Short of the design's delay range: ")
              + s.reason + ".")
    return 0 if ok else 1


def simulate_command(design, *, case: str | None, dt: float | None, as_json: bool,
                     csv: str | None = None, plot: str | None = None) -> int:
    """``workbench simulate`` of one scenario: its metrics (with ``csv`` its
    trajectory, :func:`trajectory_csv`; with ``plot`` a PNG of it); exit 0."""
    import time

    from ...errors import DesignError
    from ...report.markdown import fmt
    from .run import designed_gain, metrics, simulate
    spec = design.spec
    if not spec.scenarios:
        raise DesignError(design.path, "scenarios", "<missing>", "at least one [[scenarios]]")
    names = [s.name for s in spec.scenarios]
    if case is not None and case not in names:
        raise DesignError("<cli>", "--case", case, "one of " + ", ".join(names))
    sc = spec.scenarios[names.index(case) if case else 0]
    if dt is not None and not (math.isfinite(dt) and 0 < dt <= sc.t_end / 10):
        raise DesignError("<cli>", "--dt", dt, f"a step in (0, {sc.t_end / 10:g}] s")
    got = designed_gain(design, what="to simulate")
    if got is None:
        return 1
    model, values, op, A, B, s = got
    t0 = time.perf_counter()
    r = simulate(spec, model, values, op, s.K, sc, dt or sc.dt)
    wall = time.perf_counter() - t0
    m = metrics(spec, op, sc, r)
    if csv:
        from pathlib import Path

        from ...report.files import atomic_write
        atomic_write(Path(csv), trajectory_csv(spec, r))
    if plot:
        from pathlib import Path

        from ...report.figures import save_figure
        from ...report.markdown import Figure
        save_figure(Figure(Path(plot).stem, f"{design.name}: {sc.name}",
                           lambda fig: _draw_run(fig, spec, r), (8.0, 4.5)), Path(plot))
    return print_run({"design": design.name, "case": sc.name, "dt": dt or sc.dt,
                      "metrics": m, "wall_s": round(wall, 3)},
                     f"{design.name}: scenario {sc.name}, h = {fmt(sc.h)} s, dt = "
                     f"{fmt(dt or sc.dt)} s, K = "
                     f"{gain_text(s.K, spec.synthesis.settings.gain_digits)}", m, as_json)


def print_run(payload: dict, header: str, m: dict, as_json: bool) -> int:
    """The output of ``simulate``: ``payload`` as JSON, or ``header`` and the
    metrics ``m`` as a table; exit 0."""
    from ...report.markdown import fmt, md_table
    if as_json:
        print(json.dumps(payload, indent=2))
        return 0
    print(header)
    print(md_table(["metric", "value"], [[k, fmt(v, 6)] for k, v in m.items()], "lr"))
    return 0


def trajectory_csv(spec, r) -> str:
    """A simulated run as CSV: ``t`` (s), each state, each input as the
    controller outputs it at t (it acts h later), in the design's units, one
    row per recorded step (``repr`` floats: the file reads back bit for bit)."""
    from .run import input_history
    U = input_history(r, len(spec.plant.input_names))
    return csv_text(spec, r.t, r.x, U)


def csv_text(spec, t, x, u, phases=None) -> str:
    """Columns ``t``, the states, the inputs (and ``phase``, the names in
    ``phases``), ``repr`` floats: the CSV of ``simulate --csv``."""
    cols = ["t", *spec.plant.state_names, *spec.plant.input_names]
    rows = np.vstack([t, x, u]).T
    tail = [""] * len(t) if phases is None else [f",{p}" for p in phases]
    return ",".join(cols + ([] if phases is None else ["phase"])) + "\n" + "".join(
        ",".join(repr(float(v)) for v in row) + end + "\n" for row, end in zip(rows, tail))


def _draw_run(fig, spec, r) -> None:
    """States (top) and controller outputs (bottom) against time."""
    from .run import input_history
    U = input_history(r, len(spec.plant.input_names))
    for k, (rows, names, units) in enumerate((
            (r.x, spec.plant.state_names, [v.unit for v in spec.plant.states]),
            (U, spec.plant.input_names, [v.unit for v in spec.plant.inputs]))):
        ax = fig.add_subplot(2, 1, k + 1)
        for row, name, unit in zip(rows, names, units):
            ax.plot(r.t, row, label=f"{name} ({unit})")
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, alpha=0.3)
    ax.set_xlabel("t (s)")


def sweep_command(design, *, samples: int, seed: int, as_json: bool = False,
                  out: str | None = None, resume: bool = False) -> int:
    """``workbench sweep`` of a ``delay-feedback`` design with ``[montecarlo]``:
    its distributions with ``samples`` draws and ``seed``, on every scenario
    without a parameter schedule, the gain and operating point nominal
    (:func:`.montecarlo.run_montecarlo`, the report's path); prints the
    diverged runs and every metric's largest value; exit 0 (1 when no gain
    was certified).

    With ``out`` the runs are computed in chunks and written to
    ``out/<scenario>-chunk-NNNN.csv`` (one row per run: its drawn parameters
    and its metrics), ``resume`` skipping the chunks already there
    (:mod:`workbench.features.montecarlo_chunks`); the summary is read back from the
    files. A chunk's runs equal the one-batch sweep's up to the last bits of
    the gain's matrix product (the only operation not elementwise over runs)."""
    from pathlib import Path
    from types import SimpleNamespace

    from ..capabilities import sweep_draws
    from ...features.montecarlo_chunks import check_resume
    from .montecarlo import montecarlo_values, run_montecarlo
    from .run import designed_gain, predict, reference
    spec = replace(design.spec, montecarlo=sweep_draws(design, samples, seed, 2000))
    check_resume(out, resume)
    got = designed_gain(design, spec, "to sweep")
    if got is None:
        return 1
    model, values, op, A, B, s = got
    res = run_montecarlo(spec, model, values, op, s.K, reference, predict,
                         folder=Path(out) if out else None, design=design.name, resume=resume)
    q = montecarlo_values(SimpleNamespace(montecarlo=res))
    return print_run({"design": design.name, "samples": samples, "seed": seed,
                      "quantities": q},
                     f"{design.name}: Monte Carlo, {samples} runs per scenario, seed {seed}, "
                     f"K = {gain_text(s.K, spec.synthesis.settings.gain_digits)}",
                     {k: math.nan if v is None else v for k, v in q.items()}, as_json)
