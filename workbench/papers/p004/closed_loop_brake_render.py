"""Markdown and figures of paper 004's closed-loop brake
(designs/closed-loop-brake-004.toml, ``[analysis] module =
"p004.closed_loop_brake"``): pure rendering, in the paper's wording."""
from __future__ import annotations

import sympy as sp

from ...kinds.stop_accuracy.grid_map import GridAxis, plot_grid_map, result_cell
from ...kinds.stop_accuracy.loop_damping import loop_values
from ...kinds.stop_accuracy.quantities import feasible
from ...kinds.stop_accuracy.render import corner_rows, plot_speed_distance, quantity_table
from ...kinds.stop_accuracy.run import speed_key
from ...report.markdown import Figure, Rendered, fmt, md_table
from .closed_loop_brake_fair_render import fault_text, figures, monte_carlo, retune_section
from .closed_loop_brake_run import ELECTRIC_LOSS, FACTORS, MODES, RUNS, faults
from .closed_loop_brake_spec import worked_formulas

MODE_TEXT = {"open": "open loop, single command",
             "ato-open": "open loop + ATO re-commands (a_req sent as the brake demand: no "
                         "gradient feed-forward, brake only)",
             "closed": "closed deceleration loop"}


def _worked_section(res, spec) -> str:
    _, distance, degraded, share = worked_formulas()
    w = res.worked
    rows = [["d1: 50 km/h at a_full, v as printed", fmt(w["d1"], 8), "m"],
            [f"d1 from exact 50 km/h ({fmt(50 / 3.6, 5)} m/s)", fmt(w["d1_exact_speed"], 8), "m"],
            ["a2: -15 % force, 15 ‰ down-grade", fmt(w["a2"], 6), "m/s²"],
            ["d2 at a2", fmt(w["d2"], 8), "m"],
            ["d2 − d1", fmt(w["delta"], 6), "m"],
            ["d2 − d1 with a2 rounded to 0.703", fmt(w["delta_rounded_inputs"], 6), "m"],
            ["d2 − d1 from exact 50 km/h", fmt(w["delta_exact_speed"], 6), "m"]]
    rows += [[f"grade share: {k.split('[')[1].rstrip(']').replace('permille,', ' ‰ of ')} × full",
              fmt(v, 5), "%"] for k, v in w.items() if k.startswith("share")]
    return ("## Worked numbers (paper 004, section 1.3)\n\nComputed from the sympy expressions "
            f"$d = {sp.latex(distance)}$, $a_2 = {sp.latex(degraded)}$ and the gradient share "
            f"${sp.latex(share)}$ (i in ‰), with the printed inputs (claims below compare the "
            "printed results).\n\n" + md_table(["quantity", "value", "unit"], rows, "lrl"))


def render(design, res) -> Rendered:
    spec, loop = design.spec, loop_values(design.spec, "closed")
    grid = dict(spec.grid)
    sections = [
        "## Problem\n\nPaper 004 argues qualitatively that closing the loop on the measured "
        "deceleration cancels force errors, gradient and friction scatter; it gives no "
        "dynamics, gains or simulations. Here the brake is paper 000's electro-pneumatic "
        f"model (parameters below), the train brakes from {', '.join(fmt(s) for s in spec.speeds_kmh)} "
        f"km/h to a stopping point D = the nominal open-loop stopping distance of the single "
        f"command {fmt(spec.command)} m/s² (D = "
        + ", ".join(f"{fmt(d, 5)} m" for d in res.distance.values())
        + "), over the grid force error "
        f"{list(grid['force_error'])} × gradient {list(grid['gradient'])} ‰ × air-brake "
        f"friction factor {list(grid['friction'])}. Modes: "
        + "; ".join(f"**{m}** = {MODE_TEXT[m]}" for m in MODES)
        + ". The ATO's required deceleration is a_req = v_p² / (2 d_p) at the state predicted "
        f"{fmt(spec.constants['t_p'].value)} s ahead; the closed loop measures the deceleration "
        "from the maximum of four axle speeds (filtered derivative), uses the incremental fuzzy "
        f"controller when |a_req − a_meas| > {fmt(loop['e_switch'])} m/s² and PID below, and "
        "falls back to the ATO open loop when all four axles are failed or sliding. The "
        f"3-bit channel sends round(7 c / {fmt(spec.c_max)}) levels.\n\n"
        + quantity_table("parameter", spec.params, 5),
        _worked_section(res, spec),
        retune_section(spec, res),
    ]
    rows, kv, n = [], res.kind_values, len(res.corners())
    for s in res.distance:
        for (m, ch), c in RUNS.items():
            q = f"{speed_key(s)}.{c}.grid."
            rows.append([fmt(s), m, ch, fmt(kv[q + "max_abs_m"], 3),
                         f"{kv[q + 'failing_corners']:g} / {n}",
                         f"{kv[q + 'failing_feasible_corners']:g}"])
    n_inf = sum(not ok for s in res.distance for ok in feasible(res.kind, s)) // max(
        len(res.distance), 1)
    sections.append(
        f"## Error grid: stop error against the ±{fmt(res.tolerance)} m window\n\n"
        + md_table(["km/h", "mode", "channel", "max |error| (m)", "corners outside ±"
                    f"{fmt(res.tolerance)} m", "of them feasible"], rows, "rllrrr")
        + f"\n\n*Feasible*: full service applied from the first instant stops at least "
        f"{fmt(res.tolerance)} m short of D on that corner (simulated); {n_inf} of the corners "
        "per speed are not, and no brake controller can stop at D there. The map shows the "
        "closed loop's error per corner.\n\n![error grid]({figdir}/error-grid.png)\n\n"
        + _corner_details(res))
    frows = []
    for s in res.distance:
        for f, axles in faults(spec).items():
            frows.append([fmt(s), f, axles, fmt(res.stop(s, fault=f), 3),
                          "fallback (ATO open loop)" if all(c in "sf" for c in axles)
                          else "closed, fault undetected" if set(axles) & set("hz")
                          else "closed"])
        for m in ("ato-open", "closed"):
            frows.append([fmt(s), f"electric brake lost ({m})", "oooo",
                          fmt(res.stop(s, m, fault=ELECTRIC_LOSS), 3), m])
    sections.append(
        "## Sensor faults and electric-brake loss (nominal corner)\n\n"
        + md_table(["km/h", "case", "axles", "stop error (m)", "loop"], frows, "rllrl")
        + "\n\n" + fault_text(spec))
    sections.append("## Speed against distance\n\nFrom " + fmt(spec.speeds_kmh[0]) + " km/h at "
                    "the nominal corner and with the lowest force error (gradient 0, friction ×1)."
                    "\n\n![curves]({figdir}/speed-distance.png)")
    sections.append(monte_carlo(spec, res))
    figs = (Figure("speed-distance", "Speed against position relative to the stopping point.",
                   lambda fig: plot_speed_distance(fig, [(f"force error {fmt(100 * fe)} %", [
                       (f"{m} ({ch})", dx, v) for m, ch, f, dx, v in res.curves if f == fe])
                       for fe in sorted({c[2] for c in res.curves}, reverse=True)]),
                   size=(7.0, 4.0)),
            Figure("error-grid", "Closed-loop stop error per grid corner (analogue channel), "
                   "with the open loop for contrast.",
                   lambda fig, res=res, spec=spec: _plot_grid(fig, res, spec), size=(8.0, 5.5)),
            ) + figures(spec, res)
    return Rendered(tuple(sections), figs)


def _corner_details(res) -> str:
    rows = corner_rows(res.kind, FACTORS, list(RUNS.values()), (lambda f: fmt(100 * f), fmt, fmt))
    return ("<details><summary>Every corner (stop error, m; + = overshoot)</summary>\n\n"
            + md_table(["km/h", "force error %", "gradient ‰", "friction", "feasible", "open",
                        "ATO open", "closed analogue", "closed 3-bit"], rows, "rrrrlrrrr")
            + "\n\n</details>")


def _plot_grid(fig, res, spec):
    grid, tol = dict(spec.grid), res.tolerance
    plot_grid_map(
        fig, list(res.distance), GridAxis(grid["force_error"], "force error (%)",
                                          lambda f: fmt(100 * f)),
        GridAxis(grid["gradient"], "gradient (‰, + uphill)"), GridAxis(grid["friction"]),
        result_cell(res.kind, RUNS["closed", "analogue"], FACTORS),
        tol, title=lambda s, fr: f"{fmt(s)} km/h, friction ×{fmt(fr)}",
        suptitle=f"closed-loop stop error (m); green: within ±{fmt(tol)} m, orange to red: "
        f"beyond it, dark red: ≥ {fmt(3 * tol)} m",
        colorbar=f"|stop error| (m); tolerance {fmt(tol)} m")
