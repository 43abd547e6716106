"""The stepping path of a batch of runs: a compiled (numba) kernel or the numpy reference.

A study that compiles its closed loop keeps the numpy form as the reference
the kernel is compared with, and as the path where numba is not installed
(``pip install 'traincontrol-workbench[fast]'``) or where the kernel does
not cover a variant of the loop. This module names the two paths and picks
one; it knows no kernel.
"""
from __future__ import annotations

from importlib.util import find_spec
from typing import Literal

__all__ = ["KERNELS", "Kernel", "compiled_available", "default_kernel", "chosen_path"]

#: The stepping paths of a batch: "compiled" (numba) or "numpy".
KERNELS = ("compiled", "numpy")
Kernel = Literal["compiled", "numpy"]


def compiled_available() -> bool:
    """Whether numba is installed (a compiled kernel can run)."""
    return find_spec("numba") is not None


def default_kernel() -> Kernel:
    """"compiled" when numba is installed, else "numpy"."""
    return "compiled" if compiled_available() else "numpy"


def chosen_path(kernel: str, covered: bool) -> Kernel:
    """The path a batch takes when ``kernel`` (:data:`KERNELS`) is asked for:
    "compiled" only where the kernel ``covered`` the batch's variant, else
    "numpy"; ValueError on a name not in :data:`KERNELS`."""
    if kernel not in KERNELS:
        raise ValueError(f"kernel = {kernel!r}; expected one of {KERNELS}")
    return "compiled" if kernel == "compiled" and covered else "numpy"
