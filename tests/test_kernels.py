"""Same output under another CPU's BLAS kernels (issue 12).

numpy/scipy ship OpenBLAS with run-time kernel selection, and
``OPENBLAS_CORETYPE`` forces another CPU's kernels on this one: Haswell
(AVX2 + FMA), Sandybridge (AVX, no FMA) and Prescott (SSE3). A synthesis whose
printed gain depended on the kernel (the degenerate optimum of problem (60))
would print different digits under them; the canonical gain of
:mod:`workbench.lmi.gain` must not. On a CPU without a kernel, OpenBLAS
ignores the variable and the test compares the default kernel with itself.
"""
import os
import subprocess
import sys

import pytest

KERNELS = ("Haswell", "Sandybridge", "Prescott")
DESIGN = "designs/antiskid-cruise-dry.toml"


def _run(kernel: str, *args: str) -> str:
    env = {**os.environ, "OPENBLAS_CORETYPE": kernel, "OPENBLAS_NUM_THREADS": "1"}
    out = subprocess.run([sys.executable, "-m", "workbench.cli", *args], env=env,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    return out.stdout


@pytest.mark.slow
def test_synthesize_is_byte_identical_under_three_kernels():
    outs = {k: _run(k, "synthesize", "delay-bound", DESIGN, "--eps", "0.35", "0.1")
            for k in KERNELS}
    assert "[-0.00" in outs["Haswell"]                 # a gain was printed
    for k in KERNELS[1:]:
        assert outs[k] == outs["Haswell"], f"{k} differs from Haswell"
