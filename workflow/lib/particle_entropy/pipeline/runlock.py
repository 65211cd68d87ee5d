"""One run at a time in a results folder: a lock that the workflow's main process holds in
``results/`` for as long as it runs, whichever working directory it runs in.

Snakemake's own lock lives in ``.snakemake/locks`` of the working directory, so two clones whose
``results/`` link to one folder never see each other's lock: both would write, check and set
aside the same tables at once. The lock here is taken on ``results/.run.lock``, the link
followed, with ``flock`` (the kernel's, released when the process ends however it ends: no stale
lock after a kill -9); it holds the holder's process id, host, folder and start time so that a
refused run can name it. A file system that offers no locks (some network mounts) is said in one
line and the run goes on, as before.
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import time
from pathlib import Path
from typing import IO

LOCK_NAME = ".run.lock"
_HELD: dict[str, IO] = {}  # real path of a locked folder -> its open lock file, for this process's life


class FolderBusy(Exception):
    """Another run holds the lock of the results folder; the message names it."""


def hold(folder: str | os.PathLike = "results") -> str | None:
    """Lock ``folder`` (made if missing) for this process until it ends: FolderBusy naming the run
    that holds it, else None, or a line saying why no lock could be taken (a file system without
    locks). Taking it again in the same process is a no-op."""
    folder = Path(folder)
    real = os.path.realpath(folder)
    if real in _HELD:
        return None
    Path(real).mkdir(parents=True, exist_ok=True)  # a link to a folder not made yet: made
    path = folder / LOCK_NAME
    try:  # never through a link: the lock is this folder's own file
        fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC | os.O_NOFOLLOW, 0o644)
    except OSError as e:
        return f"cannot lock {folder}/ ({real}) at {path}: {e.strerror}; two runs sharing it are not kept apart"
    lock = os.fdopen(fd, "r+", encoding="utf-8", errors="replace")
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as e:
        holder = lock.read(1000).strip()
        lock.close()
        if e.errno not in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            return f"cannot lock {folder}/ ({real}): {e.strerror}; two runs sharing it are not kept apart"
        raise FolderBusy(
            f"{folder}/ ({real}) is in use by another run ({holder or 'its holder is not named'}): wait for it to "
            f"end, or give this working directory a results folder of its own"
        ) from None
    lock.seek(0)
    lock.truncate()
    since = time.strftime("%Y-%m-%d %H:%M:%S %Z", time.localtime())
    lock.write(f"pid {os.getpid()} on {socket.gethostname()} in {os.getcwd()}, since {since}\n")
    lock.flush()
    _HELD[real] = lock
    return None
