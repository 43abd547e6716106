"""Writing files: whole or not at all, and only inside the output folder.

* :func:`atomic_write` writes through a temporary file with a unique name in
  the target folder (:func:`tempfile.mkstemp`), then renames it over the
  target: a reader sees the old file or the new one, and two writers of the
  same path never share a temporary file.
* :func:`replace_set` replaces a report's files (``NAME.md`` and the folder
  ``NAME/`` of its figures) as a set: the new set is written to a staging
  folder, a journal names it, and the journal is rolled forward (folder
  swapped by rename, Markdown renamed in). A write killed before the journal
  leaves the old set; one killed after it is finished by the next write.
* :func:`inside` and :data:`SAFE_NAME` keep every written path in its folder.
"""
from __future__ import annotations

import os
import re
import shutil
import tempfile
import time
from pathlib import Path
from typing import Callable

from ..errors import DesignError

__all__ = ["SAFE_NAME", "atomic_write", "check_name", "inside", "replace_set"]

#: a name a file may be written under: no separator, not ``.`` or ``..``, no leading dot
SAFE_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9._-]{0,127}")

#: a staging folder this old (s) is a killed write's, removed by the next write
STALE_S = 600.0

_UMASK = os.umask(0o022)
os.umask(_UMASK)


def check_name(name: str, what: str = "name") -> str:
    """``name`` if it is a safe file name (:data:`SAFE_NAME`), else DesignError."""
    if not isinstance(name, str) or not SAFE_NAME.fullmatch(name):
        raise DesignError("<output>", what, name, "a file name of letters, digits, '.', '-', "
                          "'_' (no path separator, not '.' or '..', no leading dot)")
    return name


def inside(folder: Path, path: Path) -> Path:
    """``path`` if it resolves inside ``folder``, else DesignError (nothing written)."""
    base = Path(folder).resolve()
    full = Path(path).resolve()
    if full != base and base not in full.parents:
        raise DesignError("<output>", "path", str(path), f"a path inside {folder}")
    return path


def atomic_write(path: Path, data: str | bytes | Callable, *, folder: Path | None = None
                 ) -> Path:
    """Write ``data`` to ``path`` through a uniquely named temporary file in the
    same folder, then rename it over ``path``; returns ``path``.

    Parameters
    ----------
    path : Path
        Target.
    data : str, bytes or callable
        Text (UTF-8), bytes, or a function that writes to a binary file object.
    folder : Path, optional
        If given, ``path`` must lie inside it (:func:`inside`).
    """
    path = Path(path)
    if folder is not None:
        inside(folder, path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_UMASK)
        with os.fdopen(fd, "wb") as fh:
            if callable(data):
                data(fh)
            else:
                fh.write(data.encode("utf-8") if isinstance(data, str) else data)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path


def _journal(outdir: Path, name: str) -> Path:
    return outdir / f".{name}.commit"


def _roll_forward(outdir: Path, name: str) -> None:
    """Finish an interrupted :func:`replace_set` of ``name`` and clean up."""
    journal = _journal(outdir, name)
    if journal.is_file():
        stage = outdir / journal.read_text(encoding="utf-8").strip()
        inside(outdir, stage)
        new_dir, new_md = stage / name, stage / f"{name}.md"
        if stage.is_dir():
            if new_dir.is_dir() or (stage / ".nofigures").exists():
                old = outdir / name
                if old.exists():
                    os.replace(old, tempfile.mkdtemp(prefix=f".{name}.old-", dir=outdir)
                               + "/x")
                if new_dir.is_dir():
                    os.replace(new_dir, outdir / name)
                (stage / ".nofigures").unlink(missing_ok=True)
            if new_md.is_file():
                os.replace(new_md, outdir / f"{name}.md")
        journal.unlink()
        shutil.rmtree(stage, ignore_errors=True)
    for left in outdir.glob(f".{name}.old-*"):
        shutil.rmtree(left, ignore_errors=True)
    for left in outdir.glob(f".{name}.new-*"):   # a killed write's; not a running one's
        if time.time() - left.stat().st_mtime > STALE_S:
            shutil.rmtree(left, ignore_errors=True)


def replace_set(outdir: Path, name: str, markdown: str, figures: dict[str, bytes]) -> list[Path]:
    """Replace ``outdir/NAME.md`` and the folder ``outdir/NAME/`` (the figures,
    ``{file name: PNG bytes}``) as one set; returns the paths written.

    Raises
    ------
    DesignError
        If ``name`` or a figure name is not a safe file name.
    """
    outdir = Path(outdir)
    check_name(name)
    for fig in figures:
        check_name(fig, "figure")
    outdir.mkdir(parents=True, exist_ok=True)
    _roll_forward(outdir, name)
    stage = Path(tempfile.mkdtemp(prefix=f".{name}.new-", dir=outdir))
    try:
        for fig, png in figures.items():
            atomic_write(stage / name / fig, png, folder=stage)
        if not figures:
            (stage / ".nofigures").touch()
        atomic_write(stage / f"{name}.md", markdown, folder=stage)
        os.chmod(stage, 0o777 & ~_UMASK)
        if figures:
            os.chmod(stage / name, 0o777 & ~_UMASK)
        atomic_write(_journal(outdir, name), stage.name + "\n", folder=outdir)
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    _roll_forward(outdir, name)
    return [outdir / name / fig for fig in figures] + [outdir / f"{name}.md"]
