"""The library's layout: subpackages in layers, each importing only from the layers below it."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

import particle_entropy

PACKAGE = Path(particle_entropy.__file__).parent
LAYERS = ["core", "numerics", "models", "experiments", "analysis", "figures", "pipeline"]  # bottom up


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
