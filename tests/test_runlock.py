"""One run at a time in a results folder (pipeline/runlock.py), whichever clone it runs from."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from particle_entropy.pipeline import runlock
from particle_entropy.pipeline.runlock import LOCK_NAME, FolderBusy, hold

HOLDER = textwrap.dedent(
    """
    import sys, time
    from particle_entropy.pipeline.runlock import hold
    assert hold(sys.argv[1]) is None
    print("held", flush=True)
    sys.stdin.read()  # until the test closes the pipe
    """
)


def holding(folder, cwd):
    """A process in ``cwd`` that holds ``folder``'s lock until its stdin is closed."""
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLDER, str(folder)], cwd=cwd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout.readline().strip() == "held"
    return proc


@pytest.fixture(autouse=True)
def _forget_held(monkeypatch):
    monkeypatch.setattr(runlock, "_HELD", {})  # each test's folders, released with the test's files


def test_a_second_holder_through_another_clones_link_is_refused_naming_the_first(tmp_path):
    shared = tmp_path / "shared"
    for clone in ("a", "b"):
        (tmp_path / clone).mkdir()
        (tmp_path / clone / "results").symlink_to(shared, target_is_directory=True)
    first = holding("results", tmp_path / "a")
    try:
        with pytest.raises(FolderBusy) as busy:
            hold(tmp_path / "b" / "results")
        message = str(busy.value)
        assert "\n" not in message and f"({shared}) is in use by another run" in message
        assert f"pid {first.pid} on " in message and f"in {tmp_path / 'a'}" in message
    finally:
        first.stdin.close()
        first.wait(timeout=30)
    assert hold(tmp_path / "b" / "results") is None  # released when its holder ended
    assert (shared / LOCK_NAME).read_text().startswith(f"pid {os.getpid()} on ")
    assert hold(tmp_path / "a" / "results") is None  # this process holds it already: a no-op


def test_a_killed_holder_leaves_no_stale_lock(tmp_path):
    first = holding(tmp_path / "results", tmp_path)
    first.kill()
    first.wait(timeout=30)
    assert hold(tmp_path / "results") is None


def test_a_lock_file_that_is_a_link_is_not_followed(tmp_path):
    (tmp_path / "results").mkdir()
    outside = tmp_path / "outside.txt"
    outside.write_text("kept")
    (tmp_path / "results" / LOCK_NAME).symlink_to(outside)
    note = hold(tmp_path / "results")
    assert note.startswith("cannot lock ") and "not kept apart" in note
    assert outside.read_text() == "kept"
