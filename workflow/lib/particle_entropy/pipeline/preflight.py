"""What the main Snakemake process checks while it reads the Snakefile, before it plans a job, and
the one place where reading the Snakefile may move files: ``preflight``.

Tables whose bytes no longer match their checksum (truncated, a flipped bit, empty), or that hold
another case than their path names, are moved to ``<name>.corrupt`` before the DAG is built, and
the default target rebuilds every table set aside and not yet rebuilt, so a dry run in between
loses nothing. Each table's SHA-256 is kept against its size, mtime, inode and ctime
(verify.corrupt_tables), beside Snakemake's own state (``verify.DIGESTS``), not in results/, which
may be copied elsewhere, so a table is reread only when it changed; deleting that file makes the
next run read every table. Folders linked under results/ are followed (verify.tables_below).

A command that will not hold Snakemake's lock only looks, changing no file (``looks_only``): a
dry run, a command that runs no job (the run that follows checks the tables before it plans),
and any run while a lock is held, which Snakemake then refuses (another run is writing these
tables; a stale lock needs --unlock, which also only looks). Snakemake takes its lock after the
Snakefile is read, so two runs started in the same instant may both check; and it picks its
action (a run, --unlock, --summary, --dag ...) only after reading it, so the command line is read
again with Snakemake's own parser (invocation.py). Only the main process checks: a job re-parsing
the Snakefile on a cluster node must not judge tables that other jobs are writing at that moment.
Nothing here imports Snakemake: a refusal raises the caller's ``error`` (the workflow passes
Snakemake's WorkflowError, reported in one line without a traceback).
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Mapping, Sequence
from functools import partial
from pathlib import Path

from ..core.case import Case
from ..numerics.compiled import kernels_folder
from ..scenes import reference as reactive
from .crate import crate_folder_problem
from .invocation import runs_no_job, snakemake_options
from .runlock import LockRefused, hold
from .sweeps import RUN_PATTERN, SUMMARY_PATTERN
from .verify import (
    CORRUPT_SUFFIX,
    CRATE_DIR,
    DIGESTS,
    TableError,
    folder_problems,
    numba_cache_folders,
    numba_cache_problem,
    set_aside,
    set_aside_corrupt,
    tables_below,
)


def _path_regex(pattern: str) -> re.Pattern:
    """A path pattern (``results/{kind}/.../seeds~{first}-{last}.parquet``) as a regex with a named
    group for each wildcard, as Snakemake matches an output."""
    parts = re.split(r"\{(\w+)\}", pattern)
    return re.compile("".join(f"(?P<{p}>.+)" if i % 2 else re.escape(p) for i, p in enumerate(parts)) + "$")


NAMED_BY_PATH = [(_path_regex(p), p) for p in (RUN_PATTERN, SUMMARY_PATTERN)]


def named_columns(path: str | os.PathLike) -> dict | None:
    """The column values a run or summary table's path names (its case, and its block of seeds),
    or None for another table: verify.content_problem holds the table to them."""
    for regex, _pattern in NAMED_BY_PATH:
        m = regex.match(Path(path).as_posix())
        if m:
            w = m.groupdict()
            named = Case.from_wildcards(w).columns()
            return named | ({"seed": (int(w["first"]), int(w["last"]))} if "first" in w else {})
    return None


def looks_only(dry_run: bool, options: Mapping | None, locks: str | os.PathLike = ".snakemake/locks") -> bool:
    """Whether this invocation must change no table (see the module): a dry run, a command line
    (``options``, invocation.snakemake_options) that runs no job, or a lock held."""
    locks = Path(locks)
    return dry_run or runs_no_job(options) or (locks.is_dir() and any(locks.iterdir()))


def writable_problems(look_only: bool, local: bool, library: str | os.PathLike) -> list[str]:
    """Where this run cannot write what it must: .snakemake/ (every invocation: Snakemake keeps
    its state there), and for a run of jobs results/ and, run here (``local``) before this code's
    kernels are compiled, numba's cache (verify.numba_cache_folders; a cluster node has its own).
    Else every job fails on a traceback or an empty log."""
    problems = folder_problems([".snakemake"] if look_only else [".snakemake", "results"])
    if not look_only and local and not Path(kernels_folder()).is_dir():
        # numba's cache is written while the first job compiles the kernels of this code (compiled.take);
        # once they are, jobs load them and numba caches nothing
        problems += [p for p in [numba_cache_problem(numba_cache_folders(library))] if p]
    return problems


def crate_requested(options: Mapping | None) -> bool:
    """Whether the command line (``options``, invocation.snakemake_options) asks for the crate: its
    rule or a path in its folder; an unknown command line (the API) may."""
    if options is None:
        return True
    return any(t == "crate" or Path(t).as_posix().startswith(CRATE_DIR) for t in options.get("targets") or [])


# a reactive scene's references (scenes/reference.py), below results/: checked as tables are
REFERENCES = Path(reactive.REFERENCE_PATTERN).parent.relative_to("results")


def references_in(root="results", suffix=".json") -> list[Path]:
    """The entries of the references folder below ``root`` whose names end in ``suffix``, sorted:
    only its own (REFERENCE_PATTERN is flat), never what a folder in a reference's place holds."""
    folder = Path(root) / REFERENCES
    try:
        names = os.listdir(folder)
    except OSError:  # no reference yet, or no folder there: the scene_reference job says so
        return []
    return sorted(folder / name for name in names if name.endswith(suffix))


def set_aside_bad_references(root="results", report=print) -> list[Path]:
    """Set aside (verify.set_aside) every reference file below ``root`` that reactive.problem
    refuses (damaged, no or a wrong checksum, another physics' file copied in), reporting each in
    one line, so that the run rebuilds it; returns those moved. Every file is read each time: they
    are few and small. One that cannot be moved raises TableError."""
    moved = []
    for path in references_in(root):
        problem = reactive.problem(path)
        if problem is None:
            continue
        try:
            target = set_aside(path)
        except OSError as e:
            raise TableError(
                f"corrupt reference {path}: {problem}; it cannot be moved aside ({e.strerror or e}): "
                "make its folder writable, or delete it, and rerun"
            ) from None
        report(f"corrupt reference {path}: {problem}; moved to {target.name}; the scenes target rebuilds it")
        moved.append(path)
    return moved


def set_aside_corrupt_tables(root="results", look_only=False, digests=DIGESTS, error=RuntimeError) -> list[str]:
    """Move the corrupt tables and references below ``root`` aside (see the module) and return
    those set aside, now or before, and not yet rebuilt. ``look_only``: read no file and move
    none, only name those set aside before. One that cannot be moved (a read-only results/):
    ``error``."""
    if not look_only:
        report = partial(print, file=sys.stderr)
        try:
            set_aside_corrupt(root, digests, named_columns, report=report)
            set_aside_bad_references(root, report=report)
        except TableError as e:
            raise error(str(e)) from None
    aside = tables_below(root, f".parquet{CORRUPT_SUFFIX}")
    aside += references_in(root, f".json{CORRUPT_SUFFIX}")
    missing = [str(p)[: -len(CORRUPT_SUFFIX)] for p in aside]
    return sorted(m for m in missing if not Path(m).exists())


def preflight(
    dry_run: bool, argv: Sequence[str], local: bool, library: str | os.PathLike, error=RuntimeError
) -> list[str]:
    """The main process's checks before it plans a job (see the module), in one call; returns
    the tables set aside and not yet rebuilt, which the default target makes. In order: stop in
    one line (``error``) where the run cannot write what it must (``writable_problems``), or where
    the crate is asked for and cannot be written (crate.crate_folder_problem: a file there, or a
    link out of results/); for a run of jobs, hold results/'s own lock (runlock.py: Snakemake's
    lock is per working directory, so two clones whose results/ link to one folder would both
    write there; a second run is refused naming the first, a file system without locks is said,
    not fatal); then set the corrupt tables aside, or only look. ``dry_run``: Snakemake's (from a
    profile too); ``argv``: sys.argv; ``local``: jobs run on this machine; ``library``: the
    library folder, whose numba cache a local run writes."""
    options = snakemake_options(argv)
    look_only = looks_only(dry_run, options)
    problems = writable_problems(look_only, local, library)
    if problems:
        raise error("\n".join(problems))
    problem = crate_folder_problem(".") if crate_requested(options) else None
    if problem:
        raise error(problem)
    if not look_only:
        try:
            note = hold("results")
        except LockRefused as e:
            raise error(str(e)) from None
        if note:
            print(note, file=sys.stderr)
    return set_aside_corrupt_tables(look_only=look_only, error=error)
