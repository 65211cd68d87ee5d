"""What a job reads is verified; a table behind a linked folder is checked; a machine that cannot
write is told in one line (issue 33, round 4)."""

from __future__ import annotations

import errno
import json
import os
import resource
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest
from conftest import ROOT, TINY, run_snakemake

import particle_entropy.pipeline.verify as verify
from particle_entropy.core.io import TableReadError, read_parquet, write_parquet
from particle_entropy.pipeline.verify import corrupt_tables, set_aside_corrupt

DF = pd.DataFrame({"step": np.arange(2000), "SSE": np.random.default_rng(0).random(2000)})
HOUR_NS = 3600 * 10**9


def _settled(path: Path) -> Path:
    """A table written an hour ago (its mtime set back): the digest cache vouches for it."""
    write_parquet(DF, path)
    old = path.stat().st_mtime_ns - HOUR_NS
    os.utime(path, ns=(old, old))
    return path


def _flip_in_a_data_page(path: Path) -> None:
    """Flip one bit in the middle of column SSE's pages, in place: same inode and size, mtime put back."""
    column = pq.ParquetFile(path).metadata.row_group(0).column(1)
    start = column.dictionary_page_offset or column.data_page_offset
    pos = start + column.total_compressed_size // 2
    before = path.stat()
    with open(path, "r+b") as f:
        f.seek(pos)
        byte = f.read(1)[0]
        f.seek(pos)
        f.write(bytes([byte ^ 0x10]))
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))
    after = path.stat()
    assert (after.st_size, after.st_mtime_ns, after.st_ino) == (before.st_size, before.st_mtime_ns, before.st_ino)


def _vouch(digests: Path, root: Path, path: Path) -> None:
    """Make the digest cache vouch for ``path`` as it is now, with the digest it had (bytes that
    decayed on the disk: no stamp of the file moved)."""
    entries = json.loads(digests.read_text())
    key = path.relative_to(root).as_posix()
    st = path.stat()
    entries["tables"][key][:-1] = [st.st_size, st.st_mtime_ns, st.st_ino, st.st_ctime_ns]
    digests.write_text(json.dumps(entries))


# --- case 1: every table a job reads verifies its page checksums -------------------------------


def test_the_verified_reader_refuses_a_flipped_page_byte_naming_the_table(tmp_path):
    path = _settled(tmp_path / "run.parquet")
    assert pq.ParquetFile(path).metadata.row_group(0).column(1).total_compressed_size > 1000
    _flip_in_a_data_page(path)
    assert not pd.read_parquet(path)["SSE"].equals(DF["SSE"])  # the unchecked read: other numbers, silently
    mtime = path.stat().st_mtime_ns
    with pytest.raises(TableReadError) as caught:
        read_parquet(path)
    message = str(caught.value)
    assert message.startswith(f"corrupt table {path}: ") and "CRC" in message and "\n" not in message
    assert "the next run sets it aside and rebuilds it" in message
    assert path.stat().st_mtime_ns == mtime  # Snakemake sees no change; only the ctime moved
    pd.testing.assert_frame_equal(read_parquet(tmp_path / "run.parquet", columns=["step"]), DF[["step"]])


def test_the_verified_reader_reads_what_pandas_reads(tmp_path):
    path = tmp_path / "t.parquet"
    frame = DF.assign(label=[f"x{k % 7}" for k in range(len(DF))])
    write_parquet(frame, path)
    pd.testing.assert_frame_equal(read_parquet(path), pd.read_parquet(path))
    with pytest.raises(TableReadError, match=r"^cannot read table .*missing\.parquet: No such file"):
        read_parquet(tmp_path / "missing.parquet")


def test_a_table_edited_in_place_with_its_mtime_put_back_is_set_aside(tmp_path):
    path = _settled(tmp_path / "runs" / "t.parquet")
    digests = tmp_path / "state" / "table_digests.json"
    assert corrupt_tables(tmp_path, digests) == {}  # remembered
    _flip_in_a_data_page(path)
    assert "differs from the recorded" in corrupt_tables(tmp_path, digests)[path]


def test_a_table_a_job_found_corrupt_is_set_aside_by_the_next_check(tmp_path):
    path = _settled(tmp_path / "runs" / "t.parquet")
    digests = tmp_path / "state" / "table_digests.json"
    corrupt_tables(tmp_path, digests)
    _flip_in_a_data_page(path)
    _vouch(digests, tmp_path, path)  # decay on the disk: the cache still vouches for it
    assert corrupt_tables(tmp_path, digests) == {}
    with pytest.raises(TableReadError):
        read_parquet(path)  # a job reads it
    lines = []
    assert set_aside_corrupt(tmp_path, digests, report=lines.append) == [path]
    assert "differs from the recorded" in lines[0] and (path.parent / "t.parquet.corrupt").exists()


SCRIPT = """
import sys
from particle_entropy.core.io import exit_on_table_errors, read_parquet
exit_on_table_errors()
read_parquet(sys.argv[1])
"""


def test_a_script_that_reads_a_corrupt_table_exits_with_one_line(tmp_path):
    path = _settled(tmp_path / "t.parquet")
    _flip_in_a_data_page(path)
    proc = subprocess.run([sys.executable, "-c", SCRIPT, str(path)], capture_output=True, text=True)
    assert proc.returncode == 1 and proc.stderr.startswith(f"corrupt table {path}: ")
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr


def test_every_job_script_and_analysis_reads_tables_through_the_verified_reader():
    readers = [
        *(ROOT / "workflow" / "scripts").glob("*.py"),
        *(ROOT / "workflow/lib/particle_entropy/analysis").glob("*.py"),
    ]
    for path in readers:
        text = path.read_text()
        assert "pd.read_parquet(" not in text and "pq.read_table(" not in text, path
        if path.parent.name == "scripts" and "read_parquet(" in text:
            assert "exit_on_table_errors()" in text, path


# --- case 2: a linked folder under results/ --------------------------------------------------


def test_a_truncated_table_behind_a_linked_folder_is_set_aside(tmp_path):
    results, elsewhere = tmp_path / "results", tmp_path / "disk2" / "runs"
    elsewhere.mkdir(parents=True)
    results.mkdir()
    (results / "runs").symlink_to(elsewhere, target_is_directory=True)
    good, bad = _settled(elsewhere / "good.parquet"), _settled(elsewhere / "bad.parquet")
    bad.write_bytes(bad.read_bytes()[:100])
    (elsewhere / "loop").symlink_to(results, target_is_directory=True)  # a loop back to results/
    digests = tmp_path / "table_digests.json"
    linked = results / "runs" / "bad.parquet"
    assert list(corrupt_tables(results, digests)) == [linked]
    assert sorted(json.loads(digests.read_text())["tables"]) == ["runs/good.parquet"]  # each table once
    assert set_aside_corrupt(results, digests, report=lambda line: None) == [linked]
    assert (elsewhere / "bad.parquet.corrupt").exists() and good.exists()
    assert verify.tables_below(results, ".parquet.corrupt") == [results / "runs" / "bad.parquet.corrupt"]


# --- case 3: a machine that cannot write ------------------------------------------------------


def _refuse(monkeypatch, folders, code, on_write=False):
    """Make files in ``folders`` fail with ``code``: when made, or (``on_write``) when written."""
    real = verify.tempfile.TemporaryFile
    folders = {str(f) for f in folders}

    class Full:
        def __init__(self, f):
            self.f = f

        def write(self, data):
            raise OSError(code, os.strerror(code))

        def __getattr__(self, name):
            return getattr(self.f, name)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.f.close()

    def temporary(dir=None, **kw):
        if str(dir) in folders and not on_write:
            raise OSError(code, os.strerror(code), str(dir))
        f = real(dir=dir, **kw)
        return Full(f) if str(dir) in folders else f

    monkeypatch.setattr(verify.tempfile, "TemporaryFile", temporary)


def test_a_full_numba_cache_is_named_with_what_to_change(tmp_path, monkeypatch):
    cache = tmp_path / "numba"
    folders = verify.numba_cache_folders(tmp_path / "lib", {"NUMBA_CACHE_DIR": str(cache), "HOME": str(tmp_path)})
    assert folders[0] == cache
    _refuse(monkeypatch, [cache], errno.ENOSPC, on_write=True)
    message = verify.numba_cache_problem(folders)
    assert message.startswith(f"No space left for numba's cache of compiled kernels in {cache} (No space left")
    assert "set NUMBA_CACHE_DIR to a folder with room" in message and "\n" not in message


def test_a_read_only_numba_cache_falls_back_as_numba_does_and_none_writable_is_named(tmp_path, monkeypatch):
    env = {"NUMBA_CACHE_DIR": str(tmp_path / "ro"), "XDG_CACHE_HOME": str(tmp_path / "home_cache")}
    folders = verify.numba_cache_folders(tmp_path / "lib", env)
    _refuse(monkeypatch, folders[:1], errno.EROFS)
    assert verify.numba_cache_problem(folders) is None  # numba takes the __pycache__ beside the kernels
    _refuse(monkeypatch, folders, errno.EROFS)
    message = verify.numba_cache_problem(folders)
    assert message.startswith("numba has no writable folder for its cache of compiled kernels: ")
    assert all(f"{f} (Read-only file system)" in message for f in folders)
    assert message.endswith("set NUMBA_CACHE_DIR to a writable folder and rerun")


def test_a_read_only_working_directory_is_named(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _refuse(monkeypatch, ["results"], errno.EROFS)
    (line,) = verify.folder_problems([".snakemake", "results"])
    assert line.startswith(f"cannot write in results/ ({tmp_path / 'results'}): Read-only file system; ")
    assert "snakemake -d <folder>" in line


def test_a_run_with_no_room_for_numbas_cache_stops_before_any_job_in_one_line(tmp_path):
    def small_files():  # a 1 MB file-size limit: the numba cache's files do not fit, as on a full disk
        resource.setrlimit(resource.RLIMIT_FSIZE, (2**20, 2**20))

    cache = tmp_path / "numba_cache"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache)}
    proc = run_snakemake(tmp_path, configfile=TINY, env=env, preexec_fn=small_files, check=False)
    assert proc.returncode != 0 and f"No space left for numba's cache of compiled kernels in {cache}" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "results" / "runs").exists()


def test_a_run_that_cannot_write_results_stops_in_one_line(tmp_path):
    (tmp_path / "results").write_text("a file in the folder's place\n")
    proc = run_snakemake(tmp_path, configfile=TINY, check=False)
    assert proc.returncode != 0 and f"cannot write in results/ ({tmp_path / 'results'})" in proc.stderr
    assert "Traceback" not in proc.stderr
    dry = run_snakemake(tmp_path, configfile=TINY, dry_run=True, check=False)  # a dry run writes no results/
    assert "cannot write in results/" not in dry.stderr
