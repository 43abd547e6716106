"""workbench: robust-control design and verification for train control.

Determinism: OpenBLAS may split a product across threads, and how it splits
depends on the machine's core count. The workbench runs OpenBLAS on one
thread so that the same inputs give the same bits on every machine; this is
set here, before numpy is imported by any workbench module, and a value the
user set in the environment wins.
"""
import os as _os

_os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

#: The distribution (the name on the package index and in ``pip install``).
#: ``workbench`` on the index is an unrelated project, so ours is published
#: under a name of its own; the import name and the command stay ``workbench``.
DISTRIBUTION = "traincontrol-workbench"


def version() -> str:
    """The installed version of :data:`DISTRIBUTION` ("unknown" when run
    from a source tree that was never installed)."""
    from importlib import metadata
    try:
        return metadata.version(DISTRIBUTION)
    except metadata.PackageNotFoundError:
        return "unknown"


#: Public API names loaded on first use (``import workbench`` stays light):
#: name -> the module that defines it.
_LAZY = {
    "delay_bound": "api", "simulate_delay": "api", "DelayBoundResult": "api",
    "implementation": "digital", "ImplementationResult": "digital",
    "synthesize_sampled": "digital",
    "design_gain": "api_design",          # design to requirements
}


def __getattr__(name):
    """Lazy access to the public API (``workbench.delay_bound`` etc.)."""
    if name in _LAZY:
        from importlib import import_module
        return getattr(import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'workbench' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY))
