"""pipeline/preflight.py: the main process's checks while the Snakefile is read, and the one place
that may move files then (corrupt tables set aside); a command that will not run jobs only looks.
The workflow-level behaviour is tested in tests/test_workflow.py and tests/test_invocation.py."""

from __future__ import annotations

import re

import pytest
from snakemake.io import regex_from_filepattern

from particle_entropy.core.case import Case
from particle_entropy.pipeline import preflight as P
from particle_entropy.pipeline.sweeps import RUN_PATTERN, SUMMARY_PATTERN, run_path


@pytest.mark.parametrize("pattern", [RUN_PATTERN, SUMMARY_PATTERN])
def test_a_path_pattern_matches_as_snakemake_matches_it(pattern):
    case = Case("mtpt", "collision", 1000)
    path = pattern.format(kind="runs", first=0, last=3, nreal=20, **case.wildcards())
    ours = P.NAMED_BY_PATH[[RUN_PATTERN, SUMMARY_PATTERN].index(pattern)][0].match(path)
    theirs = re.match(regex_from_filepattern(pattern), path)
    assert ours and theirs and ours.groupdict() == theirs.groupdict()


def test_a_table_path_names_its_columns():
    case = Case("mtpt", "collision", 1000)
    named = P.named_columns(run_path(case, 4, 7))
    assert named["method"] == "mtpt" and named["n"] == 1000 and named["seed"] == (4, 7)
    assert "seed" not in P.named_columns(SUMMARY_PATTERN.format(nreal=3, **case.wildcards()))
    assert P.named_columns("results/figures/fig3.parquet") is None


def test_only_a_command_that_runs_jobs_without_a_held_lock_may_change_tables(tmp_path):
    locks = tmp_path / "locks"
    assert P.looks_only(True, None, locks)  # a dry run
    assert P.looks_only(False, {"unlock": True}, locks)  # a command that runs no job
    assert not P.looks_only(False, None, locks) and not P.looks_only(False, {"targets": []}, locks)
    locks.mkdir()
    assert not P.looks_only(False, None, locks)  # an empty lock folder holds no lock
    (locks / "0.output.lock").write_text("results/x.parquet\n")
    assert P.looks_only(False, None, locks)


def test_the_crate_is_requested_by_its_rule_or_a_path_in_its_folder():
    assert P.crate_requested(None)  # the API: it may be
    assert P.crate_requested({"targets": ["crate"]}) and P.crate_requested({"targets": ["results/ro-crate/x"]})
    assert not P.crate_requested({"targets": ["figures/fig3.png"]}) and not P.crate_requested({"targets": None})


def test_a_look_only_scan_moves_nothing_and_names_the_tables_set_aside(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / "tables").mkdir(parents=True)
    aside = tmp_path / "results" / "tables" / "comic.parquet.corrupt"
    aside.write_bytes(b"PAR1 broken")
    rebuilt = tmp_path / "results" / "tables" / "old.parquet"
    (tmp_path / "results" / "tables" / "old.parquet.corrupt").write_bytes(b"x")
    rebuilt.write_bytes(b"rebuilt since")
    bad = tmp_path / "results" / "tables" / "bad.parquet"
    bad.write_bytes(b"PAR1 truncated")
    assert P.set_aside_corrupt_tables("results", look_only=True) == ["results/tables/comic.parquet"]
    assert bad.exists()  # only looked


def test_a_dry_run_preflight_holds_no_lock_and_moves_nothing(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    bad = tmp_path / "results" / "runs" / "x.parquet"
    bad.parent.mkdir(parents=True)
    bad.write_bytes(b"PAR1 truncated")
    assert P.preflight(True, ["pytest"], local=True, library=tmp_path) == []
    assert bad.exists() and not (tmp_path / "results" / ".run.lock").exists()


def test_a_folder_that_cannot_be_written_raises_the_given_error(tmp_path, monkeypatch):
    class Refused(Exception):
        pass

    monkeypatch.chdir(tmp_path)
    (tmp_path / ".snakemake").write_text("a file where Snakemake keeps its state")
    with pytest.raises(Refused, match=".snakemake"):
        P.preflight(True, ["pytest"], local=True, library=tmp_path, error=Refused)


def test_a_run_with_a_folder_at_its_lock_path_is_refused_before_any_change(tmp_path, monkeypatch):
    class Refused(Exception):
        pass

    monkeypatch.chdir(tmp_path)
    (tmp_path / "results" / ".run.lock").mkdir(parents=True)
    bad = tmp_path / "results" / "runs" / "x.parquet"
    bad.parent.mkdir(parents=True)
    bad.write_bytes(b"PAR1 truncated")
    with pytest.raises(Refused, match=r"results/\.run\.lock is no lock file \(it is a folder\)"):
        P.preflight(False, ["snakemake", "-j2"], local=True, library=tmp_path, error=Refused)
    assert bad.exists()  # refused before any table was judged
