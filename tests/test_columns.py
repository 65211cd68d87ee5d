"""core/columns.py, the meanings of the run tables' columns: they follow the code's column names
key for key and in order, and no simulation or shear job imports them (nor pipeline/columnsdoc.py,
which holds the shear flow's), so editing a description reruns no simulation."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from particle_entropy.core import case, columns, records
from particle_entropy.core.registry import METHODS
from particle_entropy.pipeline import columnsdoc
from particle_entropy.pipeline.codeversion import closure, modules

ROOT = Path(__file__).resolve().parents[1]
COMMON = ROOT / "workflow" / "rules" / "common.smk"
SCRIPTS = ROOT / "workflow" / "scripts"
PRESENTATION = ("columns", "columnsdoc")  # modules of column meanings that no job hashing a simulation may reach

# The code each simulation job hashes, as workflow/rules/common.smk builds SIM_CODE and SHEAR_CODE:
# (entry modules, the script the job runs). The script's own library imports are added below,
# so a job is held to all it runs, even what its hash does not follow.
JOBS = {
    **{f"simulate {m}": (("simulate", "io", m), "simulate.py") for m in METHODS},
    "simulate_shear": (("shear2d", "io"), "shear2d.py"),
}


def _script_imports(script: str) -> set[str]:
    """The library modules a workflow script imports (``from particle_entropy.core.io import ...``)."""
    text = (SCRIPTS / script).read_text()
    return {m.split(".")[-1] for m in re.findall(r"^\s*from particle_entropy\.([\w.]+) import", text, flags=re.M)}


def test_common_smk_hashes_the_entries_these_tests_hold():
    """If SIM_CODE or SHEAR_CODE change their entries, JOBS above must follow them."""
    text = COMMON.read_text()
    assert 'code_version("simulate", "io", m, exclude=set(METHODS) - {m}, files=[SCRIPTS / "simulate.py"])' in text
    assert 'SHEAR_CODE = code_version("shear2d", "io", files=[SCRIPTS / "shear2d.py"])' in text


@pytest.mark.parametrize("job", JOBS)
def test_no_simulation_job_imports_the_column_meanings(job):
    entries, script = JOBS[job]
    code = closure([*entries, *_script_imports(script)])
    assert {"case", "records"} <= set(code)  # what the job does need: the names and order of its columns
    assert not set(PRESENTATION) & set(code), f"{job} imports {sorted(set(PRESENTATION) & set(code))}"


def test_the_presentation_modules_are_package_modules():
    """closure() knows them by these names (else the test above could never fail)."""
    assert set(PRESENTATION) <= set(modules())
    assert "columns" in closure(["columnsdoc"]) and "columns" in closure(["style"])


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
    from particle_entropy.experiments import shear2d

    assert not hasattr(shear2d, "STEP_COLUMNS") and not hasattr(shear2d, "STATE_COLUMNS")
    assert "wall_fraction" in columnsdoc.SHEAR_STEP_COLUMNS and "x" in columnsdoc.SHEAR_STATE_COLUMNS
    assert str(shear2d.WALL_BAND) in columnsdoc.SHEAR_STEP_COLUMNS["wall_fraction"]
