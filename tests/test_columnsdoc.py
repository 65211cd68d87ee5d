"""docs/columns.md and the column dicts it is rendered from (pipeline/columnsdoc.py): the committed
page is the rendered one, every column of every dict is on it, a column added to a dict changes
it, units are read from descriptions, and the command line writes and checks the page."""

from __future__ import annotations

import subprocess
import sys

import pytest
from conftest import ROOT

from particle_entropy.analysis import aggregate, claims, optimum, scene_search
from particle_entropy.core import case, columns, records
from particle_entropy.figures import fig10, style
from particle_entropy.pipeline import columnsdoc
from particle_entropy.pipeline.columnsdoc import COMMAND, PAGE, main, render, sections, split_unit

REGENERATE = f"run `{COMMAND} {PAGE}` from the repository root to regenerate it"
MODULES = {  # the module names the page cites as sources of its columns
    "columns": columns,
    "aggregate": aggregate,
    "optimum": optimum,
    "scene_search": scene_search,
    "style": style,
    "fig10": fig10,
    "columnsdoc": columnsdoc,
}
KEYED = {  # held to the column names of the code: case.CASE_COLUMNS, records.COLUMNS, claims.COLUMNS, ...
    "columns.CASE_COLUMN_DOCS",
    "columns.RECORD_COLUMN_DOCS",
    "columnsdoc.CLAIM_COLUMNS",
    "columnsdoc.PLAN_COLUMN_DOCS",
}
SOURCES = sorted({name for s in sections() for name, _ in s.parts})
UNITS = {"–", "T", "L", "nats", "1/L", "1/L²", "L²/T", "s", "MB", "kernel widths"}
UNITS |= {"per `x_name`", "per `y_name`", "L in a-c, 1/L in d-f"}  # the figure source data's


def _source(name: str) -> dict:
    module, attr = name.split(".")
    return getattr(MODULES[module], attr)


def _page_sections() -> dict[str, str]:
    """The committed page's sections by heading line."""
    blocks = ("\n" + (ROOT / PAGE).read_text(encoding="utf-8")).split("\n## ")[1:]
    return {"## " + b.splitlines()[0]: b for b in blocks}


def test_the_committed_page_is_the_rendered_one():
    assert (ROOT / PAGE).read_text(encoding="utf-8") == render(), f"{PAGE} differs from the column dicts: {REGENERATE}"


def test_every_column_of_every_dict_is_on_the_page():
    page = _page_sections()
    grouped = set(case.CASE_COLUMNS)
    for section in sections():
        heading = columnsdoc.render_section(section).splitlines()[0]
        assert heading in page, f"{heading}: not on {PAGE}; {REGENERATE}"
        rows = [line for line in page[heading].splitlines() if line.startswith("| `")]
        for source, part in section.parts:
            for column, description in part.items():
                if section.grouped and column in grouped:  # one row for the case columns, linked
                    assert any(f"`{column}`" in row.split(" | ")[0] for row in rows), (heading, column)
                    continue
                meaning, unit = split_unit(description)
                meaning = meaning.replace("|", "\\|")  # as the table escapes it
                row = f"| `{column}` | {meaning} | {unit} |"
                assert row in rows, f"{source}[{column!r}] is not on {PAGE} as it reads now: {REGENERATE}"


@pytest.mark.parametrize("source", SOURCES)
def test_a_column_added_to_a_dict_changes_the_page(source, monkeypatch):
    monkeypatch.setitem(_source(source), "brand_new_column", "a column no table has yet [T]")
    if source in KEYED:  # a meaning without a column of the module's list is refused
        with pytest.raises(ValueError, match="brand_new_column"):
            render()
        return
    text = render()
    assert "| `brand_new_column` | a column no table has yet | T |" in text
    assert text != (ROOT / PAGE).read_text(encoding="utf-8")


@pytest.mark.parametrize(("module", "attr"), [(records, "COLUMNS"), (claims, "COLUMNS"), (optimum, "PLAN_COLUMNS")])
def test_a_column_without_a_meaning_is_refused(module, attr, monkeypatch):
    monkeypatch.setattr(module, attr, [*getattr(module, attr), "brand_new_column"])
    with pytest.raises(ValueError, match="columns without a meaning: \\['brand_new_column'\\]"):
        render()


def test_every_source_the_page_names_is_a_dict_of_the_library():
    for name in SOURCES:
        assert isinstance(_source(name), dict), name


def test_units_are_trailing_brackets_and_known():
    assert split_unit("time at the end of the step [T]") == ("time at the end of the step", "T")
    assert split_unit("final lateral position, in [0, 1] [L]") == ("final lateral position, in [0, 1]", "L")
    assert split_unit("uniform on [-6, 6] drawn once") == ("uniform on [-6, 6] drawn once", "–")
    units = {split_unit(d)[1] for s in sections() for _, part in s.parts for d in part.values()}
    assert units <= UNITS, f"units no other column has (a bracket read as a unit?): {sorted(units - UNITS)}"


def test_the_command_line_writes_and_checks_the_page(tmp_path, monkeypatch, capsys):
    text = render()
    monkeypatch.chdir(ROOT)
    assert main(["--check"]) == 0
    out = tmp_path / "columns.md"
    assert main(["--write", str(out)]) == 0 and out.read_text(encoding="utf-8") == text
    assert main([]) == 0 and capsys.readouterr().out == text
    out.write_text(text.replace("| `seed` |", "| `seeds` |", 1), encoding="utf-8")
    assert main(["--check", str(out)]) == 1
    assert f"{COMMAND} {out}" in capsys.readouterr().err
    assert main(["--check", str(tmp_path / "absent.md")]) == 1
    assert "is missing" in capsys.readouterr().err


def test_the_module_runs_as_the_page_says():
    proc = subprocess.run(
        [sys.executable, "-m", "particle_entropy.pipeline.columnsdoc", "--check"],
        cwd=ROOT,
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr


def test_the_readme_and_the_page_name_the_case_folder_as_the_code_builds_it():
    """The README, the full output layout and this page spell a case's folder from case.CASE_DIR, every
    segment included (a grid~ segment was once missing from both)."""
    folder = columnsdoc.CASE_FOLDER
    assert folder.count("/") == 7 and folder.endswith("/grid~R")  # method, kernel and six dimensions
    assert folder in (ROOT / "README.md").read_text()
    assert folder in (ROOT / "docs" / "running.md").read_text()
    assert folder in (ROOT / "docs" / "columns.md").read_text()


def test_the_page_says_what_every_figure_plots():
    """Every figure that writes source data (all of figures.FIGURES but the searches) has its row in
    the shared table, or, the shear flow with columns of its own, a section."""
    from particle_entropy.figures import FIGURES

    named = {name for row in columnsdoc.FIGURE_CONTENTS for name in row[0].split(", ")}
    assert named == {f.name for f in FIGURES} - {"optimum", "fig10"}
    assert any("results/figures/fig10.parquet" in s.paths for s in sections())
