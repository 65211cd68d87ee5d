"""Table output: atomic, flushed, checksummed, never over a non-regular file; corrupt tables found."""

from __future__ import annotations

import hashlib
import os
import random
import stat

import pandas as pd
import pytest

from particle_entropy.core.io import (
    OutputError,
    check_output_path,
    checksum_path,
    corrupt_tables,
    set_aside,
    table_problem,
    write_parquet,
)

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


def test_a_nearly_full_disk_is_named(tmp_path, monkeypatch):
    from collections import namedtuple

    import particle_entropy.core.io as io

    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr(io.shutil, "disk_usage", lambda path: usage(10 * 2**30, 10 * 2**30 - 50 * 2**20, 50 * 2**20))
    message = io.disk_space_problem(tmp_path)
    assert message.startswith("No space left on device?") and "50 MB free" in message and str(tmp_path) in message
    monkeypatch.setattr(io.shutil, "disk_usage", lambda path: usage(10 * 2**30, 2**30, 9 * 2**30))
    assert io.disk_space_problem(tmp_path) is None
