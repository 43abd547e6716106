"""pytest plugin: every claim of a workbench project as a pytest item.

Registered as the ``pytest11`` entry point ``workbench``; it does nothing
unless pytest runs with ``--workbench``. Then, in the project holding the
folder pytest was started from (see :mod:`workbench.project`):

* each design file ``designs/*.toml`` is a test file whose items are its
  claims (node id ``designs/<design>.toml::<claim-id>``);
* each proof module ``proofs/*.py`` (not starting with ``_``) is a test file
  whose items are its proof claims.

An item passes or fails by the rules of :mod:`workbench.ci` (INCONCLUSIVE
fails; an expected failure passes and shows its reason in a "workbench"
report section). A failing item's report gives expected, got, tolerance and
source. ``-k`` matches claim ids and design file names; a design file given
on the command line selects that design. A study runs once per design, at
its first selected claim.

Configuration (``pytest.ini``, ``tox.ini`` or ``[tool.pytest.ini_options]``)::

    workbench_designs = designs/a.toml designs/b.toml   # default: every design
    workbench_proofs = false                            # default: true

When pytest's arguments come from ``testpaths`` (or nothing was given), the
project's ``designs/`` and ``proofs/`` are added to them, so ``pytest
--workbench`` checks the claims next to the team's own tests.
"""
from __future__ import annotations

from pathlib import Path

import pytest


def pytest_addoption(parser):
    group = parser.getgroup("workbench", "workbench claims")
    group.addoption("--workbench", action="store_true", default=False,
                    help="collect every claim of the workbench project (designs/*.toml, "
                         "proofs/*.py) as a test item")
    parser.addini("workbench_designs", type="args", default=[],
                  help="design files whose claims --workbench collects (default: all "
                       "of designs/)")
    parser.addini("workbench_proofs", type="bool", default=True,
                  help="whether --workbench also collects the claims of proofs/")


def _active(config) -> bool:
    return bool(config.getoption("workbench", default=False))


_PROJECT = pytest.StashKey[object]()


def _project(config):
    """The project of the folder pytest was started from (found once per run)."""
    if _PROJECT not in config.stash:
        from .project import find_project
        config.stash[_PROJECT] = find_project(config.invocation_params.dir)
    return config.stash[_PROJECT]


def pytest_configure(config):
    if not _active(config):
        return
    if config.args_source is pytest.Config.ArgsSource.ARGS:
        return
    project = _project(config)
    given = [Path(a.split("::")[0]).resolve() for a in config.args]
    for folder in (project.designs, project.proofs):
        if folder.is_dir() and not any(g == folder or g in folder.parents for g in given):
            config.args.append(str(folder))


def _selected_designs(config, project) -> set[Path] | None:
    names = config.getini("workbench_designs")
    if not names:
        return None
    base = config.inipath.parent if config.inipath else project.root
    return {(base / n).resolve() for n in names}


def pytest_collect_file(file_path: Path, parent):
    config = parent.config
    if not _active(config):
        return None
    project = _project(config)
    path = file_path.resolve()
    if path.suffix == ".toml" and path.parent == project.designs.resolve():
        chosen = _selected_designs(config, project)
        if chosen is None or path in chosen:
            return DesignFile.from_parent(parent, path=file_path)
    if (path.suffix == ".py" and path.parent == project.proofs.resolve()
            and not path.name.startswith("_") and config.getini("workbench_proofs")):
        return ProofFile.from_parent(parent, path=file_path)
    return None


class ClaimFailed(Exception):
    """A claim that is not ok; carries its :class:`workbench.ci.Case`."""

    def __init__(self, case):
        super().__init__(case.message)
        self.case = case


class _ClaimFile(pytest.File):
    """A design file or proof module: its items are claims."""

    _cases: dict | None = None
    _error: BaseException | None = None

    def repr_failure(self, excinfo, style=None):
        from .errors import WorkbenchError
        if isinstance(excinfo.value, WorkbenchError):
            return f"error: {excinfo.value}"
        return super().repr_failure(excinfo)    # a Collector's takes no style

    def case(self, claim_id: str):
        """The :class:`workbench.ci.Case` of one claim (the study runs once)."""
        if self._error is not None:
            raise self._error
        if self._cases is None:
            try:
                self._cases = {c.claim: c for c in self.run_cases()}
            except Exception as exc:
                self._error = exc
                raise
        return self._cases[claim_id]

    def run_cases(self) -> list:
        raise NotImplementedError


class DesignFile(_ClaimFile):
    """``designs/<design>.toml``: one item per claim."""

    def collect(self):
        from .design import load_design
        self.design = load_design(self.path)
        for c in self.design.claims:
            yield ClaimItem.from_parent(self, name=c.id)

    def run_cases(self) -> list:
        from .ci import design_cases
        from .verify import evaluate_design
        return design_cases(evaluate_design(self.design))


class ProofFile(_ClaimFile):
    """``proofs/<module>.py``: one item per proof claim."""

    def collect(self):
        from .prove import proof_modules
        folder = self.path.resolve().parent
        (self.module,) = [m for m in proof_modules(folder) if m.name == self.path.stem]
        for c in self.module.claims:
            yield ClaimItem.from_parent(self, name=c.id)

    def run_cases(self) -> list:
        from .ci import proof_cases
        from .prove import check_proof_claim
        folder = self.path.resolve().parent
        return proof_cases([(self.module, check_proof_claim(folder, self.module.name, c.id))
                            for c in self.module.claims])


class ClaimItem(pytest.Item):
    """One claim; passes or fails like a test (see the module docstring)."""

    def runtest(self):
        case = self.parent.case(self.name)
        self.user_properties.append(("verdict", case.verdict))
        if case.out:
            self.add_report_section("call", "workbench", case.out)
        if not case.ok:
            raise ClaimFailed(case)

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, ClaimFailed):
            c = excinfo.value.case
            return f"{c.name}: {c.message}\n\n{c.detail}"
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        suite = self.path.stem if isinstance(self.parent, DesignFile) \
            else f"proofs/{self.path.stem}"
        return self.path, None, f"{suite}::{self.name}"
