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

import re
import shutil
from pathlib import Path

from .. import DISTRIBUTION, version
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
DEFAULT_REQUIREMENT = f"{DISTRIBUTION}=={version()}"

_EXTRAS = r"(\[[a-z]+(,[a-z]+)*\])?"
_PIN = re.compile(re.escape(DISTRIBUTION) + _EXTRAS +
                  r"==\d+(\.\d+)*((a|b|rc)\d+)?(\.post\d+)?(\.dev\d+)?")
_GIT = re.compile(r"git\+(https|ssh)://[A-Za-z0-9._~:/@%+-]+@[0-9a-f]{40}")
_WHEEL = re.compile(r"([A-Za-z0-9._~:/%+][A-Za-z0-9._~:/%+-]*/)?" + DISTRIBUTION.replace("-", "_") +
                    r"-[0-9][A-Za-z0-9.+]*-[A-Za-z0-9._]+-[A-Za-z0-9._]+-[A-Za-z0-9._]+\.whl")
FORMS = (f"{DISTRIBUTION}==VERSION, git+https://REPOSITORY@COMMIT (40 hex digits) "
         f"or a path or URL of a {DISTRIBUTION.replace('-', '_')}-*.whl")


def install_requirement(text: str) -> str:
    """What the CI files ``pip install``: exactly this package, pinned.

    ``workbench`` on the package index is an unrelated project, and an
    unpinned name lets an index serve anything under it (dependency
    confusion). Accepted: ``traincontrol-workbench==VERSION`` (with extras),
    a git URL pinned to a full commit hash (returned as
    ``traincontrol-workbench @ git+...@COMMIT``), or a wheel of this
    distribution by path or URL.

    Raises
    ------
    DesignError
        For anything else (a range, another name, an unpinned URL, options).
    """
    req = text.strip()
    if req.startswith(f"{DISTRIBUTION} @ "):
        req = req[len(DISTRIBUTION) + 3:].strip()
    if _PIN.fullmatch(req) or _WHEEL.fullmatch(req):
        return req
    if _GIT.fullmatch(req):
        return f"{DISTRIBUTION} @ {req}"
    raise DesignError("<cli>", "--requirement", text, FORMS)


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
        What the CI files ``pip install``: see :func:`install_requirement`.

    Raises
    ------
    DesignError
        If ``path`` exists and is not an empty folder, or ``requirement`` is not
        a pinned form of this distribution (nothing is written).
    """
    target = Path(path)
    if target.exists() and (not target.is_dir() or any(target.iterdir())):
        raise DesignError("<cli>", "PATH", str(target),
                          "a new or empty folder (init never overwrites)")
    requirement = install_requirement(requirement)
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
