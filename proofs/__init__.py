"""Claims as code: each module builds sympy claims about one paper's derivations.

A module defines ``PAPER`` ("000".."004"), ``TITLE`` and ``claims() ->
list[workbench.symbolic.proof.Claim]``. Modules are discovered by name (every
module of this package not starting with ``_``); ``workbench prove`` checks
them and ``workbench verify`` includes them.
"""
from __future__ import annotations

import importlib
import pkgutil


def module_names() -> list[str]:
    """Names of the proof modules, sorted."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))


def modules() -> list:
    """The proof modules, imported, in name order."""
    return [importlib.import_module(f"{__name__}.{n}") for n in module_names()]
