"""The pinned environment: requirements.lock pins every dependency exactly and is what is
installed; the conda environment lists the same dependencies and nothing Snakemake cannot build."""

from __future__ import annotations

import re
import tomllib
from importlib.metadata import version

import yaml
from conftest import ROOT

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
CONDA_NAMES = {"matplotlib": "matplotlib-base", "snakemake": "snakemake-minimal"}  # conda-forge's slim builds


def _name(requirement: str) -> str:
    return re.split(r"[<>=!~\[ ;]", requirement, maxsplit=1)[0].strip().lower().replace("_", "-")


def _lock() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "requirements.lock").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, _, exact = line.partition("==")
            assert exact, f"not an exact pin: {line!r}"
            pins[name.strip().lower().replace("_", "-")] = exact.strip()
    return pins


def test_lock_pins_every_dependency_and_test_tool():
    direct = {_name(r) for r in PYPROJECT["dependencies"] + PYPROJECT["optional-dependencies"]["test"]}
    missing = direct - set(_lock())
    assert not missing, f"add to requirements.lock: {sorted(missing)}"


def test_installed_versions_are_the_locked_ones():
    """The README's set-up installs with -c requirements.lock: the direct dependencies must match."""
    pins = _lock()
    direct = {_name(r) for r in PYPROJECT["dependencies"] + PYPROJECT["optional-dependencies"]["test"]}
    wrong = {n: (version(n), pins[n]) for n in direct if version(n) != pins[n]}
    assert not wrong, f"installed != locked: {wrong}"


def test_conda_environment_has_the_dependencies_and_no_relative_pip_install():
    env = yaml.safe_load((ROOT / "envs" / "particle-entropy.yaml").read_text())
    listed = {_name(d) for d in env["dependencies"] if isinstance(d, str)}
    for dep in PYPROJECT["dependencies"]:
        assert CONDA_NAMES.get(_name(dep), _name(dep)) in listed, dep
    # Snakemake builds the env from a copy in a temporary folder: a relative path would break
    assert not [d for d in env["dependencies"] if isinstance(d, dict)], "no pip section (-e ../ breaks there)"
