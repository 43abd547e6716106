"""Markdown and figures of paper 004's retuning, sensor
faults and Monte Carlo (pure rendering of a
:class:`~workbench.papers.p004.closed_loop_brake.Result004`)."""
from __future__ import annotations

from ...kinds.stop_accuracy.loop_damping import loop_values
from ...kinds.stop_accuracy.render import (mc_figure, mc_section, plot_case_bars,
                                           plot_constant_sweep)
from ...report.markdown import Figure, fmt, md_table
from .closed_loop_brake_run import MC_MODES, faults

MODE_LABEL = {"ato-open": "ATO open loop", "closed": "closed loop (analogue)"}


def retune_section(spec, res) -> str:
    """``## Retuned closed loop``: the horizon, the PID's damping, the nominal corner."""
    p, loop = {k: q.value for k, q in spec.params.items()}, loop_values(spec, "closed")
    rows = [[fmt(s), fmt(res.stop(s), 3), fmt(res.stop(s, channel="3bit"), 3),
             fmt(res.stop(s, "ato-open"), 3)] for s in res.distance]
    d = res.damping
    return (
        "## Retuned closed loop (nominal corner)\n\n"
        f"The ATO evaluates a_req = v_p² / (2 d_p) at the state predicted t_predict = "
        f"{fmt(spec.constants['t_p'].value, 3)} s ahead: the brake's dead time plus lag, T1 + T2 = "
        f"{fmt(p['T1'] + p['T2'], 3)} s, the delay with which a dead time and a first-order lag "
        "follow a ramp. Before, 0.5 s: less than the dead time alone, so the loop reacted to the "
        "end of the stop only once it could no longer change it. The deceleration PID (kp "
        f"{fmt(loop['kp'])}, ki {fmt(loop['ki'])}) is kept: on its linearised loop "
        "(electric stage, dead time T1 plus one control period, the measurement filter; "
        "`workbench/studies/pid_tuning.py`) its dominant roots have damping ratio "
        f"{fmt(d.zeta, 2)} (decay rate {fmt(-d.alpha, 2)} 1/s), the criterion of paper 000's "
        "PID (ζ ≥ 0.7) holds; the miss was the horizon, not the loop.\n\n"
        "Stop error at the nominal corner (m, + = overshoot):\n\n"
        + md_table(["km/h", "closed loop, analogue", "closed loop, 3-bit", "ATO open loop"],
                   rows, "rrrr")
        + f"\n\nThe residual overshoot is the hand-over from the electric to the air stage "
        f"(at {fmt(3.6 * p['v_ho'], 3)} km/h): the air stage's lag T4 = {fmt(p['T4'])} s is "
        "longer than the electric one, so the achieved deceleration dips in the last metres and "
        "deceleration feedback can only react to the dip, not anticipate it (compare the "
        "model-based terminal phase of designs/stopping-line5.toml). The figure sweeps the "
        "horizon at the nominal corner.\n\n![horizon sweep]({figdir}/horizon-sweep.png)")


def fault_text(spec) -> str:
    loop = loop_values(spec, "closed")
    return ("Axle states: o = healthy, s = sliding (reads "
            f"{fmt(100 * loop['slide_ratio'])} % low), f = failed (reads 0), h = reads high (× "
            f"{fmt(loop['high_ratio'])}, e.g. a wheel diameter set too large), z = stuck at its "
            "reading when braking starts. Train speed = max of the four; the command generator "
            "detects s and f (all four: fallback to the ATO open loop), not h or z. The ATO's "
            "own position and speed are not from these sensors. A sensor reading high or stuck "
            "high wins the max-of-4 selection: the reading-high case only scales the measured "
            "deceleration, which the ATO's outer loop re-commands; the stuck one freezes the "
            "measured speed, the loop sees no deceleration and winds the command up to full "
            "service.\n\n![sensor faults]({figdir}/sensor-faults.png)")


def monte_carlo(spec, res) -> str:
    """``## Monte Carlo``: both modes at both speeds over the same draws."""
    return mc_section(
        spec, "##", "), the same draws for both modes and both speeds, analogue channel, "
        "healthy sensors; the stopping point D is the nominal one of each speed.",
        [((fmt(s), MODE_LABEL[m]), st) for (s, m), st in res.mc.items()], heads=("km/h", "mode"),
        align="rl", unit="m", error=lambda x: fmt(x, 3), alt="Monte Carlo")


def figures(spec, res) -> tuple[Figure, ...]:
    axles = faults(spec)
    return (Figure("horizon-sweep", "Closed-loop stop error at the nominal corner against the "
                   "ATO's prediction horizon.", lambda fig: plot_constant_sweep(
                       fig.add_subplot(111), res.sweep, list(res.distance), res.tolerance,
                       chosen=spec.constants["t_p"].value, chosen_label="chosen: T1 + T2",
                       xlabel="ATO prediction horizon t_predict (s)"), size=(6.4, 3.6)),
            Figure("sensor-faults", "Stop error per axle-sensor case, nominal corner.",
                   lambda fig: plot_case_bars(
                       fig.add_subplot(111), [f"{c} ({a})" for c, a in axles.items()],
                       [(f"{fmt(s)} km/h", [res.stop(s, fault=f) for f in axles])
                        for s in res.distance], res.tolerance, linthresh=0.3), size=(7.0, 3.8)),
            mc_figure("Monte Carlo stop errors per speed and mode.", [
                (f"{fmt(s)} km/h", [(MODE_LABEL[m], res.mc[s, m].errors) for m in MC_MODES])
                for s in sorted({s for s, _ in res.mc})], res.tolerance, (7.0, 3.8)))
