"""The claim-level refinement of findings: :mod:`workbench.features.refinement`.

The committed reports name this path (``workbench/refinement.py``,
``workbench.refinement.guarded_check``); the one implementation is
:mod:`workbench.features.refinement`, which every caller imports.
"""
from .features import refinement as _impl
from .features.refinement import *  # noqa: F401,F403 (the printed path re-exports it)

__all__ = list(_impl.__all__)
