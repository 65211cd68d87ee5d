"""One run at a time in a results folder: a lock that the workflow's main process holds in
``results/`` for as long as it runs, whichever working directory it runs in.

Snakemake's own lock lives in ``.snakemake/locks`` of the working directory, so two clones whose
``results/`` link to one folder never see each other's lock: both would write, check and set
aside the same tables at once. The lock here is taken on ``results/.run.lock``, the link
followed, with ``flock`` (the kernel's, released when the process ends however it ends: no stale
lock after a kill -9); it holds the holder's process id, host, folder and start time so that a
refused run can name it. That record may be another run's (a results folder copied with its lock
file, a holder that has not written yet), so a refusal names the process the kernel says holds the
lock (``/proc/locks``), with its folder, and the record only when it is that process's. Where no
lock can be taken on the lock file (a folder, a link, a dangling link, a file this user cannot
open) the run is refused in one line, never run unlocked; only a file system that offers no locks
(some network mounts) is said in one line and the run goes on, as before.
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import stat
import time
from pathlib import Path
from typing import IO

LOCK_NAME = ".run.lock"
_HELD: dict[str, IO] = {}  # real path of a locked folder -> its open lock file, for this process's life


class LockRefused(Exception):
    """No run may start in the results folder: another holds its lock, or the lock file is no file
    this run can lock (a folder, a link); the message names which and what to do."""


class FolderBusy(LockRefused):
    """Another run holds the lock of the results folder; the message names it."""


NO_LOCKS = {errno.ENOLCK, errno.ENOSYS, errno.EOPNOTSUPP, errno.EINVAL}  # a file system without flock


def hold(folder: str | os.PathLike = "results") -> str | None:
    """Lock ``folder`` (made if missing) for this process until it ends: FolderBusy naming the run
    that holds it, LockRefused when the lock file cannot be locked (a folder, a link, dangling or
    not, or a file this user cannot open), else None, or a line saying why no lock could be taken
    on a file system without locks. Taking it again in the same process is a no-op."""
    folder = Path(folder)
    real = os.path.realpath(folder)
    if real in _HELD:
        return None
    Path(real).mkdir(parents=True, exist_ok=True)  # a link to a folder not made yet: made
    path = folder / LOCK_NAME
    try:  # never through a link: the lock is this folder's own file
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC | os.O_NOFOLLOW | os.O_NONBLOCK, 0o644)
        if not stat.S_ISREG(os.fstat(fd).st_mode):  # a pipe or a device: no lock of ours
            os.close(fd)
            raise OSError(errno.EINVAL, "not a regular file")
    except OSError as e:
        what = "a symbolic link" if os.path.islink(path) else "a folder" if path.is_dir() else None
        why = f"it is {what}" if what else e.strerror
        raise LockRefused(
            f"cannot lock {folder}/ ({real}): {path} is no lock file ({why}); no run may write there unlocked: "
            f"remove {path} (no run of this workflow makes it so) and rerun"
        ) from None
    os.set_blocking(fd, True)
    lock = os.fdopen(fd, "r+", encoding="utf-8", errors="replace")
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        recorded = lock.read(1000).strip()
        holders = lock_holders(os.fstat(fd))
        lock.close()
        if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            if e.errno in NO_LOCKS:
                return f"cannot lock {folder}/ ({real}): {e.strerror}; two runs sharing it are not kept apart"
            raise LockRefused(f"cannot lock {folder}/ ({real}) at {path}: {e.strerror}; rerun when it can be") from None
        raise FolderBusy(
            f"{folder}/ ({real}) is in use by another run ({holder_named(recorded, holders)}): wait for it to "
            f"end, or give this working directory a results folder of its own"
        ) from None
    lock.seek(0)
    lock.truncate()
    since = time.strftime("%Y-%m-%d %H:%M:%S %Z", time.localtime())
    lock.write(f"pid {os.getpid()} on {socket.gethostname()} in {os.getcwd()}, since {since}\n")
    lock.flush()
    _HELD[real] = lock
    return None


def lock_holders(st: os.stat_result, locks: str | os.PathLike = "/proc/locks") -> list[int]:
    """The processes on this machine that the kernel says hold a flock on the file of ``st`` (from
    ``locks``; none where it is missing or names none: another host, another kernel)."""
    dev = f"{os.major(st.st_dev):02x}:{os.minor(st.st_dev):02x}:{st.st_ino}"
    try:
        lines = Path(locks).read_text().splitlines()
    except OSError:
        return []
    exact, by_inode = set(), set()  # an overlay or FUSE mount may show another device than stat
    for line in lines:
        words = line.split()
        if "->" in words or len(words) < 6 or words[1] != "FLOCK" or not words[4].isdigit():  # "->": a waiter
            continue
        if int(words[4]) == 0:  # a holder outside this pid namespace, or whose pid is freed: unnamed
            continue
        if words[5] == dev:
            exact.add(int(words[4]))
        elif words[5].rsplit(":", 1)[-1] == str(st.st_ino):
            by_inode.add(int(words[4]))
    # an inode number alone may be another file's, on another device: only a process that has ours open
    return sorted(exact or {pid for pid in by_inode if has_open(pid, st)})


def has_open(pid: int, st: os.stat_result) -> bool:
    """Whether process ``pid`` has the file of ``st`` open (its /proc fd links; False where they
    cannot be read)."""
    try:
        fds = os.listdir(f"/proc/{pid}/fd")
    except OSError:
        return False
    for fd in fds:
        try:
            other = os.stat(f"/proc/{pid}/fd/{fd}")
        except OSError:  # closed since it was listed
            continue
        if (other.st_dev, other.st_ino) == (st.st_dev, st.st_ino):
            return True
    return False


def holder_named(recorded: str, holders: list[int]) -> str:
    """The holder of a lock as a refusal names it: the lock file's record when it is that of the
    process the kernel names (``holders``, lock_holders), else that process, its folder and the
    record as stale; the record alone where the kernel names none (another host)."""
    if not holders:
        return recorded or "its holder is not named"
    host = socket.gethostname()
    for pid in holders:
        if recorded.startswith(f"pid {pid} on {host} "):
            return recorded
    named = []
    for pid in holders:
        try:
            folder = os.readlink(f"/proc/{pid}/cwd")
        except OSError:
            folder = "a folder not shown"
        named.append(f"pid {pid} on {host} in {folder}")
    stale = f"; the lock file's record, {recorded!r}, is not its holder's" if recorded else ""
    return ", ".join(named) + stale
