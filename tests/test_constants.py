"""A shared default is written in one place (issue 51): the fast Gauss transform's tolerance in
core/registry.py (``FGT_TOLERANCE``) and the particle cases' time-step growth in core/run_settings.py
(``DT_GROWTH``). Modules, rules, benchmarks and config.yaml's comments name the constant or import
it; a literal copy is one more place to edit when the default changes, and is found here.

Scanned: the tracked ``*.py`` and ``*.smk`` files, the Snakefile and config.yaml. Not scanned:
tests/, whose tests state the paper's values on purpose (an expectation written apart from the
code, e.g. test_registry's check that the default growth is the paper's) and whose inputs are
data (a case folder ``growth~1.05``, tolerances to sweep); the Markdown pages, whose numbers are
measurements or rendered by pipeline/prose.py; and the generated schema."""

from __future__ import annotations

import re
import subprocess

from conftest import ROOT

from particle_entropy.core.registry import FGT_TOLERANCE
from particle_entropy.core.run_settings import DT_GROWTH, PAPER

LITERALS = {
    "FGT_TOLERANCE": re.compile(r"(?<![\w.])1(?:\.0*)?[eE]-0*17(?![\w.])"),  # 1e-17, 1.0e-17, 1E-017
    "DT_GROWTH": re.compile(r"(?<![\w.])1\.050*(?![\w.])"),  # 1.05, 1.050; not 1.055, 11.05 or 1.05e3
}

# (file, text on the line): why that literal stays. Each entry must still match (test below).
ALLOWED = {
    ("workflow/lib/particle_entropy/core/registry.py", "FGT_TOLERANCE = 1e-17"): "the tolerance's one place",
    ("workflow/lib/particle_entropy/core/run_settings.py", "DT_GROWTH = 1.05"): "the growth's one place",
    ("config.yaml", "transfer_tolerance: 1.0e-17"): "a user setting: the shipped config states its value",
    ("config.yaml", "dt_growth: 1.05"): "a user setting: the shipped config states its value",
    ("config.yaml", "cost: [[1.005, 1.21], [1.0108, 0.593], [1.0232, 0.285], [1.05, 0.138]"): (
        "a growth search's measured cost table: 1.05 is one of its points, not a default"
    ),
    ("benchmarks/reactive_step.py", "[--growths 1.05 1.02 1.01 1.005]"): (
        "a sweep of growths given on the command line in the usage line, not a default"
    ),
}


def scanned() -> list[str]:
    """The tracked files this test reads (paths relative to the repository root)."""
    out = subprocess.run(
        ["git", "-C", str(ROOT), "ls-files", "*.py", "*.smk", "Snakefile", "config.yaml"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.split()
    return sorted(p for p in out if not p.startswith("tests/"))


def copies(path: str, text: str) -> list[tuple[str, str, int, str]]:
    """Each line of ``text`` holding a literal of LITERALS and not ALLOWED: (constant, path, line, text)."""
    found = []
    for number, line in enumerate(text.splitlines(), 1):
        for name, pattern in LITERALS.items():
            if pattern.search(line) and not any(p == path and s in line for p, s in ALLOWED):
                found.append((name, path, number, line.strip()))
    return found


def test_the_constants_are_the_defaults():
    assert PAPER["transfer_tolerance"] == FGT_TOLERANCE
    assert PAPER["dt_growth"] == DT_GROWTH


def test_each_default_is_written_once():
    files = scanned()
    assert "workflow/lib/particle_entropy/core/registry.py" in files and "config.yaml" in files
    found = [c for path in files for c in copies(path, (ROOT / path).read_text(encoding="utf-8"))]
    assert not found, "name the constant instead of its value:\n" + "\n".join(
        f"{path}:{number}: {line}  ({name})" for name, path, number, line in found
    )


def test_every_allowed_copy_is_still_there():
    """An entry whose line has gone is removed from ALLOWED, so the list cannot hide a new copy."""
    text = {path: (ROOT / path).read_text(encoding="utf-8") for path, _ in ALLOWED}
    gone = [(path, snippet) for path, snippet in ALLOWED if snippet not in text[path]]
    assert not gone


def test_a_copy_is_found_and_other_numbers_are_not():
    lines = [
        "tolerance = 1e-17",
        "    (1.0E-017 of the summed mass)",
        "dt = 0.01 * 1.05**174",
        "growth 1.050 by default",
        "dt_growth: 1.05",  # allowed in config.yaml only
        "x = 1.055, 11.05, 1.05e3, 1e-170, 21e-17, 1.5, 0.05",
    ]
    found = copies("workflow/lib/particle_entropy/numerics/new.py", "\n".join(lines))
    assert [(name, number) for name, _, number, _ in found] == [
        ("FGT_TOLERANCE", 1),
        ("FGT_TOLERANCE", 2),
        ("DT_GROWTH", 3),
        ("DT_GROWTH", 4),
        ("DT_GROWTH", 5),
    ]
    assert not copies("config.yaml", "  dt_growth: 1.05    # a user setting")
