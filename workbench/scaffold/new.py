"""``workbench new KIND NAME``: write a commented template design.

Templates live in ``workbench/scaffold/files/<kind>.toml.tmpl`` (``str.format``
with ``name``); each runs as written (``workbench verify`` passes on it).
"""
from __future__ import annotations

import re
from pathlib import Path

from ..errors import DesignError

FILES = Path(__file__).resolve().parent / "files"
#: kinds with a template
KINDS = ("delay-feedback",)
_NAME = re.compile(r"^[a-z0-9][a-z0-9-]*$")


def new_design(kind: str, name: str, folder: str | Path = "designs") -> Path:
    """Write ``folder/name.toml`` from the template of ``kind``.

    Parameters
    ----------
    kind : str
        One of :data:`KINDS`.
    name : str
        Design name (lower-case letters, digits and dashes; the file stem).
    folder : path
        Where to write (created if missing).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    DesignError
        Unknown kind, bad name, or the file exists (never overwritten).
    """
    if kind not in KINDS:
        raise DesignError("<cli>", "KIND", kind, "one of " + ", ".join(KINDS))
    if not _NAME.match(name):
        raise DesignError("<cli>", "NAME", name, "lower-case letters, digits and dashes, "
                          "starting with a letter or digit")
    path = Path(folder) / f"{name}.toml"
    if path.exists():
        raise DesignError("<cli>", "NAME", name, f"a design that does not exist yet ({path} "
                          "does; never overwritten)")
    text = (FILES / f"{kind}.toml.tmpl").read_text(encoding="utf-8").format(name=name)
    from ..report.files import atomic_write
    return atomic_write(path, text)
