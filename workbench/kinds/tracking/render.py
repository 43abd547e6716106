"""Markdown and figures of a ``tracking`` design (pure rendering).

A design with ``[analysis] module = "pNNN.name"`` is written by that paper
module's ``render(design, res)`` (its wording of the paper's questions); any
other design gets the general report of :mod:`.render_general`.
"""
from __future__ import annotations

import importlib

__all__ = ["render"]


def render(design, res):
    """The report of a ``tracking`` design (see the module docstring)."""
    name = design.spec.analysis_module
    if name is not None:
        return importlib.import_module(f"workbench.papers.{name}").render(design, res)
    from .render_general import render as general
    return general(design, res)
