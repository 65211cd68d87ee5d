"""Parquet output: byte-stable for identical tables, written whole or not at all, and checked.

Every table goes to a temporary file beside its target, is flushed to disk (fsync), then
renamed over the target, and the folder is flushed too, so a crash or power cut leaves the old
file or the new one, never part of one. Beside each table a ``<name>.sha256`` file records the
SHA-256 of its bytes (verify.py checks them before a run). Only regular files are ever replaced:
an existing directory, device or pipe at the target is refused.

Tables are read back with ``read_parquet``, which checks every page it reads against its CRC.
"""

from __future__ import annotations

import glob
import hashlib
import os
import stat
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import pyarrow as pa
import pyarrow.parquet as pq

if TYPE_CHECKING:
    import pandas as pd

CHECKSUM_SUFFIX = ".sha256"


class OutputError(ValueError):
    """An output path that must not be written; the message names the path and the reason."""


def check_output_path(path: str | os.PathLike) -> Path:
    """``path`` as a Path if a table may be written there: a new path or an existing regular
    file, in a folder that exists or can be made and is writable. Else OutputError."""
    p = Path(path)
    full = len(os.fsencode(os.path.abspath(p))) + len(CHECKSUM_SUFFIX)  # first: a stat of it would fail
    path_max = _limits(Path("/"))[1]
    if full >= path_max:
        most = path_max - 1 - len(CHECKSUM_SUFFIX)
        raise OutputError(f"{p}: a path of {full - len(CHECKSUM_SUFFIX)} bytes; at most {most} here")
    if p.exists():
        mode = p.stat().st_mode  # follows links: a link to /dev/null is a device
        if not stat.S_ISREG(mode):
            kind = "a directory" if stat.S_ISDIR(mode) else "not a regular file (a device, pipe or socket)"
            raise OutputError(f"{p}: is {kind}; a table is written only to a regular file or a new path")
    folder = p.parent
    while not folder.exists():
        folder = folder.parent
    if not folder.is_dir() or not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{p}: cannot write in {folder} (not a writable folder)")
    name_max = _limits(folder)[0]
    longest = len(p.name.encode()) + len(CHECKSUM_SUFFIX)  # the checksum beside it; temporaries fit (_temp_prefix)
    if longest > name_max:
        raise OutputError(
            f"{p}: a name of {len(p.name.encode())} bytes; at most {name_max - len(CHECKSUM_SUFFIX)} here, so that "
            f"its {CHECKSUM_SUFFIX} file fits the file system's {name_max}-byte names"
        )
    return p


def _limits(folder: Path) -> tuple[int, int]:
    """The longest file name and path of the file system holding ``folder`` (255 and 4096 on Linux)."""
    try:
        return os.pathconf(folder, "PC_NAME_MAX"), os.pathconf(folder, "PC_PATH_MAX")
    except (OSError, ValueError):
        return 255, 4096


def _temp_prefix(path: Path) -> str:
    """The prefix of ``path``'s temporaries: ``.<name>.``, or a digest of the name where that and
    mkstemp's 8 random characters and ``.tmp`` would pass the file system's name limit."""
    prefix = f".{path.name}."
    if len(prefix.encode()) + 12 <= _limits(path.parent)[0]:
        return prefix
    return f".{hashlib.sha256(path.name.encode()).hexdigest()[:16]}."


def _fsync_dir(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def write_bytes_atomically(data: bytes, path: Path, sync: bool = True) -> None:
    fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path), suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            if sync:
                f.flush()
                os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _remove_stale_temporaries(path: Path) -> None:
    """Temporaries left by an interrupted write of this table (one writer per table)."""
    for name in (path.name, path.name + CHECKSUM_SUFFIX):
        prefix = _temp_prefix(path.with_name(name))
        for tmp in path.parent.glob(f"{glob.escape(prefix)}*.tmp"):
            tmp.unlink(missing_ok=True)


def write_parquet(df: pd.DataFrame | pa.Table, path: str | os.PathLike) -> None:
    """Write ``df`` (a pandas or an Arrow table) to ``path`` (flushed, atomic), then its checksum
    beside it."""
    path = check_output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_temporaries(path)
    sink = pa.BufferOutputStream()
    table = df if isinstance(df, pa.Table) else pa.Table.from_pandas(df, preserve_index=False)
    # page checksums (CRC32 in each page header): a table whose .sha256 is lost is still checked
    # page by page (verify.table_problem; 297 of 300 random bit flips found, 9 without them)
    pq.write_table(table, sink, compression="zstd", write_page_checksum=True)
    data = sink.getvalue().to_pybytes()
    write_bytes_atomically(data, path)
    write_bytes_atomically(f"{hashlib.sha256(data).hexdigest()}  {path.name}\n".encode(), checksum_path(path))
    _fsync_dir(path.parent)


def checksum_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    return path.with_name(path.name + CHECKSUM_SUFFIX)


# --------------------------------------------------------------------------- reading
class TableReadError(ValueError):
    """A table a job cannot use (a page that fails its checksum, a truncated file, an unreadable
    disk block); the one-line message names it and what happens next."""


def read_parquet(path: str | os.PathLike, columns: list[str] | None = None) -> pd.DataFrame:
    """The table at ``path`` as pd.read_parquet gives it, every page read checked against the CRC32
    in its header (write_parquet writes one per page): a table changed on the disk after it was
    written fails here instead of giving other numbers. A table that fails raises TableReadError
    naming it; its change time (ctime) is moved, its other times kept (``_mark_changed``), so that
    the workflow's digest cache (verify.corrupt_tables), which vouches for a table only while its
    ctime holds, hashes it again at the next run and sets it aside."""
    import pandas as pd

    try:
        return pd.read_parquet(path, columns=columns, page_checksum_verification=True)
    except (OSError, pa.ArrowException) as e:
        if isinstance(e, OSError) and (e.errno is not None or type(e) is not OSError):  # missing, no access, EIO
            why = e.strerror or {FileNotFoundError: "No such file", PermissionError: "Permission denied"}.get(type(e))
            raise TableReadError(f"cannot read table {path}: {why or type(e).__name__}") from None
        reason = " ".join(str(e).split())[:200]
        if not _mark_changed(path):
            raise TableReadError(f"corrupt table {path}: {reason}; delete it and rerun to rebuild it") from None
        raise TableReadError(f"corrupt table {path}: {reason}; the next run sets it aside and rebuilds it") from None


def _mark_changed(path: str | os.PathLike) -> bool:
    """Set the times of ``path`` to what they are: its content and mtime stay (Snakemake sees no
    change), its ctime moves to now. -> whether that could be done (the file's owner)."""
    try:
        st = os.stat(path)
        os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns))
    except OSError:
        return False
    return True


def exit_on_table_errors() -> None:
    """Make an uncaught TableReadError end this process (a Snakemake job's script) with its one-line
    message on stderr and exit status 1, not a traceback; every other error is shown as before."""
    import sys

    previous = sys.excepthook

    def hook(kind, value, tb):
        if issubclass(kind, TableReadError):
            print(value, file=sys.stderr)
        else:
            previous(kind, value, tb)

    sys.excepthook = hook
