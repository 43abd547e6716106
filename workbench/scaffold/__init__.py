"""``workbench init PATH``: write a project skeleton.

The skeleton (templates in ``workbench/scaffold/files/``)::

    PATH/
      workbench.toml                  project marker (root of designs/ and proofs/)
      README.md
      designs/example-cruise.toml     a commented design that verifies as written
      proofs/braking_distance.py      a proof module (sympy claims)
      reports/                        generated reports (and reports/junit.xml in CI)
      .github/workflows/workbench.yml GitHub Actions: verify --junit-xml
      .gitlab-ci.yml                  GitLab CI: verify --junit-xml, JUnit report
      .gitignore

With ``papers=True`` the example design and proof are replaced by every
design and proof module shipped with the package (papers 000-004, see
:mod:`workbench._examples`). ``init`` never overwrites: the target must be
missing or an empty folder.
"""
from __future__ import annotations

import shutil
from importlib import metadata
from pathlib import Path

from ..errors import DesignError

FILES = Path(__file__).resolve().parent / "files"

#: template (in files/) -> path in the project
COMMON = {
    "workbench.toml": "workbench.toml",
    "README.md": "README.md",
    "github-workflow.yml": ".github/workflows/workbench.yml",
    "gitlab-ci.yml": ".gitlab-ci.yml",
    "gitignore": ".gitignore",
}
EXAMPLE = {
    "example-cruise.toml": "designs/example-cruise.toml",
    "braking_distance.py.tmpl": "proofs/braking_distance.py",
}
DEFAULT_REQUIREMENT = f"workbench=={metadata.version('workbench')}"


def init_project(path: str | Path, *, papers: bool = False,
                 requirement: str = DEFAULT_REQUIREMENT) -> list[Path]:
    """Write a project skeleton at ``path``; returns the files written.

    Parameters
    ----------
    path : path
        Target folder: missing or empty.
    papers : bool
        Copy the shipped designs and proofs of papers 000-004 instead of the
        one example design and proof module.
    requirement : str
        What the CI files ``pip install`` (a requirement, wheel URL or VCS URL).

    Raises
    ------
    DesignError
        If ``path`` exists and is not an empty folder (nothing is written).
    """
    target = Path(path)
    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise DesignError("<cli>", "PATH", str(target),
                          "a new or empty folder (init never overwrites)")
    if not requirement.strip() or any(c in requirement for c in '"\n'):
        raise DesignError("<cli>", "--requirement", requirement,
                          "a pip requirement without quotes or newlines")
    name = target.resolve().name
    written = []
    for template, dest in {**COMMON, **({} if papers else EXAMPLE)}.items():
        text = (FILES / template).read_text(encoding="utf-8")
        text = text.replace("{name}", name).replace("{requirement}", requirement)
        out = target / dest
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
        written.append(out)
    if papers:
        from .._examples import shipped
        ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
        for folder in ("designs", "proofs"):
            shutil.copytree(shipped(folder), target / folder, ignore=ignore)
            written += sorted(p for p in (target / folder).rglob("*") if p.is_file())
    (target / "reports").mkdir(parents=True, exist_ok=True)
    keep = target / "reports" / ".gitkeep"
    keep.touch()
    written.append(keep)
    return written
