"""The wheel's package list matches the source folders (issue 18)."""
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_folder_is_listed_in_pyproject():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    listed = set(conf["packages"])
    found = {".".join(p.parent.relative_to(ROOT).parts)
             for p in (ROOT / "workbench").rglob("__init__.py")}
    mapped = set(conf["package-dir"])
    assert found | mapped == listed
    assert conf["package-dir"] == {"workbench._examples.proofs": "proofs",
                                   "workbench._examples.designs": "designs"}


def test_scaffold_templates_are_package_data():
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    from workbench.scaffold import COMMON, EXAMPLE, FILES
    from workbench.scaffold.new import KINDS
    assert conf["package-data"]["workbench.scaffold"] == ["files/*"]
    assert sorted(p.name for p in FILES.iterdir()) == sorted(
        {**COMMON, **EXAMPLE} | {f"{k}.toml.tmpl": None for k in KINDS})


def test_python_m_workbench_is_the_cli():
    """``python -m workbench`` runs the same CLI: a bad design path exits 2 with
    one line naming the file, no traceback."""
    import subprocess
    import sys
    r = subprocess.run([sys.executable, "-m", "workbench", "verify", "no-such-design.toml"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2
    assert "no-such-design.toml" in r.stderr and "Traceback" not in r.stderr
