"""``verify --changed-since REF``: which designs and proof modules a change touches.

The files changed since ``REF`` are what ``git diff --name-only REF`` lists
(committed and uncommitted changes to tracked files) plus untracked files
that git does not ignore. A design is checked again when any of these changed:

* its own file;
* a file in a subfolder of ``designs/`` (data a design may read, e.g.
  ``designs/benchmarks/*.toml`` of the delay benchmark) — every design then;
* ``workbench.toml``, ``pyproject.toml`` or ``constraints.txt`` (the project
  or its pinned versions) — every design and proof then;
* a file of the ``workbench`` package that its study runs: the study module
  of its ``kind`` (and of the paper module its ``[analysis]`` table names)
  and every ``workbench`` module it imports, transitively,
  plus those of the claim machinery (``verify``, ``claims``, ``design``).
  Imports are read statically from the source (:mod:`ast`, every ``import``
  statement anywhere in a module, so a lazy import counts too); a package's
  ``__init__.py`` counts as a file but the imports of
  ``workbench/kinds/__init__.py`` (the registry of every study) are not
  followed. Package files only change in a checkout of the workbench
  itself; in a user's project the installed package is not under git.

A proof module is checked again when its file, ``proofs/__init__.py``, a
sibling it imports, or a ``workbench`` module it imports (transitively) changed.
"""
from __future__ import annotations

import ast
import subprocess
from functools import cache
from pathlib import Path

from .errors import DesignError

PACKAGE_DIR = Path(__file__).resolve().parent
GLOBAL_FILES = ("workbench.toml", "pyproject.toml", "constraints.txt")
#: Package files whose imports are not followed (registries of every study).
_NOT_FOLLOWED = (PACKAGE_DIR / "kinds" / "__init__.py",)
_CORE = ("workbench.verify", "workbench.claims", "workbench.design")


def _git(root: Path, *args: str) -> str:
    try:
        out = subprocess.run(["git", "-C", str(root), *args], capture_output=True,
                             text=True, check=False)
    except FileNotFoundError:
        raise DesignError("<cli>", "--changed-since", args[-1], "git on PATH") from None
    if out.returncode != 0:
        raise DesignError("<cli>", "--changed-since", args[-1],
                          f"a git revision of the repository holding {root} "
                          f"(git: {out.stderr.strip().splitlines()[-1] if out.stderr else '?'})")
    return out.stdout


def changed_files(root: Path, ref: str) -> set[Path]:
    """Absolute paths changed since ``ref`` in the git work tree holding ``root``.

    Raises
    ------
    DesignError
        If ``root`` is not in a git work tree or ``ref`` is not a revision.
    """
    top = Path(_git(root, "rev-parse", "--show-toplevel").strip())
    _git(root, "rev-parse", "--verify", "--quiet", f"{ref}^{{commit}}")
    names = _git(root, "diff", "--name-only", ref, "--").splitlines()
    names += _git(root, "ls-files", "--others", "--exclude-standard", "--full-name").splitlines()
    return {(top / n).resolve() for n in names if n}


def _module_file(name: str) -> Path | None:
    """Source file of a ``workbench`` module name, or None."""
    parts = name.split(".")
    if parts[0] != "workbench":
        return None
    base = PACKAGE_DIR.joinpath(*parts[1:])
    for cand in (base.with_suffix(".py"), base / "__init__.py"):
        if cand.is_file():
            return cand
    return None


def _module_name(path: Path) -> str:
    rel = path.relative_to(PACKAGE_DIR.parent).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def _imports(path: Path, package: str) -> set[str]:
    """Module names imported by ``path`` (relative ones resolved against ``package``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            out.add(mod)
            out |= {f"{mod}.{a.name}" for a in node.names}
    return out


def _package_of(path: Path, name: str) -> str:
    return name if path.name == "__init__.py" else name.rpartition(".")[0]


def _closure(start: Path, package: str, siblings: Path | None = None) -> frozenset[Path]:
    """Files reached from ``start`` by imports of ``workbench`` modules (and, for a
    proof module, of sibling modules in ``siblings``)."""
    seen: set[Path] = set()
    todo = [(start, package)]
    while todo:
        path, pkg = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        if path in _NOT_FOLLOWED:
            continue
        for name in _imports(path, pkg):
            f = _module_file(name)
            if f is not None:
                parts = name.split(".")
                for i in range(2, len(parts)):  # parent packages run their __init__
                    parent = _module_file(".".join(parts[:i]))
                    if parent is not None and parent.name == "__init__.py":
                        todo.append((parent, ".".join(parts[:i])))
                todo.append((f, _package_of(f, name)))
            elif siblings is not None and pkg == "<proofs>":
                sib = siblings / (name.rpartition(".")[2] + ".py")
                if name.startswith("<proofs>.") and sib.is_file():
                    todo.append((sib, pkg))
    return frozenset(seen)


@cache
def study_files(kind: str) -> frozenset[Path]:
    """Package files a design of ``kind`` runs (see the module docstring)."""
    from . import kinds
    study = kinds.REGISTRY[kind]
    modname = study if isinstance(study, str) else type(study).__module__
    if not modname.startswith("workbench."):
        modname = f"workbench.kinds.{modname}"
    files: set[Path] = set()
    for name in (modname, *_CORE):
        f = _module_file(name)
        if f is not None:
            files |= _closure(f, _package_of(f, name))
    return frozenset(files)


def proof_files(path: Path) -> frozenset[Path]:
    """Files a proof module depends on: itself, ``__init__.py``, what it imports."""
    path = path.resolve()
    return _closure(path, "<proofs>", siblings=path.parent) | {path.parent / "__init__.py"}


def design_changed(path: Path, kind: str, designs_dir: Path, changed: set[Path]) -> bool:
    """Whether the design at ``path`` (of ``kind``) depends on a changed file."""
    if path.resolve() in changed or _global_change(designs_dir.parent, changed):
        return True
    data = designs_dir.resolve()
    if any(data in c.parents and c.parent != data for c in changed):
        return True
    return bool((study_files(kind) | _analysis_files(path)) & changed)


def _analysis_files(path: Path) -> frozenset[Path]:
    """Files of the paper module a design names in ``[analysis] module =
    "pNNN.name"`` (imported by name, so not in its kind's imports)."""
    import tomllib
    try:
        name = tomllib.loads(path.read_text(encoding="utf-8"))["analysis"]["module"]
    except (OSError, ValueError, KeyError, TypeError):
        return frozenset()
    f = _module_file(f"workbench.papers.{name}") if isinstance(name, str) else None
    return frozenset() if f is None else _closure(f, _package_of(f, f"workbench.papers.{name}"))


def proof_changed(path: Path, changed: set[Path]) -> bool:
    """Whether the proof module at ``path`` depends on a changed file."""
    return _global_change(path.resolve().parent.parent, changed) or bool(
        proof_files(path) & changed)


def _global_change(root: Path, changed: set[Path]) -> bool:
    root = root.resolve()
    return any((root / g) in changed for g in GLOBAL_FILES)
