"""Monte Carlo robustness sweep of an ``antiskid-run`` design.

Samples (seeded, numpy ``SeedSequence``): plant mass factor, adhesion
between the wet and the dry curve (a, b, c interpolated with s in [0, 1]:
s = 0 wet, s = 1 dry), true input delay in [0, h_max] (the predictor keeps
the design's h), initial speed. Sample i is row i of one (n, 4) uniform draw,
so the first n runs of a larger sweep with the same seed have the same
parameters. Each worker simulates one chunk of samples as a batch (arrays,
one pass of the fixed-step loop) and returns plain lists; a local process
pool runs the chunks (:mod:`workbench.sim.batch`); progress goes to stderr.

A batch halves a step only for the runs that need it
(:func:`workbench.sim.wheel_slip.stiff_step`), so a run's metrics
do not depend on its chunk mates (up to rounding: the batch evaluates the
model with numpy, a single run with ``math``). The partition into chunks
depends on the sample count (and ``chunk``) only, never on the worker count.

The controller always uses the design's nominal model (dry rail, nominal
mass): the sweep measures robustness, not re-tuning.

One path (:func:`start_sweep`): a chunk is a pure function of (design,
gain, seed, sample range, step), :func:`range_worker`, which draws its own
samples (from ``start``), so a payload is a few kilobytes whatever the
sweep's size. The driver (chunks, pool or Dask, progress, ``.npz`` files
per chunk with ``workbench sweep --out DIR [--resume]``, the manifest) is
the general :func:`workbench.features.montecarlo_arrays.start_array_sweep`,
the draws :func:`workbench.features.montecarlo_draws.draw_runs` and the
statistics of the runs
:class:`workbench.features.montecarlo_stats.RunsResult`. A chunk file holds
``index``, ``draw.<name>``, ``raw.<field>`` (the :class:`RunMetrics` of
each run) and ``lambda_opt`` (of each run's adhesion curve); ``sweep.json``:
design, size, seed, chunking, step path, t_brake and a hash of the data
every run shares.

This module keeps what is paper 003's: what a run draws and how the draws
enter its plant (mass factor, wet-dry interpolation of the adhesion curve),
its kernel's payloads and call, what identifies its sweep, and its metrics
and outcomes (the creep ratio against each run's own lambda_opt). The
step-size check of the sweep's runs is
:mod:`workbench.papers.p003.antiskid_halving`; the rendering is
:mod:`workbench.papers.p003.antiskid_montecarlo_render`.
"""
from __future__ import annotations

from dataclasses import asdict
from typing import ClassVar

import numpy as np

from ...features.montecarlo_arrays import ArrayRuns, chunk_arrays, inputs_digest
from ...features.montecarlo_stats import OK, RunsResult, runs_quantities
from ...features.quantities import Part
from ...sim.batch import PendingBatch
from .antiskid_run_spec import SweepSpec

#: Summary statistics reported per metric. The time to the stop (v <= v_stop)
#: is not one: after omega <= 3 rad/s the desired creep speed steps to 0 and
#: the train coasts on running resistance, ~46 s per m/s of speed left when the
#: creep is released; that release is a transient at dt |J| ~ 40 which the
#: fixed step resolves for the nominal plant (the design's braking time agrees
#: with a refined mesh) but not for mismatched plants (dt / 2 moved it by up
#: to 13 s in the halving check). The stop itself is the ``not_stopped``
#: outcome; ``omega3_after_brake`` (the end of creep-controlled braking, the
#: paper's "about 350 s") is converged.
SUMMARY_METRICS = ("lam_max_over_opt", "t_cruise", "omega3_after_brake")

#: Checks counted per run: key -> what a violation means.
VIOLATIONS = {"above_lambda_opt": "creep ratio above the sample's lambda_opt in traction",
              "diverged": "diverged (|lambda| >= 0.9, torque out of range, or step not resolved)",
              "not_stopped": "not stopped by t_end"}

#: Outcomes reported as rates with their Wilson 95 % interval: the checks of
#: :data:`VIOLATIONS` and "ok" (none of them).
OUTCOMES = (*VIOLATIONS, OK)


class SweepResult(RunsResult):
    """The runs of a sweep (:class:`~workbench.features.montecarlo_stats.RunsResult`)
    with the paper's summary metrics and outcomes."""

    SUMMARY: ClassVar[tuple] = SUMMARY_METRICS
    OUTCOMES: ClassVar[tuple] = OUTCOMES


#: Quantities of a sweep run by the ``antiskid-run`` study (None: no finite
#: value): ``montecarlo.samples``, ``montecarlo.<metric>.<statistic>``,
#: ``montecarlo.fraction.<violation>`` and ``montecarlo.wilson.<outcome>.lo``
#: / ``.hi`` (the Wilson 95 % interval of an outcome's rate).
QUANTITIES = (Part(runs_quantities("montecarlo", SUMMARY_METRICS, VIOLATIONS, OUTCOMES),
                   lambda spec: spec.montecarlo is not None, lambda r: r.montecarlo),)


def draw_samples(n: int, seed: int, spec: SweepSpec, start: int = 0) -> dict:
    """Samples ``start <= i < n`` of (mass factor, adhesion s, delay h, v0),
    uniform, seeded; sample i does not depend on n or start. With a varying
    delay (``delay_variation``), also its period and phase (fraction of a
    period) per run, uniform, from the counter-based generator of
    (seed, run) (:mod:`workbench.sim.counter_rng`): the first four draws
    are those of the same design without perturbations."""
    from ...features.montecarlo_draws import draw_runs
    from ...sim.counter_rng import DELAY_PERIOD, DELAY_PHASE
    pt = spec.perturb
    varying = pt is not None and pt.delay_period is not None
    return draw_runs(n, seed, {"mass": spec.mass, "adhesion": spec.adhesion, "h": spec.h,
                               "v0": spec.v0}, start,
                     {"delay_period": (DELAY_PERIOD, pt.delay_period),
                      "delay_phase": (DELAY_PHASE, (0.0, 1.0))} if varying else None)


def chunk_worker(payload: dict) -> dict:
    """Simulate one chunk (plain data in, plain data out)."""
    from ...controllers.antiskid003_settings import ControllerSettings, CreepSpeedProfile
    from ...sim.wheel_slip import PARAM_ORDER
    from .antiskid_kernel import simulate_batch
    from .antiskid_scenario import RunSettings
    c = payload["controller"]       # asdict of the settings, tuples possibly as lists
    cs = ControllerSettings(**{**c, "profile": CreepSpeedProfile(**c["profile"]),
                               "params": tuple(c["params"]), "K": tuple(c["K"])})
    plant = tuple(np.asarray(payload["plant"][k], float) for k in PARAM_ORDER)
    run = RunSettings(plant, cs, np.asarray(payload["h"], float),
                      (np.asarray(payload["v0"], float), payload["lambda0"]),
                      payload["u_init"], payload["t_end"],
                      payload.get("perturb"))
    m = simulate_batch(run, payload["dt"], payload.get("kernel", "numpy"))
    return {"index": payload["index"], "metrics": {k: np.asarray(v, float).tolist()
                                                   for k, v in vars(m).items()}}


def sweep_inputs(design, samples: int, seed: int, K: tuple, start: int = 0) -> dict:
    """Runs ``start <= i < samples`` of the design's sweep with ``seed`` and
    the cruise gain ``K`` as plain data: ``draws``, per-run ``plant``
    parameters, the nominal values ``base``, the ``controller`` (``asdict``
    of the case's settings), the ``scenario`` and ``dt``."""
    from ...sim.wheel_slip import PARAM_ORDER
    from .antiskid_run_spec import controller_settings, plant_values

    spec = design.spec
    ms: SweepSpec = spec.montecarlo
    case = next(c for c in spec.cases if c.name == ms.case)
    cs = controller_settings(spec, K, case)
    draws = draw_samples(samples, seed, ms, start)
    base = plant_values(spec)
    plant = {k: np.full(samples - start, base[k], float) for k in PARAM_ORDER}
    s = draws["adhesion"]
    for k in ("a", "b", "c"):
        plant[k] = ms.wet[k] + s * (base[k] - ms.wet[k])
    plant["m"] = base["m"] * draws["mass"]
    return {"draws": draws, "plant": plant, "base": base, "controller": asdict(cs),
            "scenario": spec.scenario, "dt": ms.dt or spec.dt, "seed": seed,
            "run": np.arange(start, samples), "perturb": ms.perturb, "h_range": ms.h}


def chunk_payload(inp: dict, i0: int, i1: int, dt: float, kernel: str = "numpy") -> dict:
    """The :func:`chunk_worker` payload of runs ``i0 <= i < i1`` at step
    ``dt``, simulated by the ``kernel`` path
    (:data:`~workbench.papers.p003.antiskid_kernel.KERNELS`)."""
    sl, sc, d = slice(i0, i1), inp["scenario"], inp["draws"]
    out = {"index": i0, "kernel": kernel, "controller": inp["controller"],
           "plant": {k: v[sl].tolist() for k, v in inp["plant"].items()},
           "h": d["h"][sl].tolist(), "v0": d["v0"][sl].tolist(),
           "lambda0": sc["lambda0"], "u_init": sc["u_init"], "t_end": sc["t_end"], "dt": dt}
    pt = inp.get("perturb")
    if pt is not None:      # the sim's Perturbations of runs i0 <= i < i1
        from ...features.montecarlo_draws import hold_steps, stream_keys
        from ...sim.counter_rng import GRADE, NOISE_OMEGA, NOISE_V
        from ...sim.perturb import Perturbations
        run, varying = inp["run"][sl], pt.delay_period is not None
        wave = {k: tuple(d[k][sl].tolist()) if varying else ()
                for k in ("delay_period", "delay_phase")}
        out["perturb"] = Perturbations(
            tuple(run.tolist()),
            stream_keys(inp["seed"], {"v": NOISE_V, "omega": NOISE_OMEGA, "grade": GRADE}, run),
            noise_v=pt.noise_v, noise_omega=pt.noise_omega,
            noise_every=hold_steps(inp["dt"], dt),  # a run at dt / 2 sees the same noise
            grade=None if pt.gradient is None else tuple(g / 1000 for g in pt.gradient),
            segment=pt.segment, delay=tuple(inp["h_range"]) if varying else None,
            period=wave["delay_period"], phase=wave["delay_phase"])
    return out


def traction_slope():
    """d mu / d lambda of the traction curve (eq 6), lambdified once from the
    one sympy model: ``slope(lam, *params)``, parameters in ``PARAM_ORDER``."""
    from ...features.curve_peaks import slope_function
    from ...plants.adhesion import adhesion_model
    from ...sim.wheel_slip import PARAM_ORDER
    mdl = adhesion_model()
    return slope_function(mdl.mu_traction, mdl.lam, tuple(mdl.params[k] for k in PARAM_ORDER))


def lambda_opt_of(plant: dict) -> np.ndarray:
    """lambda_opt (argmax of mu on lambda > 0) of each run's own adhesion
    curve: the root of d mu / d lambda on (0, 1)
    (:func:`workbench.features.curve_peaks.peaks`), as
    :meth:`~workbench.plants.adhesion.NumericAdhesion.lambda_opt` (same
    bracket and tolerances)."""
    from ...features.curve_peaks import peaks
    from ...sim.wheel_slip import PARAM_ORDER
    return peaks(traction_slope(), [plant[k] for k in PARAM_ORDER], 1e-12, 1.0, "adhesion curve")


def per_run(raw: dict, lam_opt: np.ndarray, t_brake: float) -> tuple[dict, dict]:
    """(metrics, violations) per run, as arrays, from a batch's raw
    :class:`~workbench.papers.p003.antiskid_scenario.RunMetrics` arrays
    (those of :data:`RUNS`)."""
    from ...controllers.antiskid003_settings import BRAKE_IN
    # the max over the phase a run diverged in is where the test fired
    in_traction = raw["phase_diverged"] < BRAKE_IN      # NaN (not diverged): False
    metrics = {"lam_max_over_opt": np.where(in_traction, np.nan,
                                            raw["lam_max_traction"] / lam_opt),
               "t_cruise": raw["t_cruise"],
               "omega3_after_brake": raw["t_omega3"] - t_brake,
               "t_diverged": raw["t_diverged"],
               "phase_diverged": raw["phase_diverged"]}
    viol = {"above_lambda_opt": raw["lam_max_traction"] > lam_opt * 1.001,
            "diverged": np.isfinite(raw["t_diverged"]),
            "not_stopped": ~np.isfinite(raw["t_stop"])}
    return metrics, viol


def range_worker(payload: dict) -> dict:
    """Simulate runs ``i0 <= i < i1`` of a design's sweep (payload: design,
    K, seed, i0, i1, kernel; ``step``: the step if not the sweep's) and
    return the arrays of its chunk (module docstring)."""
    d, i0, i1 = payload["design"], payload["i0"], payload["i1"]
    inp = sweep_inputs(d, i1, payload["seed"], payload["K"], start=i0)
    out = chunk_worker(chunk_payload(inp, 0, i1 - i0, payload.get("step") or inp["dt"],
                                     payload["kernel"]))
    return chunk_arrays(i0, i1, inp["draws"], out["metrics"],
                        lambda_opt=lambda_opt_of(inp["plant"]))


def range_payload(design, seed: int, K: tuple | None = None, kernel: str | None = None):
    """(K, kernel, payload) of a design's runs by :func:`range_worker`: the
    cruise gain (``K``, default
    :func:`~workbench.papers.p003.antiskid_run_spec.gain_for`), the stepping
    path (``kernel``, default compiled when numba is installed) and
    ``payload(i0, i1, step=None)`` of runs ``i0 <= i < i1`` at ``step``
    (None: the sweep's)."""
    from .antiskid_kernel import default_kernel
    from .antiskid_run_spec import gain_for
    K = tuple(gain_for(design.spec)[0] if K is None else K)
    kernel = kernel or default_kernel()
    return K, kernel, lambda i0, i1, step=None: {"design": design, "K": K, "seed": seed,
                                                 "i0": i0, "i1": i1, "kernel": kernel,
                                                 "step": step}


#: How a sweep's runs are made from its chunk arrays: :func:`per_run` of the
#: raw metrics it needs and each run's ``lambda_opt``, with the scenario's
#: ``t_brake`` (``RUNS.runs(arrays, t_brake)``: metrics and violations).
RUNS = ArrayRuns(per_run, ("lam_max_traction", "t_cruise", "t_omega3", "t_diverged",
                           "phase_diverged", "t_stop"), ("lambda_opt",), SweepResult)


def _manifest(design, samples: int, seed: int, chunk: int, kernel: str, K) -> dict:
    """What identifies a streamed sweep (its folder's ``sweep.json``)."""
    ms = design.spec.montecarlo
    inp = sweep_inputs(design, 1, seed, K)      # the data every run shares
    shared = {k: inp[k] for k in ("base", "controller", "scenario", "dt")}
    shared["ranges"] = [ms.mass, ms.adhesion, ms.h, ms.v0, sorted(ms.wet.items())]
    if ms.perturb is not None:      # absent: the digest of a sweep without perturbations
        shared["perturb"] = ms.perturb
    return {"design": design.name, "samples": samples, "seed": seed, "chunk": chunk,
            "kernel": kernel, "t_brake": inp["scenario"]["t_brake"],
            "inputs_sha256": inputs_digest(shared)}


def start_sweep(design, samples: int, seed: int, *, workers: int | None = None,
                chunk: int | None = None, pool: bool | None = None,
                K: tuple | None = None, kernel: str | None = None,
                scheduler: str | None = None, out=None, resume: bool = False) -> PendingBatch:
    """Start the Monte Carlo sweep of an ``antiskid-run`` design (with a
    ``[montecarlo]`` table): the general
    :func:`~workbench.features.montecarlo_arrays.start_array_sweep` of
    :func:`range_worker` (``workers``, ``chunk``, ``pool``, ``scheduler``,
    ``out``, ``resume`` as there; the results depend on ``chunk``, not on
    the workers, the executor or the chunking of a resumed sweep,
    ``tests/test_sweep_executors.py``); :meth:`PendingBatch.result` returns
    its :class:`SweepResult`.

    ``K``: the cruise gain if the caller has it (default:
    :func:`~workbench.papers.p003.antiskid_run.gain_for`). ``kernel``:
    ``"compiled"`` or ``"numpy"``, the stepping path (default: compiled when
    numba is installed); the results agree to rounding
    (``tests/test_compiled_kernel.py``).
    """
    from .antiskid_kernel import compile_kernel
    K, kernel, payload = range_payload(design, seed, K, kernel)
    return RUNS.start(range_worker, payload, samples, (design.spec.scenario["t_brake"],),
                      chunk=chunk, workers=workers, pool=pool, scheduler=scheduler,
                      before_pool=compile_kernel if kernel == "compiled" else None, out=out,
                      manifest=lambda ch: _manifest(design, samples, seed, ch, kernel, K),
                      resume=resume)


def load_sweep(out) -> SweepResult:
    """The :class:`SweepResult` of a streamed sweep, from its chunk files
    (only the columns the summaries use are read)."""
    return RUNS.load(out, lambda manifest: (float(manifest["t_brake"]),))


def sweep(design, samples: int, seed: int, *, progress: bool = True, **kw) -> SweepResult:
    """Run the Monte Carlo sweep of an ``antiskid-run`` design in memory
    (:func:`start_sweep`, the same keywords ``kw``), a progress bar on stderr
    when ``progress``."""
    return start_sweep(design, samples, seed, **kw).result(progress)
