"""A parameter-recovery study: synthetic logs from known parameters, two fits, truth.

Design tables read by :func:`read_recovery`: ``[[logs]]`` (initial output,
``duration``, ``step_times``, ``step_levels``), ``[noise]`` (``dt_log``,
``speed_sd``, ``quantum``, ``seed``) and ``[fit]`` (``flies``, ``iterations``,
``dt`` dividing ``dt_log``, ``[fit.bounds]`` one [lo, hi] per fitted name).
:func:`recover` generates the logs from the model's ``simulate`` callback at the
true parameters (:mod:`workbench.features.param_fit`), fits them with the fruit
fly and with differential evolution, and :func:`recovery_rows` tabulates the
recovered values against the truth. The model and its wording stay with the
caller (e.g. paper 000's brake fit); tested on a first-order lag with dead time.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..reader import Reader
from ..report.markdown import fmt, md_table
from .param_fit import FitResult, fit, pooled_rmse, synthetic_log

#: The two optimisers of a recovery study and their table headings.
METHODS = (("foa", "fruit fly"), ("de", "diff. evolution"))


@dataclass(frozen=True)
class RecoverySpec:
    """Logs, noise and optimiser settings of a recovery study (units of the model)."""

    logs: tuple          # (y0, duration, steps)
    dt_log: float
    noise_sd: float
    quantum: float
    seed: int
    bounds: np.ndarray   # one [lo, hi] row per fitted name
    flies: int
    iterations: int
    dt: float            # integration step of the model, dividing dt_log


def read_recovery(root: Reader, names: tuple, y0: Callable[[Reader], float],
                  commands: str = "commands") -> RecoverySpec:
    """Read ``[[logs]]``, ``[noise]`` and ``[fit]``; ``y0`` reads a log's initial output,
    ``commands`` names the step levels (with their unit) in error messages."""
    logs = []
    for lg in root.tables("logs"):
        start = y0(lg)
        dur = lg.number("duration", positive=True, hi=200.0)
        times = lg.numbers("step_times", what="times (s)")
        levels = lg.numbers("step_levels", what=commands)
        if len(times) != len(levels):
            raise lg.fail("step_levels", list(levels), f"{len(times)} levels, one per step time")
        logs.append((start, dur, tuple(zip(times, levels))))
        lg.finish()
    if not logs:
        raise root.fail("logs", [], "at least one [[logs]] entry")
    nz = root.table("noise")
    noise = (nz.number("dt_log", positive=True), nz.number("speed_sd", nonneg=True),
             nz.number("quantum", positive=True), nz.number("seed", integer=True, lo=0))
    nz.finish()
    ft = root.table("fit")
    b = ft.table("bounds")
    bounds = []
    for k in names:
        lo, hi = b.numbers(k, positive=True, what="bounds [lo, hi]")
        if not lo < hi:
            raise b.fail(k, [lo, hi], "two bounds [lo, hi] with lo < hi")
        bounds.append((lo, hi))
    b.finish()
    flies = ft.number("flies", integer=True, lo=4, hi=1000)
    iterations = ft.number("iterations", integer=True, lo=1, hi=10000)
    dt = ft.number("dt", positive=True, hi=0.1)
    if abs(noise[0] / dt - round(noise[0] / dt)) > 1e-9:
        raise ft.fail("dt", dt, "a step dividing noise.dt_log")
    ft.finish()
    return RecoverySpec(tuple(logs), *noise, np.array(bounds), flies, iterations, dt)


@dataclass(frozen=True)
class Recovery:
    """Truth, synthetic logs, the two fits and the RMSE at the truth (noise floor)."""

    truth: dict
    logs: tuple
    foa: FitResult
    de: FitResult
    rmse_truth: float


def recover(simulate: Callable, truth: dict, spec: RecoverySpec, *,
            floor: float | None = None, scale: float = 1.0) -> Recovery:
    """Generate the logs of ``spec`` at ``truth`` (name -> value) and fit them twice.

    ``simulate(values, log)`` is the model (see :mod:`~workbench.features.param_fit`);
    noisy outputs are clipped at ``floor``; RMSEs are reported times ``scale``.
    """
    row = np.array(list(truth.values()))
    seeds = np.random.SeedSequence(spec.seed).generate_state(len(spec.logs) + 2)
    logs = tuple(synthetic_log(simulate, row, steps, y0=y0, duration=dur, dt_log=spec.dt_log,
                               noise_sd=spec.noise_sd, quantum=spec.quantum, seed=int(sd),
                               floor=floor)
                 for (y0, dur, steps), sd in zip(spec.logs, seeds))
    fits = [fit(simulate, list(logs), spec.bounds, method=m, seed=int(sd), flies=spec.flies,
                iterations=spec.iterations, scale=scale)
            for (m, _), sd in zip(METHODS, seeds[-2:])]
    return Recovery(dict(truth), logs, *fits,
                    float(pooled_rmse(simulate, np.array([row]), list(logs), scale)[0]))


def fit_values(rec: Recovery, method: str) -> dict:
    """name -> value fitted by ``method`` ("foa" or "de")."""
    return dict(zip(rec.truth, getattr(rec, method).values))


def relative_errors(rec: Recovery, method: str, derived: Callable = dict) -> dict:
    """name -> fitted / true - 1 of ``method``, over ``derived(values)`` (e.g. + ratios)."""
    got, tru = derived(fit_values(rec, method)), derived(rec.truth)
    return {k: got[k] / tru[k] - 1 for k in got}


def fit_json(rec: Recovery, method: str, rmse_key: str = "rmse") -> dict:
    """JSON of one fit: fitted values, RMSE (under ``rmse_key``), model runs."""
    r = getattr(rec, method)
    return {"values": fit_values(rec, method), rmse_key: r.rmse, "evaluations": r.evaluations}


def recovery_table(rec: Recovery, derived: Callable = dict, rmse_label: str = "RMSE") -> str:
    """Markdown table: true value, each fit and its error % per name of ``derived``,
    then the RMSEs (``rmse_label``) and the model runs of each fit."""
    tru = derived(rec.truth)
    rows = []
    for k in tru:
        row = [k, fmt(tru[k], 5)]
        for m, _ in METHODS:
            row += [fmt(derived(fit_values(rec, m))[k], 5),
                    fmt(100 * relative_errors(rec, m, derived)[k], 3)]
        rows.append(row)
    rows.append([rmse_label, fmt(rec.rmse_truth, 4), fmt(rec.foa.rmse, 4), "",
                 fmt(rec.de.rmse, 4), ""])
    rows.append(["model runs", "", str(rec.foa.evaluations), "", str(rec.de.evaluations), ""])
    head = ["parameter", "true"]
    for _, label in METHODS:
        head += [label, "error %"]
    return md_table(head, rows, "l" + "r" * (len(head) - 1))


def compare(rec: Recovery, simulate: Callable, reference: Callable, ref_row: np.ndarray,
            scale: float = 1.0) -> tuple[float, tuple]:
    """RMSE (times ``scale``) of a ``reference`` model at ``ref_row`` (not fitted) on the
    logs, and per log the curves (t, logged, fruit-fly fit, reference)."""
    err = float(pooled_rmse(reference, np.array([ref_row]), list(rec.logs), scale)[0])
    return err, tuple((lg.t, lg.output, simulate(np.array([rec.foa.values]), lg)[0],
                       reference(np.array([ref_row]), lg)[0]) for lg in rec.logs)


def plot_curves(ax, curves: tuple, labels: tuple, scale: float = 1.0, *,
                ylabel: str | None = None) -> None:
    """Per log of :func:`compare`: logged dots, fitted line, reference dashed line.

    ``labels`` are three formats of the log number ``{i}`` (logged, fitted, reference).
    With ``ylabel`` (the output times ``scale``, with its unit) the axes are
    labelled (time in s) and the legend drawn.
    """
    for i, (t, *ys) in enumerate(curves):
        for y, style, label in zip(ys, (".", "-", "--"), labels):
            ax.plot(t, y * scale, style, color=f"C{i}", label=label.format(i=i + 1),
                    **({"ms": 2} if style == "." else {"lw": 1}))
    if ylabel is not None:
        ax.set_xlabel("time (s)")
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=7)
