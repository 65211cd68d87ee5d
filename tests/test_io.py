"""Table output: atomic, flushed, checksummed, never over a non-regular file; corrupt tables found."""

from __future__ import annotations

import hashlib
import json
import os
import random
import stat
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import particle_entropy.pipeline.verify as verify
from particle_entropy.core.io import OutputError, check_output_path, checksum_path, write_parquet
from particle_entropy.pipeline.verify import corrupt_tables, set_aside, table_problem

DF = pd.DataFrame({"step": range(50), "SSE": [0.5 / (k + 1) for k in range(50)], "label": ["a"] * 50})


def test_table_and_its_checksum_are_written_and_byte_stable(tmp_path):
    a, b = tmp_path / "a.parquet", tmp_path / "sub" / "b.parquet"
    write_parquet(DF, a)
    write_parquet(DF, b)
    assert a.read_bytes() == b.read_bytes()
    digest = hashlib.sha256(a.read_bytes()).hexdigest()
    assert checksum_path(a).read_text() == f"{digest}  a.parquet\n"
    pd.testing.assert_frame_equal(pd.read_parquet(a), DF)
    assert table_problem(a) is None


def test_stale_temporaries_of_a_table_are_removed(tmp_path):
    target = tmp_path / "t.parquet"
    stale = [tmp_path / ".t.parquet.x1y2.tmp", tmp_path / ".t.parquet.sha256.q9.tmp"]
    other = tmp_path / ".u.parquet.zz.tmp"  # another table's: not this write's business
    for f in [*stale, other]:
        f.write_bytes(b"half a table")
    write_parquet(DF, target)
    assert not any(f.exists() for f in stale) and other.exists()


def test_non_regular_targets_are_refused_and_left_alone(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(OutputError, match="not a regular file"):
        write_parquet(DF, fifo)
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    link = tmp_path / "link.parquet"
    link.symlink_to(fifo)  # a link to a pipe (or to /dev/null) is refused the same way
    with pytest.raises(OutputError, match="not a regular file"):
        check_output_path(link)
    with pytest.raises(OutputError, match="is a directory"):
        write_parquet(DF, tmp_path)


def test_every_single_bit_flip_and_truncation_is_found(tmp_path):
    path = tmp_path / "t.parquet"
    write_parquet(DF, path)
    data = path.read_bytes()
    rng = random.Random(0)
    for _ in range(200):
        flipped = bytearray(data)
        pos = rng.randrange(len(flipped))
        flipped[pos] ^= 1 << rng.randrange(8)
        path.write_bytes(bytes(flipped))
        assert table_problem(path) is not None, pos
    for size in (0, 100, len(data) - 1):
        path.write_bytes(data[:size])
        assert "differs from the recorded" in table_problem(path)
    path.write_bytes(data)
    assert table_problem(path) is None


def test_tables_without_a_checksum_are_judged_by_their_magic_bytes(tmp_path):
    path = tmp_path / "old.parquet"
    write_parquet(DF, path)
    checksum_path(path).unlink()
    assert table_problem(path) is None
    path.write_bytes(path.read_bytes()[:100])
    assert "not a whole Parquet file" in table_problem(path)


def _case_table(n_rows: int = 2000, **columns) -> pd.DataFrame:
    rng = np.random.default_rng(0)
    df = pd.DataFrame({"step": np.arange(n_rows), "SSE": rng.random(n_rows), "H_C": rng.normal(size=n_rows)})
    return df.assign(**{k: v for k, v in columns.items()})


def test_without_its_checksum_a_table_is_read_whole_and_a_flipped_page_byte_is_found(tmp_path):
    # the case: no .sha256 and one flipped byte; the magic bytes are intact, so only
    # reading the pages (with the CRC32 write_parquet puts in each page header) finds it
    path = tmp_path / "t.parquet"
    write_parquet(_case_table(), path)
    checksum_path(path).unlink()
    data = path.read_bytes()
    rng = random.Random(1)
    found = 0
    for _ in range(100):
        flipped = bytearray(data)
        pos = rng.randrange(4, len(data) - 4)  # never the magic bytes
        flipped[pos] ^= 1 << rng.randrange(8)
        path.write_bytes(bytes(flipped))
        found += table_problem(path) is not None
    assert found >= 95  # measured 297 of 300 on a run table; without page checksums 9 of 300
    path.write_bytes(data)
    assert table_problem(path) is None


@pytest.mark.parametrize(
    "sidecar",
    ["folder", "not utf-8", "empty", "foreign text", "a short hex word"],
)
def test_a_bad_checksum_file_is_treated_as_missing_never_as_a_crash(tmp_path, sidecar):
    good, bad = tmp_path / "good.parquet", tmp_path / "bad.parquet"
    for path in (good, bad):
        write_parquet(DF, path)
        record = checksum_path(path)
        record.unlink()
        if sidecar == "folder":
            record.mkdir()
        else:
            content = {"not utf-8": b"\xff\xfe\x00", "empty": b"", "foreign text": b"hello world\n"}
            record.write_bytes(content.get(sidecar, b"abc123  bad.parquet\n"))
    bad.write_bytes(bad.read_bytes()[:-30] + b"PAR1")  # footer cut, magic bytes kept
    assert verify.recorded_digest(good) is None
    assert table_problem(good) is None  # read whole: sound
    assert list(corrupt_tables(tmp_path)) == [bad] and "cannot be read whole" in corrupt_tables(tmp_path)[bad]


def test_another_cases_table_in_its_place_is_found_by_its_columns(tmp_path):
    here = tmp_path / "runs" / "n~100" / "seeds~0-3.parquet"
    write_parquet(_case_table(n=100, seed=np.repeat(np.arange(4), 500)), here)
    expected = lambda path: {"n": 100, "kernel": "collision", "seed": (0, 3)} if "n~100" in str(path) else None
    assert corrupt_tables(tmp_path, expected=expected) == {}
    # a valid table of N = 300 copied over it with its matching checksum: the bytes are whole
    write_parquet(_case_table(n=300, seed=np.repeat(np.arange(4), 500)), here)
    assert table_problem(here) is None
    problem = corrupt_tables(tmp_path, expected=expected)[here]
    assert "its column n holds [300], its path names 100" in problem
    # the right case with seeds outside its block
    write_parquet(_case_table(n=100, seed=np.repeat(np.arange(2, 6), 500)), here)
    assert "column seed holds 4, outside the 0-3" in corrupt_tables(tmp_path, expected=expected)[here]
    # a missing value where the path names none (truncation none is stored as NaN or null)
    assert verify.content_problem(here, {"n": 100}) is None
    write_parquet(_case_table(truncation=np.nan), here)
    assert verify.content_problem(here, {"truncation": None}) is None
    assert "its path names 3.0" in verify.content_problem(here, {"truncation": 3.0})


def test_a_remembered_table_is_not_read_for_its_columns_again(tmp_path, monkeypatch):
    here = tmp_path / "runs" / "t.parquet"
    write_parquet(_case_table(n=100), here)
    os.utime(here, ns=(10**18, 10**18))  # settled: remembered after its first check
    digests = tmp_path / "digests.json"
    calls = []
    expected = lambda path: calls.append(path) or {"n": 100}
    assert corrupt_tables(tmp_path, digests, expected) == {} and len(calls) == 1
    assert corrupt_tables(tmp_path, digests, expected) == {} and len(calls) == 1


def test_a_table_that_cannot_be_moved_aside_stops_with_one_line(tmp_path, monkeypatch):
    bad = tmp_path / "runs" / "bad.parquet"
    write_parquet(DF, bad)
    bad.write_bytes(bad.read_bytes()[:100])

    def refuse(src, dst):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(verify.os, "replace", refuse)
    with pytest.raises(verify.TableError) as err:
        verify.set_aside_corrupt(tmp_path)
    message = str(err.value)
    assert "bad.parquet" in message and "Permission denied" in message and "make its folder writable" in message
    assert bad.exists() and checksum_path(bad).exists()  # nothing changed
    monkeypatch.undo()
    lines = []
    assert verify.set_aside_corrupt(tmp_path, report=lines.append) == [bad]
    assert "moved to bad.parquet.corrupt" in lines[0]


def test_corrupt_tables_are_listed_and_set_aside(tmp_path):
    good, bad = tmp_path / "runs" / "good.parquet", tmp_path / "runs" / "deep" / "bad.parquet"
    write_parquet(DF, good)
    write_parquet(DF, bad)
    bad.write_bytes(bad.read_bytes()[:100])
    found = corrupt_tables(tmp_path)
    assert list(found) == [bad]
    moved = set_aside(bad)
    assert moved.name == "bad.parquet.corrupt" and moved.exists()
    assert not bad.exists() and not checksum_path(bad).exists()
    assert corrupt_tables(tmp_path) == {} and corrupt_tables(tmp_path / "missing") == {}


def test_a_folder_or_pipe_with_a_table_name_is_set_aside_without_reading_it(tmp_path):
    folder, pipe = tmp_path / "runs" / "a.parquet", tmp_path / "runs" / "b.parquet"
    folder.mkdir(parents=True)
    os.mkfifo(pipe)  # reading it would block for ever
    found = corrupt_tables(tmp_path)
    assert found == {folder: "it is a folder, not a table", pipe: "it is not a regular file"}
    (tmp_path / "runs" / "a.parquet.corrupt").mkdir()  # an older copy set aside before
    assert set_aside(folder).is_dir() and not folder.exists()
    assert corrupt_tables(tmp_path) == {pipe: "it is not a regular file"}


def test_a_folder_in_a_table_s_place_holding_a_table_is_set_aside_whole(tmp_path):
    """The table inside was judged after its folder had been moved aside, and the run stopped on
    "it cannot be moved aside (No such file or directory)"."""
    inner = tmp_path / "runs" / "a.parquet" / "inner.parquet"
    inner.parent.mkdir(parents=True)
    inner.write_bytes(b"PAR1 cut short")
    lines = []
    assert verify.set_aside_corrupt(tmp_path, report=lines.append) == [inner.parent]
    assert (tmp_path / "runs" / "a.parquet.corrupt" / "inner.parquet").exists() and len(lines) == 1


# --- digests remembered against size, mtime and inode (a workflow start rereads no unchanged table)

HOUR_NS = 3600 * 10**9


def _settled_tables(root, count):
    """``count`` tables written an hour ago (their mtime set back)."""
    paths = [root / "runs" / f"t{k}.parquet" for k in range(count)]
    for path in paths:
        write_parquet(DF, path)
        old = path.stat().st_mtime_ns - HOUR_NS
        os.utime(path, ns=(old, old))
    return paths


def _count_reads(monkeypatch):
    """The names of the tables hashed from now on, in order."""
    reads, real = [], verify.file_sha256

    def counted(path):
        reads.append(Path(path).name)
        return real(path)

    monkeypatch.setattr(verify, "file_sha256", counted)
    return reads


def _flip_in_place(path, pos):
    with open(path, "r+b") as f:  # same inode, same size
        f.seek(pos)
        byte = f.read(1)[0]
        f.seek(pos)
        f.write(bytes([byte ^ 1]))


def test_unchanged_tables_are_not_read_again(tmp_path, monkeypatch):
    paths = _settled_tables(tmp_path, 3)
    digests = tmp_path / "state" / "table_digests.json"
    reads = _count_reads(monkeypatch)
    assert corrupt_tables(tmp_path, digests) == {} and len(reads) == 3
    saved = digests.read_bytes()
    assert corrupt_tables(tmp_path, digests) == {} and len(reads) == 3  # nothing read again
    assert digests.read_bytes() == saved  # nor the digests file rewritten
    write_parquet(DF.head(10), paths[0])  # a new file renamed into place: new inode and mtime
    paths[2].unlink()
    checksum_path(paths[2]).unlink()
    assert corrupt_tables(tmp_path, digests) == {} and reads[3:] == ["t0.parquet"]
    assert sorted(json.loads(digests.read_text())["tables"]) == ["runs/t1.parquet"]  # t0 is too fresh


def test_a_table_written_moments_ago_is_read_again_next_time(tmp_path, monkeypatch):
    write_parquet(DF, tmp_path / "t.parquet")  # a second write in the same clock tick would keep its mtime
    digests = tmp_path / "table_digests.json"
    reads = _count_reads(monkeypatch)
    corrupt_tables(tmp_path, digests)
    assert corrupt_tables(tmp_path, digests) == {} and reads == ["t.parquet", "t.parquet"]


def test_a_flipped_byte_is_found_when_the_mtime_changed(tmp_path):
    (path,) = _settled_tables(tmp_path, 1)
    digests = tmp_path / "table_digests.json"
    assert corrupt_tables(tmp_path, digests) == {}
    before = path.stat()
    _flip_in_place(path, 100)  # the write sets the mtime to now
    after = path.stat()
    assert (after.st_ino, after.st_size) == (before.st_ino, before.st_size) and after.st_mtime_ns != before.st_mtime_ns
    assert "differs from the recorded" in corrupt_tables(tmp_path, digests)[path]


def test_a_change_keeping_size_mtime_and_inode_is_found_by_its_ctime(tmp_path):
    (path,) = _settled_tables(tmp_path, 1)
    digests = tmp_path / "table_digests.json"
    corrupt_tables(tmp_path, digests)
    before = path.stat()
    _flip_in_place(path, 100)
    os.utime(path, ns=(before.st_atime_ns, before.st_mtime_ns))  # the mtime set back by hand
    after = path.stat()
    assert (after.st_size, after.st_mtime_ns, after.st_ino) == (before.st_size, before.st_mtime_ns, before.st_ino)
    assert "differs from the recorded" in corrupt_tables(tmp_path, digests)[path]  # the ctime moved: hashed again


def test_a_remembered_digest_never_condemns_a_good_table(tmp_path):
    (path,) = _settled_tables(tmp_path, 1)
    digests = tmp_path / "table_digests.json"
    corrupt_tables(tmp_path, digests)
    entries = json.loads(digests.read_text())
    good = entries["tables"]["runs/t0.parquet"][4]
    entries["tables"]["runs/t0.parquet"][4] = "0" * 64
    digests.write_text(json.dumps(entries))
    assert corrupt_tables(tmp_path, digests) == {}  # reread before it is judged
    assert json.loads(digests.read_text())["tables"]["runs/t0.parquet"][4] == good


@pytest.mark.parametrize(
    "content",
    [
        b"",  # lost in a crash
        b'{"version": 1, "tables": {"runs/t0.parquet": [1, 2',  # cut short
        b"\xff\xfe\x00 not text",
        b"[1, 2, 3]",
        b'{"version": 99, "tables": {}}',
        b'{"version": 1, "tables": {"runs/t0.parquet": ["x", 0, 0, 0], "runs/t1.parquet": 5}}',
        b"[" * 100_000,  # nested too deep to parse
    ],
)
def test_a_damaged_digests_file_is_ignored_and_rebuilt(tmp_path, content):
    good, bad = _settled_tables(tmp_path, 2)
    bad.write_bytes(bad.read_bytes()[:100])
    digests = tmp_path / "table_digests.json"
    digests.write_bytes(content)
    assert list(corrupt_tables(tmp_path, digests)) == [bad]
    entries = json.loads(digests.read_text())["tables"]
    assert list(entries) == ["runs/t0.parquet"] and entries["runs/t0.parquet"][4] == verify.file_sha256(good)


def test_a_digests_file_that_cannot_be_written_is_skipped(tmp_path):
    good, bad = _settled_tables(tmp_path, 2)
    bad.write_bytes(bad.read_bytes()[:100])
    folder = tmp_path / "table_digests.json"
    folder.mkdir()  # a folder in its place
    assert list(corrupt_tables(tmp_path, folder)) == [bad] and folder.is_dir() and not any(folder.iterdir())
    assert not list(tmp_path.glob(".*.tmp"))  # its temporary file removed
    assert list(corrupt_tables(tmp_path, tmp_path / "runs" / "t0.parquet" / "x.json")) == [bad]  # under a file


def test_a_nearly_full_disk_is_named(tmp_path, monkeypatch):
    from collections import namedtuple

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(
        verify.shutil, "disk_usage", lambda path: usage(10 * 2**30, 10 * 2**30 - 50 * 2**20, 50 * 2**20)
    )
    message = verify.disk_space_problem(tmp_path)
    assert message.startswith("No space left on device?") and "50 MB free" in message and str(tmp_path) in message
    monkeypatch.setattr(verify.shutil, "disk_usage", lambda path: usage(10 * 2**30, 2**30, 9 * 2**30))
    assert verify.disk_space_problem(tmp_path) is None


def test_a_full_file_system_is_named_wherever_results_lives(tmp_path, monkeypatch):
    from collections import namedtuple

    usage = namedtuple("usage", "total used free")
    work, results = tmp_path / "work", tmp_path / "elsewhere" / "results"
    work.mkdir()
    results.mkdir(parents=True)
    (work / "results").symlink_to(results)
    full = {str(results.resolve())}  # only the file system behind the link is full
    monkeypatch.setattr(
        verify.shutil,
        "disk_usage",
        lambda p: usage(2**30, 2**30, 2**19) if str(Path(p).resolve()) in full else usage(2**30, 0, 2**30),
    )
    device = lambda p: {str(results.resolve()): -1}.get(str(Path(p).resolve()), os.stat(p).st_dev)  # a mount
    monkeypatch.chdir(work)
    (problem,) = verify.disk_space_problems((".", "results", ".snakemake"), device)  # each file system once
    assert str(results.resolve()) in problem and "0 MB free" in problem
    full.add(str(work.resolve()))
    assert len(verify.disk_space_problems((".", "results", "missing"), device)) == 2


@pytest.mark.parametrize("length", [200, 240, 248])
def test_a_long_table_name_is_written_with_temporaries_that_fit(tmp_path, length):
    path = tmp_path / ("x" * (length - len(".parquet")) + ".parquet")
    write_parquet(DF, path)  # its temporary and its checksum's must fit 255 bytes
    assert len(path.name) == length and pd.read_parquet(path).equals(DF)
    assert checksum_path(path).exists() and len(checksum_path(path).name) == length + 7
    assert not list(tmp_path.glob("*.tmp")) and not list(tmp_path.glob(".*.tmp"))


def test_a_name_or_path_past_the_file_systems_limits_is_refused_before_anything_is_written(tmp_path):
    too_long = tmp_path / ("x" * 241 + ".parquet")  # 249 bytes: its .sha256 would be 256
    with pytest.raises(OutputError, match=r"a name of 249 bytes; at most 248 here"):
        check_output_path(too_long)
    deep = tmp_path.joinpath(*["d" * 200] * 21, "t.parquet")  # past PATH_MAX (4096)
    with pytest.raises(OutputError, match=r"a path of \d+ bytes; at most 4088 here"):
        check_output_path(deep)
    assert not too_long.exists() and not (tmp_path / ("d" * 200)).exists()


def test_the_cli_refuses_a_too_long_output_name_before_it_runs(tmp_path, capsys):
    from particle_entropy.cli import main

    out = tmp_path / ("r" * 245 + ".parquet")
    with pytest.raises(SystemExit):
        main(["simulate", "--method", "fd", "--n", "100", "--t-final", "1", "--out", str(out)])
    assert "a name of 253 bytes" in capsys.readouterr().err and not out.exists()
