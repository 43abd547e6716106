"""Time of the delay-feedback path: rejecting a hostile design, and each stage
of the shipped delay-feedback designs.

Prints, per design: load (text -> checked expressions -> sympy model ->
operating point), synthesis, exact margin and windows, simulations (each at dt
and dt/2), in seconds; then the wall time of ``workbench verify`` on a design
whose expression is hostile (a fresh process: Python start-up included), which
must answer without importing numpy, sympy or a solver.

Run: ``.venv/bin/python benchmarks/delay_feedback.py``
"""
from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from workbench.design import load_design
from workbench.report.markdown import md_table

ROOT = Path(__file__).resolve().parents[1]
DESIGNS = sorted((ROOT / "designs").glob("*generic.toml")) + sorted(
    (ROOT / "designs").glob("*-delay-feedback.toml"))


def stages(path: Path) -> list[str]:
    from workbench.margins import exact_margin, stability_windows
    from workbench.kinds.delay_feedback.run import nominal_point, simulate_scenario, synthesise
    t0 = time.perf_counter()
    d = load_design(path)
    spec = d.spec
    model, values, op, A, B = nominal_point(spec)
    points = tuple(nominal_point(spec, v)[3:] for v in spec.vertices)
    t1 = time.perf_counter()
    s = synthesise(spec, A, B, points)
    t2 = time.perf_counter()
    exact_margin(A, B @ s.K)
    stability_windows(A, B @ s.K, spec.window_horizon)
    t3 = time.perf_counter()
    for sc in spec.scenarios:
        simulate_scenario(spec, model, values, op, s.K, sc)
    t4 = time.perf_counter()
    return [d.name, f"{t1 - t0:.2f}", f"{t2 - t1:.2f}", f"{t3 - t2:.2f}", f"{t4 - t3:.2f}"]


def hostile_seconds() -> float:
    text = (ROOT / "workbench" / "scaffold" / "files" / "delay-feedback.toml.tmpl").read_text()
    text = text.format(name="hostile").replace('"spring - d*x2 + u"', '"x2.__class__"')
    with tempfile.TemporaryDirectory() as tmp:
        p = Path(tmp) / "hostile.toml"
        p.write_text(text)
        t0 = time.perf_counter()
        rc = subprocess.run([sys.executable, "-m", "workbench.cli", "verify", str(p)],
                            capture_output=True, cwd=tmp).returncode
        assert rc == 2
        return time.perf_counter() - t0


def main() -> None:
    rows = [stages(p) for p in DESIGNS]
    print(md_table(["design", "load + op point + Jacobians", "synthesis", "exact margin + windows",
                    "simulations (dt and dt/2)"], rows, "lrrrr"))
    print(f"\nhostile expression rejected by `workbench verify` in a fresh process: "
          f"{hostile_seconds():.2f} s wall")


if __name__ == "__main__":
    main()
