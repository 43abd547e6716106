"""Sampled-data antiskid (issue 20): the laws of paper 003 run as a real
controller at a fixed rate f_c, inside the ``antiskid-run`` study.

Design table (optional; absent: no sampled section)::

    [sampled]
    case = "compensated"          # the [[cases]] entry whose controller is sampled
    rates_hz = [5.0, 10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1000.0, 2000.0, 5000.0]
    creep_margin = 0.001          # traction requirement lambda <= lambda_opt (1 + creep_margin)
    plant_step = 1e-4             # s, largest plant sub-step (mesh checked at its half)
    predictor_step = 1e-3         # s, the predictor steps over >= this many held samples
    bisect = 4                    # bisection steps on f_c below the lowest passing grid rate
    quantisation = { value = 8.0, unit = "N m", source = "..." }        # optional
    measurement_delay = { value = 0.002, unit = "s", source = "..." }   # optional

What a sampled controller is (:mod:`.antiskid_sampled_kernel`): the state
measured ``measurement_delay`` before each sample t_k = k / f_c, the law of
the case evaluated once with the printed hold (``sampling = "zoh"``, no
mismatch estimate), the torque rounded to a multiple of ``quantisation`` and
held until the next sample; the wheel receives it h later. The predictor
covers the known loop delay h + ``measurement_delay`` and steps through the
commands it sent, ``predictor_step`` at a time (whole samples, their exact
average). The plant is integrated on a mesh of sub-steps <= ``plant_step``
that does not depend on f_c.

Two scenarios per rate, each only as long as its requirement needs:
*traction* from the design's initial state until :data:`~.antiskid_sampled_kernel.TRACTION_TAIL` s
after the cruise law took over (requirement: no divergence, the cruise law
reached, lambda <= lambda_opt (1 + creep_margin) throughout); *braking* from
the cruise equilibrium (v_d, lambda_d) :data:`~.antiskid_sampled_kernel.BRAKING_LEAD` s before
t_brake, until v <= v_stop (requirement: the stop is reached without
divergence). Variants: ``zoh`` (exact, current samples, unquantised) and,
when the design gives a quantisation or a measurement delay, ``zoh_q_tau``.
The *emulation* row is the case's controller as the other sections run it
(every step of dt/2, the stiff hold with its mismatch estimate, the plant
stepped with the control step), in the same two scenarios.

The sweep is general (:mod:`workbench.features.rate_sweep`: the table's
general keys, the variants, the grid, the lowest passing rate and its
bisection bracket, the mesh check at ``plant_step`` / 2 up to
:data:`MESH_CHECK_MAX_HZ` within :data:`MESH_ATOL`, the three levels of every
claimed rate metric, the result, every run made once; its quantities and
claimed rate metrics: :mod:`workbench.features.rate_sweep_quantities`).
What stays here is paper 003's: the case, margin and predictor keys, the
kernel as the sweep's ``run`` callback and the metrics of a rate and their
tolerances (:func:`model`, :func:`rate_metrics`, :data:`SECTION`), the emulation as the reference, the traces' records, and the Radau windows
(:mod:`.antiskid_sampled_check`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from ...features import rate_sweep as RS
from ...features import rate_sweep_quantities as RQ
from .antiskid_sampled_check import RADAU_QUANTITIES, radau_checks, radau_quantities
from .antiskid_sampled_kernel import OUT, Context, run_once

#: Grid rates up to this (Hz) are run again at plant_step / 2.
MESH_CHECK_MAX_HZ = 1000.0
#: Largest difference between plant_step and plant_step / 2 for the mesh check.
MESH_ATOL = {"lam_max_over_opt": 2e-5, "t_cruise": 0.005, "braking_duration": 0.05,
             "stop_distance": 0.5, "lam_min_brake": 2e-4, "evs_max_tracking": 2e-4}
#: Metrics of a rate (quantities ``sampled.<variant>.rate[<f>].<metric>``).
RATE_METRICS = ("lam_max_over_opt", "time_above", "t_cruise", "u_max_over_peak",
                "braking_duration", "stop_distance", "lam_min_brake", "evs_max_tracking",
                "omega3_after_brake", "traction_ok", "braking_ok", "ok")
#: Scenario (0 traction, 1 braking) -> the rate metrics computed from its run alone (the
#: others need both).
NEEDS = {0: ("lam_max_over_opt", "time_above", "t_cruise", "traction_ok", "traction_diverged"),
         1: ("braking_duration", "stop_distance", "lam_min_brake", "evs_max_tracking",
             "omega3_after_brake", "braking_ok", "braking_diverged")}
#: Rates (Hz, those of the grid) and seconds of the traction traces of the figure.
TRACE_RATES_HZ, TRACE_SECONDS = (100.0, 1000.0), 4.0
#: Metrics compared between the highest grid rate and the emulation.
GAP_METRICS = ("lam_max_over_opt", "t_cruise", "braking_duration", "stop_distance")
#: Rate quantities that are a difference to the emulation -> the rate metric they move with
#: (the emulation does not depend on plant_step).
TO_EMULATION = {"stop_time_minus_emulation": "braking_duration",
                "stop_distance_minus_emulation": "stop_distance"}
#: The section's quantities (with those of the Radau check, :mod:`.antiskid_sampled_check`)
#: and the rate metrics its claims compare (a difference to the emulation counts as its rate
#: metric).
SECTION = RQ.Section("sampled", RATE_METRICS, MESH_CHECK_MAX_HZ, "emulation", GAP_METRICS,
                     TO_EMULATION, RADAU_QUANTITIES,
                     lambda res: radau_quantities(res.checks, res.lambda_opt))


@dataclass(frozen=True)
class SampledSpec(RS.SweepTable):
    """The design's ``[sampled]`` table (module docstring): the general keys
    (:class:`workbench.features.rate_sweep.SweepTable`), the case, the
    traction requirement's margin and the predictor's step."""

    case: str = ""
    creep_margin: float = 0.0
    predictor_step: float = 0.0


def load_sampled(root, case_names) -> SampledSpec | None:
    """Read ``[sampled]`` from a run design (a :class:`workbench.reader.Reader`);
    None when absent."""
    return RS.load_table(root, "sampled", SampledSpec, "N m", 1e-3, SECTION, lambda t: dict(
        case=t.string("case", choices=tuple(case_names)),
        creep_margin=t.number("creep_margin", nonneg=True, hi=0.1),
        predictor_step=t.number("predictor_step", positive=True, hi=0.1, what="number (s)")))


@dataclass(frozen=True)
class SampledResult(RS.SweepResult):
    """Everything the sampled section shows (:func:`run_sampled`): the
    sweep (the reference is the emulation at dt/2, the checks the Radau
    windows, the traces lambda / lambda_opt - 1 from the start of traction),
    lambda_opt and the peak adhesion torque."""

    lambda_opt: float = math.nan
    u_peak: float = math.nan


def rate_metrics(ctx: Context, trac: dict, brake: dict) -> dict:
    """:data:`RATE_METRICS` of one rate from its two runs (NaN: not reached)."""
    lo = ctx.cs.lambda_opt
    t_ok = (math.isnan(trac["t_diverged"]) and not math.isnan(trac["t_handover"])
            and trac["lam_max"] / lo <= 1 + ctx.margin)
    b_ok = math.isnan(brake["t_diverged"]) and not math.isnan(brake["t_stop"])
    div = not math.isnan(trac["t_diverged"])
    return {"lam_max_over_opt": math.nan if div else trac["lam_max"] / lo,
            "time_above": trac["time_above"], "t_cruise": trac["t_cruise"],
            "u_max_over_peak": max(trac["u_max_abs"], brake["u_max_abs"]) / ctx.u_peak,
            "braking_duration": brake["t_stop"] - ctx.t_brake,
            "stop_distance": brake["stop_distance"] if b_ok else math.nan,
            "lam_min_brake": brake["lam_min"] if b_ok else math.nan,
            "evs_max_tracking": brake["evs_max"],
            "omega3_after_brake": brake["t_omega3"] - ctx.t_brake,
            "traction_ok": "yes" if t_ok else "no", "braking_ok": "yes" if b_ok else "no",
            "ok": "yes" if t_ok and b_ok else "no",
            "traction_diverged": trac["t_diverged"], "braking_diverged": brake["t_diverged"]}


def model(ctx: Context, predictor_step: float, emulation: bool = False) -> tuple:
    """(runs, declarations) of the sampled controller, the model of
    :mod:`workbench.features.rate_sweep`: the memo of the kernel's runs
    (:func:`.antiskid_sampled_kernel.run_once`, its outputs; ``emulation``:
    of the case's own controller, every step) and :data:`RATE_METRICS` of
    a rate from its traction (0) and braking (1) runs (:func:`rate_metrics`;
    a scenario not run counts as NaN outputs)."""
    return (RS.Runs(lambda rate, s, q, tau, step: run_once(
        ctx, rate, s, q=q, tau=tau, dt_p=step, predictor_step=predictor_step,
        emulation=emulation)[0]),
        RS.RateMetrics(RATE_METRICS, (0, 1), lambda got: rate_metrics(ctx, got[0], got[1]),
                       NEEDS, MESH_ATOL, MESH_CHECK_MAX_HZ, OUT))


def run_sampled(spec: SampledSpec, ctx: Context, dt: float) -> SampledResult:
    """The sampled section of an ``antiskid-run`` design with ``[sampled]``
    (``ctx``: :func:`workbench.papers.p003.antiskid_run_spec.sampled_context`;
    ``dt``: the design's step, the emulation runs at dt/2): the emulation
    row, every variant (:func:`workbench.features.rate_sweep.sweep`),
    the traces of the figure, the Radau check (on the grid's runs and the
    traces' records)."""
    dt_e = dt / 2
    emu = RS.rate_row(*model(ctx, 0.0, emulation=True), 1.0 / dt_e, 0.0, 0.0, dt_e)
    runs, decl = model(ctx, spec.predictor_step)
    variants = RS.sweep(runs, decl, spec)
    recs = trace_records(ctx, spec, dt_e)
    shown = tuple(RS.Trace(name, f, rec[:, 0].copy(), rec[:, 2] / ctx.cs.lambda_opt - 1.0)
                  for name, f, rec in recs)
    zoh = {f: rec for name, f, rec in recs if name == "zoh"}
    return SampledResult(spec, emu, dt_e, variants, radau_checks(ctx, spec, runs, zoh), shown,
                         lambda_opt=ctx.cs.lambda_opt, u_peak=ctx.u_peak)


def trace_records(ctx: Context, spec: SampledSpec, dt_e: float) -> list:
    """[(variant, rate, mesh record), ...]: the first :data:`TRACE_SECONDS`
    of traction of each variant at :data:`TRACE_RATES_HZ` (grid rates only)
    and of the emulation (:func:`workbench.features.rate_sweep.trace_records`)."""
    def record(f, q, tau, step, reference):
        cap = int(TRACE_SECONDS / min(step, 1.0 / f)) * 3 + 16
        return run_once(ctx, f, 0, q=q, tau=tau, dt_p=step, emulation=reference,
                        predictor_step=0.0 if reference else spec.predictor_step,
                        record=(0.0, TRACE_SECONDS, cap), t_cap=TRACE_SECONDS)[1][0]
    return RS.trace_records(spec, TRACE_RATES_HZ, record, ("emulation", 1.0 / dt_e, dt_e))


#: The ``sampled.*`` quantities a design with ``[sampled]`` has (of its table) and their
#: values (of a :class:`SampledResult`).
sampled_quantity_names, sampled_quantities = SECTION.quantity_names, SECTION.quantities
