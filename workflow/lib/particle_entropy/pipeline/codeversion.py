"""Content hashes of the library code a task runs, so a workflow reruns exactly what an edit changes.

``code_version("figures.fig7")`` hashes figures/fig7.py and every package module it imports, directly or
not (found by reading the import statements, so a new import is followed without a list to
keep up to date). A rule that passes this hash as a parameter reruns when, and only when, the
content of that code changes: restoring a file's old content, or touching it, reruns nothing.
(Snakemake's own `code` trigger compares a script's modification time, so the workflow's
profile leaves it out and hashes the script here instead.) ``script_code("…/comic_tables.py")`` is a
rule's hash from its script alone: the script, the package modules it imports (read from it) and
their closure, so no rule lists its modules by hand.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import os
import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]  # particle_entropy/, above this subpackage


@functools.cache
def modules(package: Path = PACKAGE) -> dict[str, Path]:
    """Every module of the package and its subpackages by its dotted name below the package
    (``numerics.gauss``, ``cli``): two subpackages may hold modules of the same file name."""
    found: dict[str, Path] = {}
    for path in sorted(package.rglob("*.py")):
        if path.name == "__init__.py" or "__pycache__" in path.parts:
            continue
        found[".".join(path.relative_to(package).with_suffix("").parts)] = path
    return found


# a relative import: its dots, its module path and the names up to the end of the line or of the
# parenthesised list (comments and strings that look like one only add a module: never fewer)
_RELATIVE = re.compile(r"^[ \t]*from[ \t]+(\.+)([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)", re.M)


@functools.cache
def imports(module: str, package: Path = PACKAGE) -> frozenset[str]:
    """Package modules (dotted names) that ``module`` imports by relative imports (``from . import
    x``, ``from .x import y``, ``from ..sub.x import y``, ``from ..sub import x``), lazy ones
    included. Read by a pattern, not a parse: the workflow hashes its code at every start."""
    known = modules(package)
    here = module.split(".")[:-1]  # the subpackage the module sits in
    found = set()
    for dots, path, names in _RELATIVE.findall(known[module].read_text()):
        base = here[: len(here) - (len(dots) - 1)] if len(dots) - 1 <= len(here) else None
        if base is None:  # above the package: not one of its modules
            continue
        target = ".".join([*base, *filter(None, path.split("."))])
        if target in known:
            found.add(target)
        else:  # from a (sub)package: the names may be modules
            words = re.findall(r"\w+", names.split("#")[0] if not names.startswith("(") else names)
            found.update(f"{target}.{w}" if target else w for w in words)
    return frozenset(found & set(known))


def closure(entries, exclude=(), package: Path = PACKAGE) -> list[str]:
    """``entries`` and every package module they import, transitively; ``exclude`` (and what only
    they import) left out, e.g. the other methods' modules of the simulation driver."""
    seen, todo = set(), [e for e in entries if e not in exclude]
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        todo.extend(i for i in imports(m, package) if i not in seen and i not in exclude)
    return sorted(seen)


def code_version(*entries: str, exclude=(), files=(), package: Path = PACKAGE) -> str:
    """A short hash of the content of the modules in ``closure(entries, exclude)`` and of ``files``
    (a rule's script, say)."""
    h = hashlib.sha256()
    parts = [(m, modules(package)[m]) for m in closure(entries, exclude, package)]
    for name, path in parts + [(Path(f).name, Path(f)) for f in files]:
        h.update(name.encode() + b"\0" + Path(path).read_bytes() + b"\0")
    return h.hexdigest()[:16]


def script_imports(script, package: Path = PACKAGE) -> frozenset[str]:
    """Package modules (dotted names) that a rule's ``script`` imports by absolute imports (``from
    particle_entropy.core.io import x``, ``from particle_entropy.figures import fig10``, ``import
    particle_entropy.core.io``), lazy ones included. A Python script is parsed; a rule file, whose
    ``run:`` block imports (summarise.smk), is read by a pattern like ``imports``."""
    known, top = modules(package), package.name
    text = Path(script).read_text()
    found = []  # (module path below the package, names imported from it)
    if Path(script).suffix == ".py":
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == top:
                found.append((node.module.partition(".")[2], [a.name for a in node.names]))
            elif isinstance(node, ast.Import):
                found += [(a.name.partition(".")[2], []) for a in node.names if a.name.split(".")[0] == top]
    else:
        pattern = rf"^[ \t]*from[ \t]+{top}\.?([\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n#]*)"
        found = [(path, re.findall(r"\w+", names)) for path, names in re.findall(pattern, text, re.M)]
    hit = set()
    for path, names in found:  # from a (sub)package: the names may be modules
        hit.update([path] if path in known else (f"{path}.{n}" if path else n for n in names))
    return frozenset(hit & set(known))


def script_code(script, *also: str, exclude=(), package: Path = PACKAGE) -> str:
    """The code hash of a rule: its ``script`` (or the rule file of a ``run:`` block), the package
    modules it imports and all that they import (``code_version``). ``also``: modules the script
    picks by name when it runs (plot_figure.py draws figures.<name>, simulate.py runs models.<method>)."""
    return code_version(*script_imports(script, package), *also, exclude=exclude, files=[script], package=package)


def simulation_code(method: str, methods, script, package: Path = PACKAGE) -> str:
    """The code hash of a ``method`` simulation job: its ``script`` (simulate.py), what the script
    imports, and the method's module, the other ``methods``' modules left out (the driver imports
    them all, each run uses one)."""
    others = {f"models.{m}" for m in methods if m != method}
    return script_code(script, f"models.{method}", exclude=others, package=package)


def export_library_path(lib: str | Path) -> str:
    """Put ``lib`` first on PYTHONPATH for every job this process starts (once): jobs then import
    this checkout's library in any software environment (a venv, a conda env built by --sdm
    conda, a cluster node, where the plugin passes the environment on); the environments hold
    only the dependencies. Returns the new PYTHONPATH."""
    parts = [str(lib), *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
    os.environ["PYTHONPATH"] = os.pathsep.join(dict.fromkeys(parts))
    return os.environ["PYTHONPATH"]
