"""The ``ANALYSIS`` object of an ``[analysis]`` module of a ``stop-accuracy``
design, built from the module's parts.

The kind (:class:`workbench.kinds.stop_accuracy.StopAccuracy`) calls an
analysis's ``load(root, spec)``, ``run(spec)``, ``render(design, result)`` and
``quantity_names``, ``quantity_units``, ``quantities``. A module declares its
quantities once (a :class:`~workbench.features.quantities.Declared` table)
and writes the three functions; :class:`Analysis` makes the object, so no
module writes the three quantity methods again::

    ANALYSIS = Analysis(TABLE, load, run, render)
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from ...features.quantities import names, units, values

__all__ = ["Analysis"]


@dataclass(frozen=True)
class Analysis:
    """An ``[analysis]`` module's object.

    Attributes
    ----------
    table : tuple
        The module's :class:`~workbench.features.quantities.Declared` entries.
    load : callable
        ``load(root, spec) -> tables``: checks the design (e.g.
        :func:`.needs.require`) and reads the module's own tables (the
        spec's ``paper``).
    run : callable
        ``run(spec) -> result``; the result has the ``spec`` it ran.
    render : callable
        ``render(design, result) -> Rendered``.
    """

    table: tuple
    load: Callable
    run: Callable
    render: Callable

    def quantity_names(self, spec) -> set[str]:
        return names(self.table, spec)

    def quantity_units(self, spec) -> dict[str, str]:
        return units(self.table, spec)

    def quantities(self, res) -> dict:
        return values(self.table, res.spec, res)
