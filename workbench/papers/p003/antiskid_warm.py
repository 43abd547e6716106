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

__all__ = ["WARMERS", "main"]


def warm_batch() -> None:
    """Compile (or load) the batch kernel (Monte Carlo and halving) and the
    metric update of every run, as a single run calls it."""
    from numba import boolean, float64, int64

    from .antiskid_kernel import compile_kernel
    from .antiskid_scenario import metric_updates
    compile_kernel()
    m2 = float64[:, ::1]
    metric_updates()[0].compile((float64, float64, float64, int64, boolean, boolean, boolean,
                                 float64, m2, m2, int64, float64[::1], float64, float64))


def warm_sampled() -> None:
    """Compile (or load) the sampled kernel (``[sampled]`` runs) by a short
    run of the dry design (nothing without the repository's designs)."""
    from pathlib import Path

    from ...design import load_design
    from . import antiskid_sampled as S
    from .antiskid_run_spec import sampled_context
    path = Path(__file__).resolve().parents[3] / "designs" / "antiskid-run-dry.toml"
    if path.is_file():           # else an installed package without the repository
        d = load_design(path)
        ctx = sampled_context(d.spec, d.spec.K_table)
        S.run_once(ctx, 100.0, 0, dt_p=1e-4, predictor_step=1e-3, t_cap=0.05)


#: The kernels by name, with their warm-up.
WARMERS = {"batch": warm_batch, "sampled": warm_sampled}


def main() -> int:
    """Warm both kernels on two processes; one line of figures on stdout."""
    from ...sim.jit_warm import warm_in_processes
    print(warm_in_processes(WARMERS))
    return 0


if __name__ == "__main__":
    sys.exit(main())
