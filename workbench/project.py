"""The user's project: where ``designs/``, ``proofs/`` and ``reports/`` are.

A project is a folder holding a ``workbench.toml`` marker (written by
``workbench init``). Every command finds the project root as the nearest
folder, from the current one upwards, that holds the marker; with no marker
anywhere above, the current folder is the root. Designs, proofs and reports
are always looked up from that root, never from the installed package.

The marker is data (TOML, never evaluated). It may be empty; its only keys are::

    [project]
    name = "my-claims"      # shown in JUnit output (testsuites name)
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from .errors import DesignError
from .toml_input import load_toml

MARKER = "workbench.toml"


@dataclass(frozen=True)
class Project:
    """A project root and its folders.

    Attributes
    ----------
    root : Path
        Absolute path of the project root.
    name : str
        ``project.name`` of the marker, or the root folder's name.
    marked : bool
        Whether the root holds a ``workbench.toml`` (False: the current folder
        was taken as the root).
    """

    root: Path
    name: str
    marked: bool

    @property
    def designs(self) -> Path:
        """Folder of the design files, ``<root>/designs``."""
        return self.root / "designs"

    @property
    def proofs(self) -> Path:
        """Folder of the proof modules, ``<root>/proofs``."""
        return self.root / "proofs"

    @property
    def reports(self) -> Path:
        """Folder of the generated reports, ``<root>/reports``."""
        return self.root / "reports"

    def design_files(self) -> list[Path]:
        """Every design file ``designs/*.toml``, sorted by name."""
        return sorted(self.designs.glob("*.toml"))


def read_marker(path: Path) -> str:
    """Validate a ``workbench.toml`` and return its project name ("" if unset).

    Raises
    ------
    DesignError
        If the file is not TOML or has keys other than ``project.name``.
    """
    data = load_toml(path, str(path))
    for key, val in data.items():
        if key != "project" or not isinstance(val, dict):
            raise DesignError(str(path), key, val, "only a [project] table")
        for k, v in val.items():
            if k != "name" or not isinstance(v, str) or not v.strip():
                raise DesignError(str(path), f"project.{k}", v,
                                  'only name = "a non-empty string"')
    return data.get("project", {}).get("name", "")


def find_project(start: str | Path | None = None) -> Project:
    """The project containing ``start`` (default: the current folder).

    Parameters
    ----------
    start : path, optional
        Folder to search from, upwards.

    Returns
    -------
    Project
        Rooted at the nearest folder with a ``workbench.toml``, else at ``start``.
    """
    here = Path(start if start is not None else Path.cwd()).resolve()
    for folder in (here, *here.parents):
        marker = folder / MARKER
        if marker.is_file():
            return Project(folder, read_marker(marker) or folder.name, True)
    return Project(here, here.name, False)
