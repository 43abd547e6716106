"""The papers' designs and proofs as shipped with the package.

In this repository they are the top-level ``designs/`` and ``proofs/`` folders
(their single source); the wheel carries copies of them here, as
``workbench/_examples/designs`` and ``workbench/_examples/proofs``
(``[tool.setuptools.package-dir]`` of ``pyproject.toml``). Nothing reads
them in place: ``workbench init --papers`` copies them into a project, and
every command then works on that project.
"""
from __future__ import annotations

from pathlib import Path
from typing import Literal

from ..errors import DesignError


def shipped(folder: Literal["designs", "proofs"]) -> Path:
    """Folder of the shipped ``designs`` or ``proofs`` (in the wheel, or the checkout).

    Raises
    ------
    DesignError
        If the installation carries neither (a broken install).
    """
    for cand in (Path(__file__).resolve().parent / folder,          # installed wheel
                 Path(__file__).resolve().parents[2] / folder):      # editable checkout
        if cand.is_dir() and any(cand.iterdir()):
            return cand
    raise DesignError("<install>", "workbench._examples", folder,
                      "the papers' designs and proofs shipped with the package")
