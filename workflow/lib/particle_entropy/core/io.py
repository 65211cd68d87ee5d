"""Parquet output: byte-stable for identical tables, written whole or not at all, and checked.

Every table goes to a temporary file beside its target, is flushed to disk (fsync), then
renamed over the target, and the folder is flushed too, so a crash or power cut leaves the old
file or the new one, never part of one. Beside each table a ``<name>.sha256`` file records the
SHA-256 of its bytes (verify.py checks them before a run); the old record is removed before the
table is replaced (``_commit``), so a stopped write never leaves a table under another table's
digest. The tables of one run (``write_run``) name the run in their metadata, so that tables of
two runs are never taken for one. Only regular files are ever replaced: an existing directory,
device or pipe at the target (or at its checksum's path) is refused, before any work.

Tables are read back with ``read_parquet``, which checks every page it reads against its CRC.
"""

from __future__ import annotations

import errno
import glob
import hashlib
import json
import os
import re
import signal
import stat
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING

import pyarrow as pa
import pyarrow.parquet as pq

if TYPE_CHECKING:
    import pandas as pd

CHECKSUM_SUFFIX = ".sha256"


class OutputError(ValueError):
    """An output path that must not be written; the message names the path and the reason."""


def digest(settings) -> str:
    """What a file is keyed by: 12 hex digits of the SHA-256 of ``settings`` as canonical JSON (sorted keys,
    no spaces): a scene run's settings (Scene.identity), a reference's physics (reference_file.key)."""
    text = json.dumps(settings, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()[:12]


def check_output_path(path: str | os.PathLike) -> Path:
    """``path`` as a Path if a table may be written there: a new path or an existing regular
    file, whose ``.sha256`` beside it is new or a regular file too, in a folder that exists or can
    be made and is writable, every name within the file system's limit. Else OutputError, before
    any work: nothing here is left to fail after a run (a name too long, a loop of links, a folder
    where the checksum goes). A path that names a folder (``out/``, ``out/.``, ``..``) is refused
    whether or not that folder exists: pathlib drops the separator, so ``out/`` would be written as
    a file named ``out``."""
    text = os.fsdecode(path)
    if os.path.basename(text) in ("", ".", ".."):
        example = os.path.join(text, "run.parquet")
        raise OutputError(f"{text}: names a folder, not a file; give the table's file name (e.g. {example})")
    p = Path(path)
    full = len(os.fsencode(os.path.abspath(p))) + len(CHECKSUM_SUFFIX)  # first: a stat of it would fail
    path_max = _limits(Path("/"))[1]
    if full >= path_max:
        most = path_max - 1 - len(CHECKSUM_SUFFIX)
        raise OutputError(f"{p}: a path of {full - len(CHECKSUM_SUFFIX)} bytes; at most {most} here")
    folder = p.parent  # the nearest folder that exists (a name too long for any cannot exist)
    while _stat(folder, p, missing=(errno.ENOENT, errno.ENOTDIR, errno.ENAMETOOLONG)) is None:
        if folder == folder.parent:  # no folder of it exists (the working folder was deleted)
            raise OutputError(f"{p}: no folder of it exists")
        folder = folder.parent
    name_max = _limits(folder)[0]
    for part in p.relative_to(folder).parts[:-1]:  # folders still to be made
        if len(os.fsencode(part)) > name_max:
            raise OutputError(f"{p}: a folder name of {len(os.fsencode(part))} bytes; at most {name_max} here")
    longest = len(os.fsencode(p.name)) + len(CHECKSUM_SUFFIX)  # the checksum beside it; temporaries fit (_temp_prefix)
    if longest > name_max:
        raise OutputError(
            f"{p}: a name of {len(os.fsencode(p.name))} bytes; at most {name_max - len(CHECKSUM_SUFFIX)} here, so "
            f"that its {CHECKSUM_SUFFIX} file fits the file system's {name_max}-byte names"
        )
    for target in (p, checksum_path(p)):
        st = _stat(target, p)  # follows links: a link to /dev/null is a device
        if st is not None and not stat.S_ISREG(st.st_mode):
            kind = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file (a device, pipe or socket)"
            raise OutputError(f"{p}: {target} is {kind}; a table and its checksum replace only regular files")
    if not folder.is_dir() or not os.access(folder, os.W_OK | os.X_OK):
        raise OutputError(f"{p}: cannot write in {folder} (not a writable folder)")
    return p


def _stat(path: Path, shown: Path, missing=(errno.ENOENT, errno.ENOTDIR)) -> os.stat_result | None:
    """os.stat of ``path`` (links followed), or None when nothing is there (``missing``: the errors
    that mean so); any other error (a loop of symbolic links, a folder that may not be searched)
    is an OutputError naming ``shown``, the output path asked for."""
    try:
        return os.stat(path)
    except OSError as e:
        if e.errno in missing:
            return None
        why = f"cannot be reached ({e.strerror})"
        if e.errno == errno.ELOOP:
            why = "is a loop of symbolic links; a table needs a path that resolves"
        raise OutputError(f"{shown}: {path} {why}") from None


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


def _write_temporary(data: bytes, path: Path, sync: bool = True) -> Path:
    """``data`` in a new temporary file beside ``path`` (flushed to disk unless ``sync`` is False)."""
    fd, tmp = tempfile.mkstemp(prefix=_temp_prefix(path), suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            if sync:
                f.flush()
                os.fsync(f.fileno())
        os.chmod(tmp, 0o644)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return Path(tmp)


def write_bytes_atomically(data: bytes, path: Path, sync: bool = True) -> None:
    tmp = _write_temporary(data, path, sync)
    try:
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _remove_stale_temporaries(path: Path) -> None:
    """Temporaries left by an interrupted write of this table or its checksum (one writer per
    table): ``.<name>.`` then mkstemp's random letters, digits and underscores, then ``.tmp``. A
    longer name's temporaries (``.<name>.x.<random>.tmp``, a dot among them) are not this table's."""
    for name in (path.name, path.name + CHECKSUM_SUFFIX):
        prefix = _temp_prefix(path.with_name(name))
        own = re.compile(re.escape(prefix) + r"[a-z0-9_]+\.tmp")
        for tmp in path.parent.glob(f"{glob.escape(prefix)}*.tmp"):
            if own.fullmatch(tmp.name):
                tmp.unlink(missing_ok=True)


@contextmanager
def _signals_deferred():
    """SIGINT and SIGTERM received inside are acted on only on leaving (in the main thread; a
    handler can be set nowhere else): a Ctrl-C or a scheduler's SIGTERM never splits a commit."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, lambda signum, frame: caught.append(signum)) for s in held}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, signal.SIG_DFL if handler is None else handler)
        if caught:
            signal.raise_signal(caught[0])


def _table_bytes(table: pa.Table, extra: dict[bytes, bytes] | None = None) -> bytes:
    if extra:
        table = table.replace_schema_metadata({**(table.schema.metadata or {}), **extra})
    sink = pa.BufferOutputStream()
    # page checksums (CRC32 in each page header): a table whose .sha256 is lost is still checked
    # page by page (verify.table_problem; 297 of 300 random bit flips found, 9 without them)
    pq.write_table(table, sink, compression="zstd", write_page_checksum=True)
    return sink.getvalue().to_pybytes()


def _commit(staged: dict[Path, tuple[Path, Path]]) -> None:
    """Put staged tables in place: {target: (its temporary, its checksum's temporary)}.

    A table and its checksum are never replaced as one by a single rename, so the old checksum is
    removed first (and that made durable), then every table renamed into place, then every new
    checksum. Stopped anywhere (SIGKILL, a power cut) this leaves each table either with its old
    checksum and old bytes, or without a checksum (old or new bytes, judged whole by their page
    checksums, verify.table_problem), or with its own new checksum: never a table under another
    table's digest. SIGINT and SIGTERM wait until the end (``_signals_deferred``)."""
    folders = sorted({path.parent for path in staged})
    try:
        with _signals_deferred():
            for path in staged:
                checksum_path(path).unlink(missing_ok=True)
            for folder in folders:
                _fsync_dir(folder)
            for path, (tmp, _) in staged.items():
                os.replace(tmp, path)
            for path, (_, checksum_tmp) in staged.items():
                os.replace(checksum_tmp, checksum_path(path))
            for folder in folders:
                _fsync_dir(folder)
    finally:
        _discard(staged)


def _discard(staged: dict[Path, tuple[Path, Path]]) -> None:
    for tmp, checksum_tmp in staged.values():
        tmp.unlink(missing_ok=True)
        checksum_tmp.unlink(missing_ok=True)


def _write_all(tables: dict[Path, bytes]) -> None:
    """Each table's bytes and checksum to temporaries beside it, then ``_commit``; no temporary
    is left when anything (an error, SIGINT, SIGTERM) stops it."""
    staged: dict[Path, tuple[Path, Path]] = {}
    try:
        for path, data in tables.items():
            tmp = _write_temporary(data, path)
            try:
                record = f"{hashlib.sha256(data).hexdigest()}  {path.name}\n".encode()
                staged[path] = (tmp, _write_temporary(record, checksum_path(path)))
            except BaseException:
                tmp.unlink(missing_ok=True)
                raise
    except BaseException:
        _discard(staged)
        raise
    _commit(staged)


def _arrow(df: pd.DataFrame | pa.Table) -> pa.Table:
    return df if isinstance(df, pa.Table) else pa.Table.from_pandas(df, preserve_index=False)


def _prepare(path: str | os.PathLike) -> Path:
    path = check_output_path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    _remove_stale_temporaries(path)
    return path


def write_parquet(df: pd.DataFrame | pa.Table, path: str | os.PathLike) -> None:
    """Write ``df`` (a pandas or an Arrow table) to ``path`` (flushed, atomic) with its checksum
    beside it (``_commit``: a killed write never leaves the table under another one's digest)."""
    path = _prepare(path)
    _write_all({path: _table_bytes(_arrow(df))})


RUN_KEY = b"particle_entropy.run"


def write_run(tables: dict[str | os.PathLike, pd.DataFrame | pa.Table]) -> str:
    """Write the tables of one run (a per-step table and its final state), each as write_parquet
    does and each naming the run in its Parquet key-value metadata: RUN_KEY holds JSON
    ``{"id": <run id>, "tables": [the others' paths, relative to this table's folder]}``. Returns
    the run id. A run stopped between two renames (SIGKILL, a power cut) leaves tables of two
    runs side by side; their ids differ (``run_problem``, verify.mixed_runs), so the pair is
    refused, never read as one run. The id is a digest of the tables' contents, so that equal
    tables are written as equal bytes; two runs with equal ids wrote equal tables. Every path is
    checked (check_output_path) before anything is written."""
    paths = [check_output_path(p) for p in tables]
    if len({os.path.realpath(p) for p in paths}) < len(paths):
        raise OutputError(f"{paths[0]}: a run's tables need one path each")
    arrow = [_arrow(t) for t in tables.values()]
    run = hashlib.sha256(b"".join(hashlib.sha256(_table_bytes(t)).digest() for t in arrow)).hexdigest()[:32]
    data = {}
    for path, table in zip(paths, arrow, strict=True):
        others = [os.path.relpath(os.path.abspath(q), os.path.abspath(path.parent)) for q in paths if q is not path]
        data[_prepare(path)] = _table_bytes(table, {RUN_KEY: json.dumps({"id": run, "tables": others}).encode()})
    _write_all(data)
    return run


def run_of(path: str | os.PathLike) -> dict | None:
    """The run a table names (``write_run``): {"id", "tables"}, or None for a table that names
    none (written alone, or by an older version) or whose record is not one."""
    try:
        raw = (pq.read_schema(path).metadata or {}).get(RUN_KEY)
        run = json.loads(raw) if raw is not None else None
    except (OSError, ValueError, pa.ArrowException):
        return None
    if not isinstance(run, dict) or not isinstance(run.get("id"), str) or not isinstance(run.get("tables"), list):
        return None
    return run


def run_problem(paths: dict[str, str | os.PathLike]) -> str | None:
    """Why the tables at ``paths`` ({what each is, e.g. an option: its path}) are not one run's,
    or None: their run ids (``write_run``) differ, or one names no run."""
    ids = {what: (run_of(p) or {}).get("id") for what, p in paths.items()}
    if len(set(ids.values())) <= 1 and None not in ids.values():
        return None
    named = ", ".join(f"{what} {paths[what]} ({'run ' + i[:12] if i else 'no run id'})" for what, i in ids.items())
    return f"{named}: tables of different runs (a run stopped between its writes?); write them again in one run"


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
