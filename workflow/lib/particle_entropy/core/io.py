"""Parquet output: byte-stable for identical tables, written whole or not at all, and checked.

Every table goes to a temporary file beside its target, is flushed to disk (fsync), then
renamed over the target, and the folder is flushed too, so a crash or power cut leaves the old
file or the new one, never part of one. Beside each table a ``<name>.sha256`` file records the
SHA-256 of its bytes; ``corrupt_tables`` finds every table whose bytes no longer match (a
truncation, a flipped bit, an empty file) so that the workflow can set it aside and rebuild it.
Only regular files are ever replaced: an existing directory, device or pipe at the target is
refused.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import stat
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import pyarrow as pa
import pyarrow.parquet as pq

if TYPE_CHECKING:
    import pandas as pd

CHECKSUM_SUFFIX = ".sha256"
CORRUPT_SUFFIX = ".corrupt"
MAGIC = b"PAR1"


class OutputError(ValueError):
    """An output path that must not be written; the message names the path and the reason."""


def check_output_path(path: str | os.PathLike) -> Path:
    """``path`` as a Path if a table may be written there: a new path or an existing regular
    file, in a folder that exists or can be made and is writable. Else OutputError."""
    p = Path(path)
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
    return p


def _fsync_dir(folder: Path) -> None:
    fd = os.open(folder, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _write_bytes_atomically(data: bytes, path: Path) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
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
        for tmp in path.parent.glob(f".{name}.*.tmp"):
            tmp.unlink(missing_ok=True)


def write_parquet(df: pd.DataFrame | pa.Table, path: str | os.PathLike) -> None:
    """Write ``df`` (a pandas or an Arrow table) to ``path`` (flushed, atomic), then its checksum
    beside it."""
    path = check_output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_temporaries(path)
    sink = pa.BufferOutputStream()
    table = df if isinstance(df, pa.Table) else pa.Table.from_pandas(df, preserve_index=False)
    pq.write_table(table, sink, compression="zstd")
    data = sink.getvalue().to_pybytes()
    _write_bytes_atomically(data, path)
    _write_bytes_atomically(f"{hashlib.sha256(data).hexdigest()}  {path.name}\n".encode(), checksum_path(path))
    _fsync_dir(path.parent)


def checksum_path(path: str | os.PathLike) -> Path:
    path = Path(path)
    return path.with_name(path.name + CHECKSUM_SUFFIX)


def table_problem(path: str | os.PathLike) -> str | None:
    """Why the table at ``path`` cannot be trusted, or None: its bytes differ from its recorded
    checksum, or (without one) it lacks the Parquet magic bytes at either end."""
    path = Path(path)
    if not path.is_file():  # never read a pipe (it would block) or a folder
        return "it is a folder, not a table" if path.is_dir() else "it is not a regular file"
    data = path.read_bytes()
    recorded = checksum_path(path)
    if recorded.exists():
        want = recorded.read_text().split()[0] if recorded.read_text().strip() else ""
        got = hashlib.sha256(data).hexdigest()
        return None if got == want else f"its SHA-256 {got[:12]}... differs from the recorded {want[:12] or 'nothing'}"
    if len(data) < 12 or data[:4] != MAGIC or data[-4:] != MAGIC:
        return f"it is not a whole Parquet file ({len(data)} bytes, no PAR1 at both ends)"
    return None


def corrupt_tables(root: str | os.PathLike) -> dict[Path, str]:
    """Every table below ``root`` that cannot be trusted, with the reason (a folder, pipe or device
    with a table's name included)."""
    root = Path(root)
    if not root.exists():
        return {}
    out = {}
    for path in sorted(root.rglob("*.parquet")):
        problem = table_problem(path)
        if problem:
            out[path] = problem
    return out


def set_aside(path: str | os.PathLike) -> Path:
    """Move a corrupt table (and its checksum) to ``<name>.corrupt`` so that it is rebuilt."""
    path = Path(path)
    target = path.with_name(path.name + CORRUPT_SUFFIX)
    if target.is_dir() and not target.is_symlink():  # an older copy set aside
        shutil.rmtree(target)
    os.replace(path, target)
    checksum_path(path).unlink(missing_ok=True)
    return target


MIN_FREE_MB_ENV = "PARTICLE_ENTROPY_MIN_FREE_MB"  # a test sets it high to see the message
MIN_FREE_MB = 200.0


def disk_space_problem(path: str | os.PathLike = ".") -> str | None:
    """A message when the file system holding ``path`` has less than MIN_FREE_MB free (none
    otherwise): a job that fails on a full disk often cannot write its own log, so the
    workflow says so on the terminal (Snakefile `onerror`)."""
    limit = float(os.environ.get(MIN_FREE_MB_ENV, MIN_FREE_MB))
    free_mb = shutil.disk_usage(path).free / 2**20
    if free_mb >= limit:
        return None
    return (
        f"No space left on device? The file system holding {Path(path).resolve()} has {free_mb:.0f} MB free "
        f"(below {limit:.0f} MB); a job that fails on a full disk may leave an empty log. "
        "Free some space and rerun the same command: finished tables are kept."
    )
