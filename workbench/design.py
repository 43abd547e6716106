"""TOML design files -> validated, typed specs.

A design file is data: parameters (each with its unit and source), settings
and claims. Every problem is a :class:`~workbench.errors.DesignError` naming
the file, the key, the value and what was expected. Nothing in a design file
is ever evaluated as code.

Layout shared by every design::

    [design]
    name = "antiskid-cruise-dry"     # = file stem
    kind = "antiskid-cruise"         # selects the study (workbench.studies)
    title = "..."
    source = "paper 003, ..."

    [[claims]]                        # optional, see workbench.claims
    ...

The rest of the file belongs to the study named by ``kind``; it reads it
through a :class:`~workbench.reader.Reader`, which records which keys were used so that
unknown keys (often typos) are errors too.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .errors import DesignError
from .reader import Quantity, Reader, display_path  # noqa: F401  (re-exported)
from .report.files import SAFE_NAME
from .toml_input import load_toml

@dataclass(frozen=True)
class Design:
    """A loaded design file.

    Attributes
    ----------
    path : str
    name, kind, title, source : str
    spec : object
        The study-specific, validated spec (frozen dataclass).
    claims : tuple
        Validated :class:`workbench.claims.Claim` objects.
    """

    path: str
    name: str
    kind: str
    title: str
    source: str
    spec: Any
    claims: tuple


def load_design(path: str | Path) -> Design:
    """Load and validate a design file.

    Raises
    ------
    DesignError
        On any problem, naming file, key, value and what was expected.
    """
    from . import studies
    from .claims import parse_claims

    shown = display_path(path)
    p = Path(path)
    if not p.is_file():
        raise DesignError(shown, "<file>", "<missing>", "an existing design file (.toml)")
    data = load_toml(p, shown)
    root = Reader(shown, data)
    head = root.table("design")
    name = head.string("name")
    if name != p.stem:
        raise head.fail("name", name, f'the file name without .toml, "{p.stem}"')
    if not SAFE_NAME.fullmatch(name):
        raise head.fail("name", name, "a file-name-safe name: letters, digits, '-', '_', '.', "
                        "not starting with '.' (reports are written under it)")
    kind = head.string("kind", choices=sorted(studies.REGISTRY))
    title = head.string("title")
    source = head.string("source")
    head.finish()
    study = studies.REGISTRY[kind]
    spec = study.load(root)
    claims = parse_claims(root, study, spec)
    root.finish()
    return Design(shown, name, kind, title, source, spec, tuple(claims))
