"""The library's layout: subpackages in layers, each importing only from the layers below it."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import particle_entropy

PACKAGE = Path(particle_entropy.__file__).parent
LAYERS = ["core", "numerics", "models", "experiments", "scenes", "analysis", "figures", "pipeline"]  # bottom up


def _imported_packages(path: Path) -> set[str]:
    """The subpackages (or the top level, "") that a module's relative imports reach, lazy ones
    inside functions included."""
    here = path.parent.name if path.parent != PACKAGE else ""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            if node.level == 1:
                out.add(here)
            else:
                out.add((node.module or "").split(".")[0])
    return out


MODULES = sorted(p for p in PACKAGE.rglob("*.py") if "__pycache__" not in p.parts)


def test_every_module_lives_in_a_layer():
    loose = {p.name for p in PACKAGE.glob("*.py")} - {"__init__.py", "__main__.py", "cli.py"}
    assert loose == set()
    assert {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()} == set(LAYERS)


@pytest.mark.parametrize("path", [p for p in MODULES if p.parent != PACKAGE], ids=lambda p: p.stem)
def test_imports_point_down(path):
    own = LAYERS.index(path.parent.name)
    for target in _imported_packages(path):
        assert target in LAYERS, f"{path.stem} imports from {target or 'the top level'}"
        assert LAYERS.index(target) <= own, f"{path.parent.name}.{path.stem} imports upward from {target}"


@pytest.mark.parametrize("layer", LAYERS)
def test_each_layer_says_what_it_is(layer):
    doc = ast.get_docstring(ast.parse((PACKAGE / layer / "__init__.py").read_text()))
    assert doc and len(doc.split()) >= 20


@pytest.mark.parametrize("path", MODULES, ids=lambda p: p.stem)
def test_no_module_imports_private_names(path):
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            private = [a.name for a in node.names if a.name.startswith("_")]
            assert not private, f"{path.stem} imports private {private} from {node.module}"


def _module_name(path: Path) -> str:
    """A module's dotted name: particle_entropy.pipeline.config (a package: its __init__'s)."""
    parts = list(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _import_graph() -> dict[str, set[str]]:
    """Each of the library's modules -> the library's modules it imports: relative and absolute
    imports, at the top and inside functions alike (a lazy import closes a circle as surely, it only
    hides it); ``from pkg import name`` reaches the module pkg.name where there is one, else pkg."""
    modules = {_module_name(p): p for p in MODULES}
    graph = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        out = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                base = package.split(".")[: len(package.split(".")) - node.level + 1] if node.level else []
                target = ".".join([*base, *([node.module] if node.module else [])])
                out |= {f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target for a in node.names}
            elif isinstance(node, ast.Import):
                out |= {a.name for a in node.names}
        graph[name] = {m for m in out if m in modules and m != name}
    return graph


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles of ``graph``: each group of modules that reach one another, sorted."""
    reach = {}
    for start in graph:
        seen, todo = set(), list(graph[start])
        while todo:
            m = todo.pop()
            if m not in seen:
                seen.add(m)
                todo.extend(graph.get(m, ()))
        reach[start] = seen
    groups = {frozenset(m for m in reach[start] if start in reach[m]) for start in graph if start in reach[start]}
    return sorted(sorted(g) for g in groups)


def test_the_import_graph_sees_lazy_imports_and_circles():
    graph = _import_graph()
    assert "particle_entropy.pipeline.crosschecks" in graph["particle_entropy.pipeline.configcheck"]
    # imported inside a function only: the reference cost's plan
    assert "particle_entropy.scenes.reference" in graph["particle_entropy.scenes.checks"]
    assert _cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_no_module_imports_one_that_imports_it_back():
    """No circle of imports between the library's modules, lazy ones included: each module can be
    read, tested and moved knowing only what it imports (a circle's modules load only in one order)."""
    assert _cycles(_import_graph()) == []
