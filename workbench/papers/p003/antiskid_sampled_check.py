"""Independent check of the sampled runs' plant integration against scipy's
Radau (issue 20).

The sampled loop (:mod:`.antiskid_sampled_kernel`) integrates the plant by
exponential-Euler sub-steps of at most ``plant_step``. Here the torque the
wheel received in a window of a run (piecewise constant: the held,
delayed commands) is replayed open loop into scipy's Radau and both
trajectories are compared at every mesh point of the window (the general
replay of windows of runs: :func:`workbench.features.mesh_replay.replay_windows`,
placed by :func:`~workbench.features.mesh_replay.sample_windows`, reusing the
figure's records by :func:`~workbench.features.mesh_replay.reusing`).
What stays here is paper 003's: where the windows are, the tolerances, the
kernel's recording. The right-hand side is the plant's
(:func:`workbench.sim.wheel_slip.held_torque_rhs`: the lambdified sympy
model, the traction form for lambda >= 0, the braking form otherwise), not a
retyped one.

Windows (:data:`WINDOWS`): the start of traction, from the arrival of the
first command at t = h (3 m/s: the creep ratio's time constant ~ v/4000 s is
about 1 ms), braking where the wheel speed
reaches 3 rad/s (v ~ 1.3 m/s) and the last part of the stop (v -> v_stop,
time constant ~ 10 microseconds), each at the rates :data:`RADAU_RATES_HZ`
of the ``zoh`` variant.
"""
from __future__ import annotations

from ...features.mesh_replay import largest, replay_windows, reusing, sample_windows
from ...sim.wheel_slip import held_torque_rhs
from .antiskid_sampled_kernel import run_once

#: Rates (Hz) of the check (those of the design's grid).
RADAU_RATES_HZ = (100.0, 1000.0)
#: Names of the windows (module docstring); each is :data:`WINDOW_SAMPLES` samples long.
WINDOWS = ("traction start", "braking at omega = 3 rad/s", "braking, last stretch to the stop")
#: Length of a window in samples of its rate (0.4 s at 100 Hz, 40 ms at 1 kHz).
WINDOW_SAMPLES = 40
#: solve_ivp tolerances: rtol, and atol of (v, lambda).
RTOL, ATOL = 1e-10, (1e-10, 1e-13)
#: Quantities of the check.
RADAU_QUANTITIES = ("sampled.radau.max_dlam_over_opt", "sampled.radau.max_dv_rel",
                    "sampled.radau.windows")


def radau_checks(ctx, spec, runs, traction: dict) -> tuple:
    """:class:`workbench.features.mesh_replay.WindowCheck` (key: the rate;
    range: of v) of every window at every rate of
    :data:`RADAU_RATES_HZ` in the design's grid (``zoh``, unquantised).

    ``runs``: the section's :class:`workbench.features.rate_sweep.Runs` (the
    grid's braking run locates the braking windows); ``traction``: rate ->
    mesh record of the first seconds of the ``zoh`` traction run from t = 0
    (the figure's traces), which holds the traction window. Both braking
    windows come from one recorded run; the kernel's mesh before the end of a
    record does not depend on where the run or the record ends, so the
    windows are those of separate runs (issue 36)."""
    out = []
    for rate in (f for f in RADAU_RATES_HZ if f in spec.rates):
        kw = dict(dt_p=spec.plant_step, predictor_step=spec.predictor_step)
        brake = runs(rate, 1, 0.0, 0.0, spec.plant_step)
        length = WINDOW_SAMPLES / rate
        # the traction window starts and ends on sample times (h, h + 40 samples): every
        # window starts and ends half a mesh step earlier (issue 36 item 5)
        wins = sample_windows(WINDOWS, (ctx.h, brake["t_omega3"] - length / 2,
                                        brake["t_stop"] - length), (0, 1, 1), length,
                              0.5 * min(spec.plant_step, 1.0 / rate))

        def record(scen, a, b, rate=rate, kw=kw):
            cap = int((b - a) / spec.plant_step * 1.5) + 4 * int((b - a) * rate) + 16
            return run_once(ctx, rate, scen, record=(a, b, cap), **kw)[1][0]
        # the traces' record holds the traction window when it runs on past b + 2 samples
        # (the stretch holding b ends by b + 1 / rate)
        record = reusing({0: traction.get(rate)}, record, 2 / rate)
        out += [w.check(rate) for w in replay_windows(held_torque_rhs(ctx.plant), wins, record,
                                                         RTOL, ATOL)]
    return tuple(out)


def radau_quantities(checks, lambda_opt: float) -> dict:
    """The :data:`RADAU_QUANTITIES`: the largest difference of lambda over
    lambda_opt, of v relative, the windows (None without a check)."""
    if not checks:
        return dict.fromkeys(RADAU_QUANTITIES)
    d_abs, d_rel = largest(checks)
    return dict(zip(RADAU_QUANTITIES, (d_abs[1] / lambda_opt, d_rel[0], len(checks))))
