"""Compile the two antiskid kernels into the machine's disk cache now.

``make install`` runs ``python -m workbench.papers.p003.antiskid_warm`` (issue 36,
item 3: the compiled kernels compile once per machine, and that once belongs to
the install, not to the five-minute check). Each kernel is compiled in its own
process, both at once (:func:`workbench.sim.jit_warm.warm_in_processes`); with a warm cache (:mod:`workbench.sim.jit_cache`) each
is only loaded, a few seconds. Nothing is computed that a study reads: the
cache holds machine code, and its key is the package's source, so a kernel
compiled here is the one a study would have compiled.
"""
from __future__ import annotations

import sys
import time

__all__ = ["warm", "main"]

KERNELS = ("batch", "sampled")


def warm(which: str) -> float:
    """Compile (or load) kernel ``which`` ("batch": Monte Carlo and halving,
    and the metric update of every run; "sampled": ``[sampled]`` runs) in
    this process; CPU seconds spent."""
    c0 = time.process_time()
    if which == "batch":
        from numba import boolean, float64, int64

        from .antiskid_kernel import compile_kernel
        from .antiskid_scenario import metric_updates
        compile_kernel()
        m2 = float64[:, ::1]     # the metric update as a single run calls it
        metric_updates()[0].compile((float64, float64, float64, int64, boolean, boolean, boolean,
                                     float64, m2, m2, int64, float64[::1], float64, float64))
    elif which == "sampled":
        from pathlib import Path

        from ...design import load_design
        from . import antiskid_sampled as S
        from .antiskid_run_spec import sampled_context
        path = Path(__file__).resolve().parents[3] / "designs" / "antiskid-run-dry.toml"
        if not path.is_file():           # an installed package without the repository
            return 0.0
        d = load_design(path)
        ctx = sampled_context(d.spec, d.spec.K_table)
        S.run_once(ctx, 100.0, 0, dt_p=1e-4, predictor_step=1e-3, t_cap=0.05)
    else:
        raise ValueError(f"kernel {which!r}: expected one of {KERNELS}")
    return time.process_time() - c0


def main() -> int:
    """Warm both kernels on two processes; one line of figures on stdout."""
    from ...sim.jit_warm import warm_in_processes
    print(warm_in_processes(warm, KERNELS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
