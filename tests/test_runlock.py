"""One run at a time in a results folder (pipeline/runlock.py), whichever clone it runs from."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from particle_entropy.pipeline import runlock
from particle_entropy.pipeline.runlock import LOCK_NAME, FolderBusy, LockRefused, hold

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


@pytest.mark.parametrize("kind", ["link", "dangling link", "folder"])
def test_a_lock_path_that_is_no_file_refuses_the_run_in_one_line(tmp_path, kind):
    """Issue 50 (10): a folder or a dangling link at results/.run.lock let a run go on unlocked,
    with one warning. Now it is refused, naming the path; a link is never followed."""
    (tmp_path / "results").mkdir()
    outside = tmp_path / "outside.txt"
    outside.write_text("kept")
    path = tmp_path / "results" / LOCK_NAME
    if kind == "folder":
        path.mkdir()
    else:
        path.symlink_to(outside if kind == "link" else tmp_path / "nowhere")
    with pytest.raises(LockRefused) as refused:
        hold(tmp_path / "results")
    message = str(refused.value)
    assert "\n" not in message and f"{path} is no lock file" in message and kind.split()[-1] in message
    assert outside.read_text() == "kept" and not (tmp_path / "nowhere").exists()


LOCKER = textwrap.dedent(
    """
    import fcntl, sys
    f = open(sys.argv[1], "a")
    fcntl.flock(f, fcntl.LOCK_EX)
    print("held", flush=True)
    sys.stdin.read()
    """
)


def test_a_refusal_names_the_process_that_holds_the_lock_not_a_copied_record(tmp_path):
    """Issue 50 (10): in a copied run folder the refusal named the pid and folder that the copied
    lock file records, not the holder. It now names the process the kernel says holds the lock."""
    copy = tmp_path / "copy"
    (copy / "results").mkdir(parents=True)
    record = "pid 1 on elsewhere in /the/original, since 2020-01-01 00:00:00 UTC"
    (copy / "results" / LOCK_NAME).write_text(record + "\n")  # copied with the folder
    proc = subprocess.Popen(
        [sys.executable, "-c", LOCKER, str(copy / "results" / LOCK_NAME)],
        cwd=tmp_path,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert proc.stdout.readline().strip() == "held"
        if not runlock.lock_holders(os.stat(copy / "results" / LOCK_NAME)):
            pytest.skip("this kernel shows no flock holders in /proc/locks")
        with pytest.raises(FolderBusy) as busy:
            hold(copy / "results")
        message = str(busy.value)
        assert f"(pid {proc.pid} on " in message and f" in {tmp_path}" in message
        assert "is not its holder's" in message and "\n" not in message
    finally:
        proc.stdin.close()
        proc.wait(timeout=30)


def test_holders_come_from_the_kernel_s_list_of_locks(tmp_path):
    st = os.stat(tmp_path)
    dev = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}"
    locks = tmp_path / "locks"
    locks.write_text(
        f"1: FLOCK  ADVISORY  WRITE 42 {dev}:{st.st_ino} 0 EOF\n"
        f"1: -> FLOCK  ADVISORY  WRITE 43 {dev}:{st.st_ino} 0 EOF\n"  # a waiter, not a holder
        f"2: POSIX  ADVISORY  WRITE 44 {dev}:{st.st_ino} 0 EOF\n"
        f"3: FLOCK  ADVISORY  WRITE 45 {dev}:{st.st_ino + 1} 0 EOF\n"
    )
    assert runlock.lock_holders(st, locks) == [42]
    # a lock listed under another device by the same inode number: named only when the process has
    # this very file open (an overlay's device differs; an unrelated file may share the number)
    held = os.open(tmp_path, os.O_RDONLY)
    try:
        locks.write_text(
            f"1: FLOCK  ADVISORY  WRITE 0 {dev}:{st.st_ino} 0 EOF\n"  # pid 0: outside this pid namespace
            f"2: FLOCK  ADVISORY  WRITE {os.getppid()} 00:99:{st.st_ino} 0 EOF\n"
            f"3: FLOCK  ADVISORY  WRITE {os.getpid()} 00:99:{st.st_ino} 0 EOF\n"
        )
        assert runlock.lock_holders(st, locks) == [os.getpid()]
    finally:
        os.close(held)
    assert runlock.lock_holders(st, tmp_path / "missing") == []
    assert runlock.holder_named("pid 42 on x in /y", []) == "pid 42 on x in /y"  # none named: the record
