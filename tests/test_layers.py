"""The package's layers, read from the source with ``ast`` (nothing is imported).

Every ``import`` counts, at module level, inside functions and under
``if TYPE_CHECKING:``. The rules are the layer map of the README:

    errors, reader, outcome (the closed sets of outcomes), jsonable  <- plants <- symbolic, sim <- controllers
    lmi (LMIs only)      margins (exact methods only)
    crosscheck, synthesis, benchmark: the layer that calls both
    report (rendering only) <- features, tuning <- kinds <- papers <- design, verify, cli

``kinds`` holds the general design kinds and the registry (kind -> module),
``features`` the machinery several designs use (Monte Carlo, basin,
sampled-data check), ``tuning`` PID tuning and Pareto fronts, ``papers/pNNN``
the paper-specific studies. General code never imports a paper's.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parents[1] / "workbench"
#: One concept per module, about 500 lines as a guide (issue 35, item 4): a
#: module past it is a sign that it holds two concepts, and this test says so.
MAX_LINES = 500

#: package -> the packages (first component under workbench/) it may import.
ALLOWED = {
    "plants": {"plants", "errors"},
    "symbolic": {"symbolic", "plants", "errors", "outcome", "jsonable"},
    "lmi": {"lmi", "errors", "outcome", "printed_grid"},   # printed_grid: a leaf (math, numpy)
    "margins": {"margins", "errors"},
    "sim": {"sim", "plants", "errors"},
    "controllers": {"controllers", "sim", "plants", "errors"},
    "report": {"report", "claims", "errors", "outcome", "printed_grid"},
    "roa": {"roa", "errors", "outcome", "printed_grid"},
}

#: (importer package, imported package) pairs the issue names explicitly.
FORBIDDEN = [("lmi", "margins"), ("margins", "lmi"), ("sim", "kinds"), ("sim", "papers"),
             ("sim", "report"), ("sim", "design"), ("report", "lmi"), ("report", "sim"),
             ("report", "kinds"), ("report", "papers"), ("report", "margins")]

#: (importer package, imported package) pairs the package layout forbids (issue 35):
#: the general machinery never imports a paper's code, nor a feature a kind.
GENERAL = [("kinds", "papers"), ("features", "papers"), ("tuning", "papers"),
           ("features", "kinds"), ("tuning", "kinds"), ("tuning", "features")]


def _modules() -> dict[str, Path]:
    out = {}
    for p in sorted(PKG.rglob("*.py")):
        parts = list(p.relative_to(PKG.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = p
    return out


MODULES = _modules()


def _imports(name: str, path: Path) -> list[tuple[str, str, int]]:
    """(imported module, imported name or "", line) of every workbench import."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    is_pkg = path.name == "__init__.py"
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(a.name, "", node.lineno) for a in node.names if a.name.startswith("workbench")]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = name.split(".") if is_pkg else name.split(".")[:-1]
                base = base[:len(base) - (node.level - 1)]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.startswith("workbench"):
                out += [(mod, a.name, node.lineno) for a in node.names]
    return out


def _resolve(mod: str, name: str) -> str:
    """The workbench module an import loads (``from pkg import module`` -> module)."""
    if name and f"{mod}.{name}" in MODULES:
        return f"{mod}.{name}"
    while mod not in MODULES and "." in mod:
        mod = mod.rsplit(".", 1)[0]
    return mod


def _package(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


#: module -> the workbench modules it imports; filled before the first test of
#: this file runs (parsing every module at import would cost each xdist worker's
#: collection ~0.5 s, also the workers that run none of these tests)
GRAPH: dict[str, set[str]] = {}


@pytest.fixture(autouse=True, scope="module")
def _graph():
    if not GRAPH:
        GRAPH.update({m: {_resolve(mod, n) for mod, n, _ in _imports(m, p)} - {m}
                      for m, p in MODULES.items()})


def _cycles() -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in GRAPH[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    return out


def test_the_parser_sees_function_level_and_relative_imports():
    # the controller imports the stepping kernel at module level, the study
    # registry loads studies by name only, and a study's render module
    # imports its study (function level in some)
    assert "workbench.sim.wheel_slip" in GRAPH["workbench.controllers.antiskid003"]
    p003 = "workbench.papers.p003."
    assert p003 + "antiskid_run_spec" in GRAPH[p003 + "antiskid_montecarlo"]
    assert p003 + "antiskid_cruise" in GRAPH[p003 + "antiskid_cruise_render"]
    assert len(MODULES) > 60


def test_no_import_cycle():
    assert _cycles() == []


def test_a_cycle_would_be_found(monkeypatch):
    monkeypatch.setitem(GRAPH, "workbench.errors", GRAPH["workbench.errors"] | {"workbench.cli"})
    assert any("workbench.errors" in c for c in _cycles())


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_layer_imports_only_what_the_map_allows(layer):
    bad = [f"{m} -> {t}" for m in sorted(GRAPH) if _package(m) == layer
           for t in sorted(GRAPH[m]) if _package(t) not in ALLOWED[layer]]
    assert bad == []


@pytest.mark.parametrize("src,dst", FORBIDDEN, ids=[f"{a}-not-{b}" for a, b in FORBIDDEN])
def test_forbidden_edges(src, dst):
    assert dst not in ALLOWED[src]          # the map itself forbids it ...
    bad = [f"{m} -> {t}" for m in GRAPH if _package(m) == src
           for t in GRAPH[m] if _package(t) == dst]
    assert bad == []                        # ... and the code obeys


@pytest.mark.parametrize("src,dst", GENERAL, ids=[f"{a}-not-{b}" for a, b in GENERAL])
def test_general_machinery_respects_the_layout(src, dst):
    bad = [f"{m} -> {t}" for m in GRAPH if _package(m) == src
           for t in GRAPH[m] if _package(t) == dst]
    assert bad == []


def _subpackage(module: str) -> str:
    """The sub-package of a module ("" for the top-level modules of workbench/)."""
    parent = MODULES[module].parent
    return "" if parent == PKG else parent.name


def test_no_private_name_imported_across_packages():
    bad = []
    for m, p in MODULES.items():
        for mod, name, line in _imports(m, p):
            target = _resolve(mod, name)
            if name.startswith("_") and _subpackage(target) != _subpackage(m):
                bad.append(f"{p.relative_to(PKG.parent)}:{line} imports {name} from {mod}")
    assert bad == []


def test_no_module_over_the_size_limit():
    sizes = {m: len(p.read_text(encoding="utf-8").splitlines()) for m, p in MODULES.items()}
    assert {m: n for m, n in sizes.items() if n > MAX_LINES} == {}


def test_every_study_kind_has_a_renderer_and_no_study_imports_its_renderer():
    from workbench import kinds
    assert set(kinds.RENDERERS) == set(kinds.STUDIES)
    for kind, spec in kinds.RENDERERS.items():
        render_mod = spec.split(":")[0]
        study_mod = kinds.STUDIES[kind].split(":")[0]
        assert render_mod in MODULES
        if render_mod != study_mod:
            assert render_mod not in GRAPH[study_mod], kind


def test_the_readme_layer_map_names_every_package():
    readme = (PKG.parent / "README.md").read_text(encoding="utf-8")
    section = readme.split("## Layers", 1)[1].split("\n## ", 1)[0]
    packages = {p.name for p in PKG.iterdir() if p.is_dir() and (p / "__init__.py").is_file()
                and not p.name.startswith("_")}
    missing = [p for p in sorted(packages) if f"`{p}/`" not in section]
    assert missing == []
