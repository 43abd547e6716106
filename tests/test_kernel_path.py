"""workbench.sim.kernel_path: the choice of a batch's stepping path (no kernel of any paper)."""
from __future__ import annotations

from importlib.util import find_spec

import pytest

from workbench.sim.kernel_path import KERNELS, chosen_path, compiled_available, default_kernel


def test_the_compiled_path_is_taken_only_where_the_kernel_covers_the_batch():
    assert chosen_path("compiled", True) == "compiled"
    assert chosen_path("compiled", False) == "numpy"
    assert chosen_path("numpy", True) == "numpy"


def test_an_unknown_path_is_refused_with_the_known_ones():
    with pytest.raises(ValueError, match="'fortran'.*compiled"):
        chosen_path("fortran", True)


def test_the_default_path_is_compiled_exactly_when_numba_is_installed():
    assert compiled_available() == (find_spec("numba") is not None)
    assert default_kernel() == ("compiled" if compiled_available() else "numpy")
    assert default_kernel() in KERNELS
