"""A study whose claimable quantities are one
:class:`~workbench.features.quantities.Declared` table: the study protocol's
``quantity_names`` and ``quantities``, written once.

A study class derives from :class:`DeclaredStudy` and sets ``TABLE``; its
result holds the spec it was run on as ``.spec``.
"""
from __future__ import annotations

from .quantities import names, values

__all__ = ["DeclaredStudy"]


class DeclaredStudy:
    """The quantity methods of a study with a ``TABLE`` of declared quantities."""

    TABLE: tuple = ()

    def quantity_names(self, spec) -> set[str]:
        return names(self.TABLE, spec)

    def quantities(self, res) -> dict:
        return values(self.TABLE, res.spec, res)
