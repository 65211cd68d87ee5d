"""core/columns.py, the meanings of the run tables' columns: they follow the code's column names
key for key and in order, and no simulation or shear job imports them (nor pipeline/columnsdoc.py,
which holds the shear flow's), so editing a description reruns no simulation."""

from __future__ import annotations

import re

import pytest
from conftest import ROOT

from particle_entropy.core import case, columns, records
from particle_entropy.core.registry import METHODS
from particle_entropy.pipeline import columnsdoc
from particle_entropy.pipeline.codeversion import closure, modules, script_imports

SCRIPTS = ROOT / "workflow" / "scripts"
PRESENTATION = (
    "core.columns",
    "pipeline.columnsdoc",
)  # modules of column meanings that no job hashing a simulation may reach

# The code each simulation job hashes (codeversion.script_code: the modules its script imports, and
# for simulate.py the method's): (entry modules, the script the job runs). The script's own library
# imports are added below, so a job is held to all it runs, even what its hash does not follow.
SIMULATION_ENTRIES = tuple(sorted(script_imports(SCRIPTS / "simulate.py")))
SHEAR_ENTRIES = tuple(sorted(script_imports(SCRIPTS / "shear2d.py")))
JOBS = {
    **{f"simulate {m}": ((*SIMULATION_ENTRIES, f"models.{m}"), "simulate.py") for m in METHODS},
    "simulate_shear": (SHEAR_ENTRIES, "shear2d.py"),
}


def _script_imports(script: str) -> set[str]:
    """The library modules a workflow script imports (``from particle_entropy.core.io import ...``)."""
    text = (SCRIPTS / script).read_text()
    return set(re.findall(r"^\s*from particle_entropy\.([\w.]+) import", text, flags=re.M))


def test_the_job_scripts_imports_are_hashed():
    """Every library module a simulation script imports is one of the entries its hash follows."""
    for entries, script in JOBS.values():
        assert _script_imports(script) - {"core.case", "core.runconfig"} <= set(closure(entries)), script


@pytest.mark.parametrize("job", JOBS)
def test_no_simulation_job_imports_the_column_meanings(job):
    entries, script = JOBS[job]
    code = closure([*entries, *_script_imports(script)])
    assert {"core.case", "core.records"} <= set(code)  # what the job does need: the names and order of its columns
    assert not set(PRESENTATION) & set(code), f"{job} imports {sorted(set(PRESENTATION) & set(code))}"


def test_the_presentation_modules_are_package_modules():
    """closure() knows them by these names (else the test above could never fail)."""
    assert set(PRESENTATION) <= set(modules())
    assert "core.columns" in closure(["pipeline.columnsdoc"]) and "core.columns" in closure(["figures.style"])


def test_the_meanings_follow_the_code_s_columns_in_order():
    assert tuple(columns.CASE_COLUMN_DOCS) == case.CASE_COLUMNS
    assert tuple(columns.RECORD_COLUMN_DOCS) == records.COLUMNS
    assert all(isinstance(d, str) and d for d in [*columns.CASE_COLUMN_DOCS.values()])
    assert all(isinstance(d, str) and d for d in [*columns.RECORD_COLUMN_DOCS.values()])


def test_a_run_table_keeps_records_column_order():
    """Arrow tables put records.COLUMNS first in its order, then the others as given."""
    table = records.arrow_table({"SSE": [1.0], "extra": [2], "step": [0], "time": [0.5]}, {"method": "fd"}, 1)
    assert table.column_names == ["step", "time", "SSE", "extra", "method"]


def test_the_shear_meanings_live_outside_the_shear_job():
    from particle_entropy.models import shear2d

    assert not hasattr(shear2d, "STEP_COLUMNS") and not hasattr(shear2d, "STATE_COLUMNS")
    assert "wall_fraction" in columnsdoc.SHEAR_STEP_COLUMNS and "x" in columnsdoc.SHEAR_STATE_COLUMNS
    assert str(shear2d.WALL_BAND) in columnsdoc.SHEAR_STEP_COLUMNS["wall_fraction"]
