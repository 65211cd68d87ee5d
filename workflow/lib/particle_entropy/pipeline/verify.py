"""Tables that can no longer be trusted, found before a run; and the full-disk message.

Beside each table a ``<name>.sha256`` file records the SHA-256 of its bytes (io.write_parquet);
``corrupt_tables`` finds every table whose bytes no longer match (a truncation, a flipped bit,
an empty file) so that the workflow can set it aside and rebuild it. Given a digests file, it
remembers each table's SHA-256 against the table's size, mtime, inode and ctime (DVC keeps the
first three; the ctime, which no user can set back, also sees an edit in place with the mtime
put back) and reads a table again only when one of them changed. Folders linked under the root
are followed (``tables_below``). It also says, before any job, which folder a run cannot write
(``write_problems``). Only the workflow's main process and the crate job (pipeline/crate.py)
import this module, so editing it reruns no rule but `crate`.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from ..core.io import checksum_path, write_bytes_atomically

CORRUPT_SUFFIX = ".corrupt"
CRATE_DIR = "results/ro-crate"  # a run's RO-Crate (pipeline/crate.py): links to tables checked where they were made
DIGESTS = ".snakemake/particle_entropy/table_digests.json"  # the table check's digest cache, below a run folder
MAGIC = b"PAR1"


def file_sha256(path: str | os.PathLike) -> str:
    """SHA-256 of the bytes of the file at ``path`` (hex), read in blocks."""
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def recorded_digest(path: str | os.PathLike) -> str | None:
    """The SHA-256 recorded beside the table at ``path``, or None when there is no usable record:
    none, a folder or pipe in its place, unreadable, not ASCII, or not a 64-digit hex digest.
    A record that is not one is treated as missing, never as a crash."""
    recorded = checksum_path(path)
    try:
        if not recorded.is_file():
            return None
        words = recorded.read_bytes()[:4096].decode("ascii").split()
    except (OSError, UnicodeDecodeError):
        return None
    return words[0] if words and re.fullmatch(r"[0-9a-f]{64}", words[0]) else None


def table_problem(path: str | os.PathLike, digest: str | None = None) -> str | None:
    """Why the table at ``path`` cannot be trusted, or None: its bytes differ from its recorded
    checksum, or (without a usable one, ``recorded_digest``) it cannot be read whole as Parquet:
    footer, schema and every page, with page checksums where they were written. ``digest``: the
    SHA-256 of its bytes when already known (corrupt_tables' cache); else they are read."""
    path = Path(path)
    if not path.is_file():  # never read a pipe (it would block) or a folder
        return "it is a folder, not a table" if path.is_dir() else "it is not a regular file"
    want = recorded_digest(path)
    if want is not None:
        got = digest or file_sha256(path)
        return None if got == want else f"its SHA-256 {got[:12]}... differs from the recorded {want[:12]}"
    with path.open("rb") as f:
        size = os.fstat(f.fileno()).st_size
        head = f.read(4)
        f.seek(max(size - 4, 0))
        tail = f.read(4)
    if size < 12 or head != MAGIC or tail != MAGIC:
        return f"it is not a whole Parquet file ({size} bytes, no PAR1 at both ends)"
    import pyarrow.parquet as pq  # only for a table without a usable checksum: rare

    try:
        pq.read_table(path, page_checksum_verification=True)
    except Exception as e:  # noqa: BLE001 - any reader error means the table cannot be used
        return f"it has no checksum and cannot be read whole as Parquet ({type(e).__name__}: {str(e)[:120]})"
    return None


def content_problem(path: str | os.PathLike, expected: dict) -> str | None:
    """Why the rows of the table at ``path`` are not those its path names, or None. ``expected``:
    column -> the one value every row holds (None: a missing value), or a (low, high) pair
    bounding an integer column (a block of seeds); columns the table lacks are not judged."""
    import pyarrow.parquet as pq

    try:
        names = set(pq.read_schema(path).names)
        columns = [c for c in expected if c in names]
        table = pq.read_table(path, columns=columns)
    except Exception as e:  # noqa: BLE001
        return f"it cannot be read as Parquet ({type(e).__name__})"
    for column in columns:
        values = table.column(column).unique().to_pylist()
        want = expected[column]
        if isinstance(want, tuple):
            bad = [v for v in values if v is None or not want[0] <= v <= want[1]]
            if bad:
                return f"its column {column} holds {bad[0]!r}, outside the {want[0]}-{want[1]} its path names"
            continue
        missing = [v is None or v != v for v in values]  # None or NaN: a missing value
        same = all(missing) if want is None else all(v == want for v in values)
        if not values or not same:
            return f"its column {column} holds {values[:3]!r}, its path names {want!r}: another case's table"
    return None


DIGESTS_VERSION = 2  # 2: the ctime joined the stamp
# A table changed less than this before it was hashed is hashed again next time: a write in the
# same tick of the file system's clock (or within its 1-2 s granularity) would keep the mtime.
SETTLED_NS = 2 * 10**9


def tables_below(root: str | os.PathLike, suffix: str = ".parquet") -> list[Path]:
    """Everything below ``root`` whose name ends in ``suffix`` (files, and folders, pipes and devices
    in a table's place), sorted, as paths through ``root``.
    Folders that are symbolic links are followed (results/runs may be a link to another disk), each
    real folder once: a link to a folder seen already, such as a loop back to an ancestor, is
    skipped."""
    seen, out = set(), []
    for folder, dirs, files in os.walk(root, followlinks=True):
        try:
            st = os.stat(folder)
        except OSError:  # gone since it was listed
            dirs[:] = []
            continue
        if (st.st_dev, st.st_ino) in seen:
            dirs[:] = []
            continue
        seen.add((st.st_dev, st.st_ino))
        dirs.sort()
        out += [Path(folder, name) for name in dirs + files if name.endswith(suffix)]  # a folder by a table's name too
    return sorted(out)


def corrupt_tables(root: str | os.PathLike, digests: str | os.PathLike | None = None, expected=None) -> dict[Path, str]:
    """Every table below ``root`` that cannot be trusted, with the reason (a folder, pipe or device
    with a table's name included).

    With ``digests`` (a JSON file) each table's SHA-256 is kept against its size, mtime, inode and
    ctime, and a table is read again only when one of them changed, as a new write (a new file
    renamed into place) and an edit in place (the mtime set back or not) always do; the checksum
    beside it is read every time, and a table that seems not to match is read before it is
    condemned. Bytes that decay on the disk change none of the four: a job reading such a table
    fails on its page checksums (core.io.read_parquet), which moves its ctime, so the next check
    hashes it again. A missing or unreadable digests file is rebuilt.

    ``expected``: a function of a table's path (as found below ``root``) giving the column values
    its path names (``content_problem``), or None for a path that names none; every table read
    again is also checked against it, so another case's valid table put in its place is found."""
    root = Path(root)
    if not root.exists():
        return {}
    known = _read_digests(digests) if digests is not None else {}
    kept, out = {}, {}
    crate = Path(CRATE_DIR).relative_to("results").as_posix() + "/"
    for path in tables_below(root):
        key = path.relative_to(root).as_posix()
        if key.startswith(crate):  # hard links of tables checked at their own paths
            continue
        now = digest = None  # the table's stamp, while it may be vouched for
        remembered = False
        if path.is_file() and recorded_digest(path) is not None:
            st = path.stat()
            now = stamp(st)
            remembered = known.get(key, [])[:4] == now
            if remembered:
                digest = known[key][4]
            else:
                hashed_at = time.time_ns()
                digest = file_sha256(path)
                if st.st_mtime_ns > hashed_at - SETTLED_NS:
                    now = None  # too fresh to vouch for: hashed again next time
        problem = table_problem(path, digest)
        if problem and remembered:  # a remembered digest may spare a read, never condemn
            digest = file_sha256(path)
            problem = table_problem(path, digest)
        if not problem and not remembered and expected is not None:
            names = expected(path)
            problem = content_problem(path, names) if names else None
        if problem:
            out[path] = problem
        elif now:
            kept[key] = [*now, digest]
    if digests is not None and kept != known:
        _write_digests(Path(digests), kept)
    return out


def _read_digests(path: str | os.PathLike) -> dict[str, list]:
    """The entries of a digests file, {table: [size, mtime_ns, inode, ctime_ns, sha256]}; none when
    it is missing, not a regular file, unreadable or not in this format."""
    path = Path(path)
    try:
        if not path.is_file():
            return {}
        data = json.loads(path.read_bytes())
        tables = data["tables"] if data["version"] == DIGESTS_VERSION else {}
        return {
            key: entry
            for key, entry in tables.items()
            if isinstance(key, str)
            and isinstance(entry, list)
            and len(entry) == 5
            and all(type(x) is int for x in entry[:4])
            and isinstance(entry[4], str)
        }
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RecursionError):
        return {}


def stamp(st: os.stat_result) -> list[int]:
    """What a digest cache entry holds a table's SHA-256 against: size, mtime, inode and ctime."""
    return [st.st_size, st.st_mtime_ns, st.st_ino, st.st_ctime_ns]


def cached_digests(path: str | os.PathLike) -> dict[str, list]:
    """The digest cache at ``path`` as the table check left it: {table below results/: [*stamp,
    sha256]} (empty when missing or unreadable); an entry vouches for a table only while its stamp
    matches the table's."""
    return _read_digests(path)


def restamp_digests(path: str | os.PathLike, tables: dict[str, list]) -> None:
    """Give the cache entries of ``tables`` ({table below results/: [*stamp, sha256]}) their new
    stamps: for tables whose entry vouched for them just before a change that leaves their bytes
    alone (a hard link moves the ctime), so that the next check does not read them again."""
    known = _read_digests(path)
    known.update(tables)
    _write_digests(Path(path), known)


def _write_digests(path: Path, tables: dict[str, list]) -> None:
    """Replace the digests file whole (a temporary file renamed over it; not flushed: a cache lost
    in a crash costs one reread)."""
    data = json.dumps({"version": DIGESTS_VERSION, "tables": tables}, sort_keys=True, separators=(",", ":"))
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        write_bytes_atomically(data.encode(), path, sync=False)
    except OSError:
        pass  # a read-only folder, or a folder in its place: the next check reads every table


def set_aside(path: str | os.PathLike) -> Path:
    """Move a corrupt table (and its checksum) to ``<name>.corrupt`` so that it is rebuilt."""
    path = Path(path)
    target = path.with_name(path.name + CORRUPT_SUFFIX)
    if target.is_dir() and not target.is_symlink():  # an older copy set aside
        shutil.rmtree(target)
    os.replace(path, target)
    checksum_path(path).unlink(missing_ok=True)
    return target


class TableError(RuntimeError):
    """A corrupt table that cannot be set aside; the message says which and what to do."""


def set_aside_corrupt(root, digests=None, expected=None, report=print) -> list[Path]:
    """Set aside every table ``corrupt_tables`` finds, reporting each on one line; returns the
    tables moved. A table that cannot be moved (a read-only folder) raises TableError before any
    further change."""
    moved = []
    for path, problem in corrupt_tables(root, digests, expected).items():
        if not os.path.lexists(path):  # inside a folder in a table's place, set aside before it
            continue
        try:
            target = set_aside(path)
        except OSError as e:
            raise TableError(
                f"corrupt table {path}: {problem}; it cannot be moved aside ({e.strerror or e}): "
                "make its folder writable, or delete it, and rerun"
            ) from None
        report(f"corrupt table {path}: {problem}; moved to {target.name}; the default target rebuilds it")
        moved.append(path)
    return moved + set_aside_mixed_runs(root, report)


def set_aside_mixed_runs(root, report=print) -> list[Path]:
    """Set aside (as ``set_aside``) every table below ``root`` that names a run (io.write_run)
    whose other tables are there from another run, or from none: a run stopped between the
    renames of its tables (SIGKILL, a power cut) left tables of two runs side by side, each
    whole and under its own checksum. Both sides are moved, so the job writing them runs again.
    A table whose partner is missing is left (the job reruns for the missing one); a table that
    cannot be read is corrupt_tables' to judge. Reads each table's footer (its key-value metadata)
    only. Returns the tables moved; one that cannot be moved raises TableError."""
    from ..core.io import run_of

    root = Path(root)
    mixed = {}
    for path in sorted(root.rglob("*.parquet")) if root.exists() else []:
        run = run_of(path) if path.is_file() else None
        for name in (run or {}).get("tables", []):
            other = path.parent / str(name)
            if other.is_file() and (run_of(other) or {}).get("id") != run["id"]:
                mixed[path] = f"it is from run {run['id'][:12]}, its {name} from another run"
    moved = []
    for path, problem in mixed.items():
        try:
            target = set_aside(path)
        except OSError as e:
            raise TableError(
                f"table {path}: {problem}; it cannot be moved aside ({e.strerror or e}): "
                "make its folder writable, or delete it, and rerun"
            ) from None
        report(f"table {path}: {problem}; moved to {target.name}; the default target rebuilds it")
        moved.append(path)
    return moved


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


def disk_space_problems(paths=(".", "results", ".snakemake"), device_of=lambda p: os.stat(p).st_dev) -> list[str]:
    """``disk_space_problem`` of each file system holding one of ``paths`` (each once, the first
    path naming it; a missing path is skipped): results/ may live on another file system than
    the working directory, through a link or a mount. ``device_of``: a path's file system."""
    out, seen = [], set()
    for path in paths:
        try:
            device = device_of(path)
        except OSError:
            continue
        if device in seen:
            continue
        seen.add(device)
        problem = disk_space_problem(path)
        if problem:
            out.append(problem)
    return out


# A run writes .snakemake/ (Snakemake's state) and results/, and numba writes its cache of compiled
# kernels; where one of them cannot be written every job fails, on a traceback or an empty log.
# The workflow says so in one line before any job instead (workflow/rules/common.smk).
NUMBA_CACHE_PROBE_BYTES = 4 * 2**20  # twice what numba's cache of every kernel takes (1.8 MB)


def write_problem(folder: str | os.PathLike, probe_bytes: int = 0) -> str | None:
    """Why no file can be written in ``folder``, or None: the folder is made if missing (as the run
    would), a temporary file made in it with ``probe_bytes`` written, then removed."""
    try:
        Path(folder).mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder) as f:
            for _ in range(0, probe_bytes, 2**20):
                f.write(bytes(2**20))
            f.flush()
    except OSError as e:
        return e.strerror or str(e)
    return None


def folder_problems(folders=(".snakemake", "results")) -> list[str]:
    """A line for each of ``folders`` in which nothing can be written, naming it and what to do."""
    out = []
    for folder in folders:
        why = write_problem(folder)
        if why:
            out.append(
                f"cannot write in {folder}/ ({Path(folder).absolute()}): {why}; run in a writable working "
                "directory (snakemake -d <folder>) or make this one writable"
            )
    return out


def numba_cache_folders(library: str | os.PathLike, environ=os.environ) -> list[Path]:
    """Where numba keeps the compiled kernels of ``library``'s numerics, in the order numba tries
    them (numba.core.caching's locators): $NUMBA_CACHE_DIR, the __pycache__ beside the kernels'
    sources, the user's cache ($XDG_CACHE_HOME or ~/.cache, then numba). Numba takes the first in
    which it can make a file, and fails on a write there (a full disk) or when none is writable."""
    folders = [Path(environ["NUMBA_CACHE_DIR"])] if environ.get("NUMBA_CACHE_DIR") else []
    folders.append(Path(library) / "particle_entropy" / "numerics" / "__pycache__")
    folders.append(Path(environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "numba")
    return folders


def numba_cache_problem(folders: list[Path], probe_bytes: int = NUMBA_CACHE_PROBE_BYTES) -> str | None:
    """A line when numba cannot keep compiled kernels in the first of ``folders`` it would take (no
    room: ENOSPC or a quota) or can take none (all read-only or not folders), naming the folder and
    what to change; None otherwise."""
    tried = []
    for folder in folders:
        why = write_problem(folder)
        if why is None:
            full = write_problem(folder, probe_bytes)
            if full is None:
                return None
            mb = probe_bytes / 2**20
            return (
                f"No space left for numba's cache of compiled kernels in {folder} ({full}): free {mb:.0f} MB "
                f"there, or set NUMBA_CACHE_DIR to a folder with room, and rerun"
            )
        tried.append(f"{folder} ({why})")
    return (
        f"numba has no writable folder for its cache of compiled kernels: {'; '.join(tried)}; "
        "set NUMBA_CACHE_DIR to a writable folder and rerun"
    )
