"""A finished run as a Workflow Run RO-Crate (results/ro-crate/), for a repository to ingest.

The crate (https://w3id.org/ro/wfrun/provenance/0.5, built with the ``rocrate`` library) holds:

- the workflow: the Snakefile as the crate's main entity, with its rule files and scripts, the git
  commit it ran at and whether the tree was dirty;
- the config as run (``config.yaml`` merged with every ``--configfile`` and ``--config``), with its
  SHA-256;
- the software: requirements.lock, Python and the versions of the key packages;
- one action per recorded job (Snakemake's own metadata, ``.snakemake/metadata``) that made what
  this config's targets need: its rule, inputs and outputs with SHA-256, start and end time, the
  code hash the rule's ``code`` parameter carries (pipeline/codeversion.py) and the commit it ran
  at (``start_session``, recorded as each run of jobs starts), grouped per rule as the Provenance
  Run Crate asks (a HowToStep and a tool per rule, a ControlAction per job, one OrganizeAction for
  the run); an output changed since its job wrote it is described as changed, not as its output;
- the paper the run reproduces (its DOI) and CITATION.cff.

Every data file is hard-linked into the crate (copied where a link cannot be made), so a crate of a
paper run costs no space; tables are hashed from the run's digest cache where it vouches for them
(pipeline/verify.py), so building a crate reads no table twice. ``verify_crate`` checks a crate's
files against the digests it records. A rebuild keeps what a person added to the crate (entities,
properties, files: ``merge_additions``), and writes through no link.
"""

from __future__ import annotations

import base64
import functools
import hashlib
import json
import os
import platform
import re
import shutil
import subprocess
import time
import warnings
from collections import defaultdict
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import yaml

from ..core.io import write_bytes_atomically
from .verify import CRATE_DIR, DIGESTS, cached_digests, file_sha256, recorded_digest, restamp_digests, stamp

RO_CRATE_VERSION = "1.1"  # the version the Workflow Run Crate profiles 0.5 build on
SHA256_TERM = "https://w3id.org/ro/terms/workflow-run#sha256"  # the profiles' digest property
METADATA = "ro-crate-metadata.json"
CONFIG_AS_RUN = "config-as-run.yaml"
PROFILES = {  # the profiles the crate conforms to (versioned permalinks)
    "process": "https://w3id.org/ro/wfrun/process/0.5",
    "workflow": "https://w3id.org/ro/wfrun/workflow/0.5",
    "provenance": "https://w3id.org/ro/wfrun/provenance/0.5",
    "workflow-ro-crate": "https://w3id.org/workflowhub/workflow-ro-crate/1.0",
}
KEY_PACKAGES = ("numpy", "scipy", "pandas", "pyarrow", "numba", "matplotlib", "snakemake", "rocrate")
SNAKEMAKE_URL = "https://snakemake.github.io"
DESCRIBED = ("figures/", "results/")  # the folders whose job outputs the crate holds
FORMATS = {  # a file's media type by its suffix (encodingFormat)
    ".parquet": "application/vnd.apache.parquet",
    ".png": "image/png",
    ".pdf": "application/pdf",
    ".html": "text/html",
    ".md": "text/markdown",
    ".py": "text/x-python",
    ".smk": "text/x-python",  # Snakemake's rule files: Python with rule blocks
    ".yaml": "application/yaml",
    ".cff": "application/yaml",
    ".json": "application/json",
    ".tsv": "text/tab-separated-values",
    ".lock": "text/plain",
    ".log": "text/plain",
}
README = "README.md"
SESSIONS = ".snakemake/particle_entropy/sessions"  # a record per run of jobs: its commit, tree and config
GENERATED = ".snakemake/particle_entropy/crate_generated.json"  # the graph the last build wrote
OWN = ("figures/", "results/", "workflow/")  # the crate's folders the workflow fills; the rest is the user's
# ids the workflow writes (its files are below OWN or named above): any other id is a person's addition
WORKFLOW_ID = re.compile(r"#(job|control|rule|step|param|software)-.*|#(git|python|snakemake|run|organize)")
# properties the workflow writes on some builds only: without a record of the last build, never kept
WORKFLOW_KEYS = {"exampleOfWork", "description", "softwareVersion", "citation", "identifier", "object", "result"}


class CrateError(Exception):
    """Why the crate cannot be built, in one line."""


@dataclass(frozen=True)
class Job:
    """One recorded rule execution (Snakemake's metadata of its outputs)."""

    rule: str
    start: float
    end: float  # Snakemake records each output's modification time as the job's end time
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    code: str  # the code hash of the rule's ``code`` parameter ('' if it has none)
    script: str = ""  # the rule's script below workflow/scripts ('' if it runs none)


CODE_HASH = re.compile(r"'([0-9a-f]{16})'")  # a code_version hash as Snakemake records a param


def recorded_jobs(workdir: Path, coded: Iterable[str]) -> list[Job]:
    """Every job Snakemake recorded in ``workdir`` whose outputs still exist, once, in start order.
    ``coded``: the rules with a ``code`` parameter; Snakemake records a job's params as sorted
    text, without names, so the code hash is the one param of its form (codeversion.code_version:
    16 hex digits), and '' where there is not exactly one."""
    coded = set(coded)
    folder = workdir / ".snakemake" / "metadata"
    grouped: dict[tuple, dict] = {}
    for entry in sorted(folder.iterdir()) if folder.is_dir() else []:
        name = entry.name
        output = base64.urlsafe_b64decode(name + "=" * (-len(name) % 4)).decode()
        try:
            record = json.loads(entry.read_bytes())
        except (OSError, ValueError):
            continue
        if record.get("incomplete") or not (workdir / output).is_file():
            continue
        rule = record.get("rule", "")
        params = record.get("params") or []
        hashes = [m.group(1) for p in params if (m := CODE_HASH.fullmatch(str(p)))] if rule in coded else []
        code = hashes[0] if len(hashes) == 1 else ""
        key = (rule, record.get("endtime"), record.get("job_hash"))  # a job's outputs differ in start time
        script = re.search(r"scripts/([\w.-]+\.py)", record.get("code") or "")
        job = grouped.setdefault(
            key,
            {
                "inputs": tuple(record.get("input") or ()),
                "outputs": [],
                "code": code,
                "script": script.group(1) if script else "",
                "start": float(record.get("starttime") or 0.0),
            },
        )
        job["outputs"].append(output)
        job["start"] = min(job["start"], float(record.get("starttime") or 0.0))
    jobs = [
        Job(rule, j["start"], float(end or 0.0), j["inputs"], tuple(sorted(j["outputs"])), j["code"], j["script"])
        for (rule, end, _), j in grouped.items()
    ]
    return sorted(jobs, key=lambda j: (j.start, j.rule, j.outputs))


def needed_jobs(jobs: list[Job], targets: Iterable[str]) -> list[Job]:
    """The ``jobs`` that made ``targets`` and, through their recorded inputs, what those needed,
    transitively: a job of a run with another config (a scene of another --configfile), whose
    outputs no target needs, is not this run's."""
    maker = {o: j for j in jobs for o in j.outputs}
    todo, seen, keep = list(targets), set(), set()
    while todo:
        path = todo.pop()
        if path in seen:
            continue
        seen.add(path)
        job = maker.get(path)
        if job is not None and job not in keep:
            keep.add(job)
            todo.extend(job.inputs)
    return [j for j in jobs if j in keep]


def changed_outputs(workdir: Path, job: Job) -> list[str]:
    """The outputs of ``job`` written since it ended (a hand edit): their modification time is
    not the one Snakemake recorded as the job ended. A table whose bytes still match the digest
    the job wrote beside it (only moved or copied) is the job's."""
    out = []
    for rel in job.outputs:
        path = workdir / rel
        if abs(path.stat().st_mtime - job.end) <= 1e-6:
            continue
        want = recorded_digest(path) if rel.endswith(".parquet") else None
        if want is None or want != file_sha256(path):
            out.append(rel)
    return out


def start_session(checkout: str | os.PathLike, config: Mapping, workdir: str | os.PathLike = ".") -> Path | None:
    """Record, as a run of jobs starts (the Snakefile's onstart), the commit it runs at, whether
    tracked files differed from it and the config's digest (SESSIONS); the crate gives each job
    the record of the run it started in. Returns the record's path; None where it cannot be
    written (a full disk): the run goes on, and its jobs' commit is unknown to the crate."""
    commit, dirty = git_state(Path(checkout))
    folder = Path(workdir) / SESSIONS
    path = folder / f"{time.time_ns()}-{os.getpid()}.json"
    record = {"start": time.time(), "commit": commit, "dirty": dirty, "config_sha256": config_digest(config)}
    try:
        folder.mkdir(parents=True, exist_ok=True)
        write_bytes_atomically(json.dumps(record).encode(), path, sync=False)
    except OSError:
        return None
    return path


def end_session(path: str | os.PathLike | None) -> None:
    """Add the end time to a run's record (the Snakefile's onsuccess and onerror)."""
    if path is None:
        return
    path = Path(path)
    try:
        record = json.loads(path.read_text())
        record["end"] = time.time()
        write_bytes_atomically(json.dumps(record).encode(), path, sync=False)
    except (OSError, ValueError, TypeError):
        return


def sessions(workdir: Path) -> list[dict]:
    """The recorded runs of jobs in ``workdir`` (start_session), in start order."""
    found = []
    for path in (workdir / SESSIONS).glob("*.json") if (workdir / SESSIONS).is_dir() else []:
        try:
            record = json.loads(path.read_text())
            float(record["start"])
        except (OSError, ValueError, KeyError, TypeError):
            continue
        found.append(record)
    return sorted(found, key=lambda r: float(r["start"]))


def session_of(start: float, runs: list[dict]) -> dict | None:
    """The recorded run a job that started at ``start`` belongs to: the last to start before it,
    unless that one had ended by then (the job ran in a run that recorded nothing)."""
    before = [r for r in runs if float(r["start"]) <= start]
    if not before or ("end" in before[-1] and start > float(before[-1]["end"])):
        return None
    return before[-1]


def ran_at(run: dict | None) -> str:
    """A job's commit as its run recorded it, in words."""
    if run is None:
        return "commit unknown (no record of the run it started in)"
    if not run.get("commit"):
        return "not in a git checkout"
    tree = {True: "dirty: tracked files differed from it", False: "clean"}.get(run.get("dirty"), "tree unknown")
    return f"commit {run['commit']} ({tree})"


def crate_folder_problem(workdir: str | os.PathLike, out: str | os.PathLike = CRATE_DIR) -> str | None:
    """Why the crate cannot be written at ``out`` (below ``workdir``), in one line, or None: a file
    in its place, or a link to a folder outside results/ (the crate never writes through one)."""
    path = Path(workdir) / out
    if path.is_symlink():
        results = (Path(workdir) / "results").resolve()
        target = path.resolve()
        if target != results and results not in target.parents:
            return (
                f"{out} is a link to {os.readlink(path)}, outside results/: the crate writes no file through "
                f"it; remove the link (rm {out}) and rerun"
            )
    if (path.exists() or path.is_symlink()) and not path.is_dir():
        return f"{out} is a file, not a folder: the crate is written there; move it away (mv {out} {out}.old) and rerun"
    metadata = path / METADATA
    if metadata.is_symlink():  # Snakemake would restore a failed build's backup through it
        return (
            f"{out}/{METADATA} is a link to {os.readlink(metadata)}: the crate writes no file through a link; "
            f"put the file itself there (cp --remove-destination $(readlink -f {out}/{METADATA}) {out}/{METADATA})"
        )
    return None


def _real_folders(out: Path, rel: str, progress=lambda line: None) -> Path:
    """``out / rel`` with every folder between made a real folder below ``out``: a link there is
    replaced by a folder (the link alone is removed, never what it points to), as is a file; a
    link at ``rel`` itself is removed. The crate then writes no byte outside ``out``."""
    folder = out
    for part in Path(rel).parts[:-1]:
        folder = folder / part
        if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
            what = f"a link to {os.readlink(folder)}" if folder.is_symlink() else "a file"
            progress(f"crate: {folder} was {what}; replaced by a folder (what it pointed to is untouched)")
            folder.unlink()
        folder.mkdir(exist_ok=True)
    target = out / rel
    if target.is_symlink():
        target.unlink()
    return target


def _write_text(out: Path, rel: str, text: str, progress=lambda line: None) -> None:
    """Write ``text`` at ``out / rel`` in place of any link there (_real_folders), atomically."""
    write_bytes_atomically(text.encode(), _real_folders(out, rel, progress), sync=False)


def _refs(value) -> list:
    return value if isinstance(value, list) else [value]


def merge_additions(new: dict, old: dict, generated: dict | None) -> tuple[dict, set[str]]:
    """The metadata ``new`` (just built) with what a person added to ``old`` (the crate's metadata
    before this build). With ``generated`` (the metadata the last build wrote): every entity it
    lacked, and every property whose value differs from it (a person's value wins; a list gains
    the added items). Without: every entity whose id the workflow never writes, every property
    the new entity lacks but the workflow never writes, and the items of a list that name a kept
    entity. Returns the merged metadata and the ids of the entities kept from ``old``."""
    ids = lambda meta: {e["@id"]: e for e in meta.get("@graph", []) if isinstance(e, dict) and "@id" in e}  # noqa: E731
    old_g, new_g = ids(old), ids(new)
    gen_g = ids(generated) if generated is not None else None
    if gen_g is not None:
        added = {i for i in old_g if i not in gen_g}
    else:
        added = {i for i in old_g if i not in new_g and not WORKFLOW_ID.fullmatch(i) and not _own_path(i)}
    graph = list(new.get("@graph", [])) + [old_g[i] for i in sorted(added - set(new_g))]
    for i in set(old_g) & set(new_g):
        target, base = new_g[i], (gen_g or {}).get(i)
        for key, value in old_g[i].items():
            before = base.get(key) if base is not None else None
            if key == "@id" or (base is not None and value == before):
                continue  # as the last build wrote it
            if key not in target:
                if base is not None or key not in WORKFLOW_KEYS:
                    target[key] = value
            elif isinstance(value, list | dict) and isinstance(target[key], list | dict):
                mine = [v for v in _refs(value) if v not in _refs(target[key])]
                if base is None:  # no record of what the workflow wrote: only links to kept entities
                    mine = [v for v in mine if isinstance(v, dict) and v.get("@id") in added]
                else:
                    mine = [v for v in mine if v not in _refs(before)]
                target[key] = _one(_refs(target[key]) + mine) if mine else target[key]
            elif base is not None:
                target[key] = value  # a person's value wins over the workflow's
    return {**new, "@graph": graph}, added


def _own_path(entity_id: str) -> bool:
    """Whether ``entity_id`` names a file the workflow writes into the crate (or the root)."""
    own = {"./", "Snakefile", CONFIG_AS_RUN, METADATA, README, "requirements.lock", "CITATION.cff"}
    return entity_id.startswith(OWN) or entity_id in own


class Digests:
    """SHA-256 of files below a run folder: a table from the run's digest cache where its entry
    still vouches for it (the table check has read it), anything else read once. ``linked`` then
    gives the cache the new stamps of vouched tables that were hard-linked since (a link moves a
    file's ctime, not its bytes), so the next check does not read them again either."""

    def __init__(self, workdir: Path):
        self.workdir = workdir
        self.cache = cached_digests(workdir / DIGESTS)
        self.reads = 0  # files read to hash them
        self.tables_read = 0  # of which tables
        self._known: dict[str, str] = {}
        self._vouched: dict[str, str] = {}  # cache key -> digest, for tables the cache vouched for

    @staticmethod
    def _key(rel: str) -> str | None:
        return Path(rel).relative_to("results").as_posix() if rel.startswith("results/") else None

    def __call__(self, rel: str) -> str:
        if rel not in self._known:
            path = self.workdir / rel
            key = self._key(rel)
            entry = self.cache.get(key) if key else None
            if entry and entry[:4] == stamp(path.stat()):
                digest = self._vouched[key] = entry[4]
            else:
                digest = file_sha256(path)
                self.reads += 1
                self.tables_read += rel.endswith(".parquet")
                want = recorded_digest(path) if rel.endswith(".parquet") else None
                if want is not None and want != digest:
                    raise ValueError(f"{rel}: its SHA-256 differs from the one recorded beside it; rerun the workflow")
            self._known[rel] = digest
        return self._known[rel]

    def linked(self) -> None:
        """Restamp the cache entries of the vouched tables (verify.restamp_digests)."""
        tables = {}
        for key, digest in self._vouched.items():
            path = self.workdir / "results" / key
            tables[key] = [*stamp(path.stat()), digest]
        if tables:
            restamp_digests(self.workdir / DIGESTS, tables)


def git_state(folder: Path) -> tuple[str, bool | None]:
    """(commit, dirty) of the checkout holding ``folder``: ('', None) outside git. Dirty: a tracked
    file differs from the commit (untracked files such as results do not count)."""
    try:
        commit = subprocess.run(
            ["git", "-C", str(folder), "rev-parse", "HEAD"], capture_output=True, text=True, check=True, timeout=30
        ).stdout.strip()
        status = subprocess.run(
            ["git", "-C", str(folder), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            check=True,
            timeout=60,
        ).stdout
    except (OSError, subprocess.SubprocessError):
        return "", None
    return commit, bool(status.strip())


def config_text(config: Mapping) -> str:
    """The config as run, as YAML with sorted keys: the text whose digest names it."""
    return yaml.safe_dump(json.loads(json.dumps(config, default=str)), sort_keys=True)


def config_digest(config: Mapping) -> str:
    """SHA-256 of config_text(config)."""
    return hashlib.sha256(config_text(config).encode()).hexdigest()


def _place(source: Path, out: Path, rel: str, progress=lambda line: None) -> None:
    """Put ``source`` at ``out / rel``: a hard link, else a copy (another file system). A link to the
    same file already there is kept: replacing it would move the file's ctime, and with it the
    table check's trust in its digest. A symbolic link on the way is replaced, never written
    through (_real_folders)."""
    target = _real_folders(out, rel, progress)
    if target.is_file() and os.path.samefile(source, target):
        return
    if target.exists():
        target.unlink()
    try:
        os.link(source, target)
    except OSError:
        shutil.copy2(source, target)


def _remove_others(folder: Path, keep: set[Path]) -> None:
    """Remove every file below the workflow's folders of the crate (OWN) that is not in ``keep``
    (an older run's); what a person put elsewhere in the crate stays. A link is removed, never
    followed."""
    for own in OWN:
        top = folder / own
        if top.is_symlink():
            top.unlink()
            continue
        for path in sorted(top.rglob("*"), reverse=True) if top.is_dir() else []:
            if path.is_dir() and not path.is_symlink():
                if not any(path.iterdir()):
                    path.rmdir()
            elif path not in keep:
                path.unlink()


def _one(values: list):
    """A list, or its one value alone (RO-Crate 1.1 writes a single value without brackets)."""
    return values[0] if len(values) == 1 else values


def _readme(commit: str, dirty: bool | None, config: Mapping, jobs: list[str], files: int, changed: list[str]) -> str:
    """The crate's README.md: what it holds and how it was made (``jobs``: how many jobs ran at
    which commit, in words; ``changed``: outputs edited since their job)."""
    state = {True: " (tracked files differed from it)", False: "", None: ""}[dirty]
    edited = (
        f"\n\nChanged since the job that wrote them, so described as changed, not as its output: {', '.join(changed)}."
        if changed
        else ""
    )
    return (
        "# A run of the particle-entropy workflow\n\n"
        "This folder is a Workflow Run RO-Crate (Provenance Run Crate 0.5): `ro-crate-metadata.json` describes "
        f"the workflow (`Snakefile`, `workflow/`), the config as run (`{CONFIG_AS_RUN}`, SHA-256 "
        f"{config_digest(config)}), the pinned software (`requirements.lock`) and the jobs that made "
        f"its {files} files, each with its SHA-256.\n\n"
        f"The jobs ran at: {'; '.join(jobs) or 'none'}. The workflow's files here are those of commit "
        f"{commit or 'unknown'}{state}, where `snakemake -j2 crate` built this crate "
        "(docs/deposit.md of the workflow). It reproduces Benson et al. (2020), Advances in Water Resources "
        f"103509, https://doi.org/10.1016/j.advwatres.2020.103509 (`CITATION.cff`).{edited}\n"
    )


def _when(seconds: float) -> str:
    return datetime.fromtimestamp(seconds, UTC).isoformat(timespec="seconds")


def _paper(citation: Mapping) -> dict | None:
    """The article CITATION.cff cites (its DOI) as a ScholarlyArticle."""
    for ref in citation.get("references") or []:
        if ref.get("doi"):
            authors = ", ".join(
                f"{a.get('given-names', '')} {a.get('family-names', '')}".strip() for a in ref["authors"]
            )
            return {
                "@id": f"https://doi.org/{ref['doi']}",
                "@type": "ScholarlyArticle",
                "name": ref.get("title", ""),
                "author": authors,
                "datePublished": str(ref.get("year", "")),
                "publisher": ref.get("journal", ""),
                "identifier": f"https://doi.org/{ref['doi']}",
            }
    return None


def build_crate(
    workdir: str | os.PathLike,
    checkout: str | os.PathLike,
    config: Mapping,
    coded: Iterable[str],
    out: str | os.PathLike = CRATE_DIR,
    progress=lambda line: None,
    targets: Iterable[str] | None = None,
    optional: Iterable[str] = (),
) -> dict:
    """Write the crate of the finished run in ``workdir`` (code from ``checkout``, the config as run,
    ``coded``: the rules with a ``code`` parameter) into ``out``; returns a summary (files, jobs,
    files read to hash them). ``targets``: the config's targets; only the jobs they needed are
    described (needed_jobs); None: every recorded job. ``optional``: the config's targets outside
    the default one (scenes, searches), which the crate's own run does not bring up to date: each
    counts where a run of this same config made it. CrateError: why it cannot be built."""
    try:
        return _build_crate(workdir, checkout, config, coded, out, progress, targets, optional)
    except ValueError as e:  # a table whose bytes differ from its recorded digest
        raise CrateError(str(e)) from None


def _build_crate(workdir, checkout, config, coded, out, progress, targets, optional) -> dict:
    from rocrate.model.contextentity import ContextEntity
    from rocrate.rocrate import ROCrate

    workdir, checkout = Path(workdir).resolve(), Path(checkout).resolve()
    problem = crate_folder_problem(workdir, out)
    if problem:
        raise CrateError(problem)
    out = (workdir / out).resolve()
    out.mkdir(parents=True, exist_ok=True)  # an older crate's links are kept where they still hold
    old, generated = _previous(out, workdir)
    digests = Digests(workdir)
    digest = config_digest(config)
    jobs = [j for j in recorded_jobs(workdir, coded) if any(o.startswith(DESCRIBED) for o in j.outputs)]
    runs = sessions(workdir)
    if targets is not None:
        maker = {o: j for j in jobs for o in j.outputs}
        wanted = list(targets)
        for rel in optional:
            job, run = maker.get(rel), None
            if job is not None:
                run = session_of(job.start, runs)
                if run is not None and run.get("config_sha256") == digest:
                    wanted.append(rel)
                else:
                    why = "a run of another config" if run else "a run that recorded no config"
                    progress(f"crate: {rel} left out: made by {why}")
        jobs = needed_jobs(jobs, wanted)
    run_of = {j: session_of(j.start, runs) for j in jobs}
    changed = {o: j for j in jobs for o in changed_outputs(workdir, j)}
    progress(f"crate: {len(jobs)} recorded jobs")
    for rel, job in sorted(changed.items()):
        progress(f"crate: {rel} changed after the {job.rule} job that wrote it: described as changed, not its output")

    crate = ROCrate(version=RO_CRATE_VERSION)
    crate.metadata.extra_terms["sha256"] = SHA256_TERM
    crate.name = "particle-entropy: a run of the workflow"
    crate.description = (
        "Every figure and table of a run of the particle-entropy workflow, with the jobs that made them."
    )
    crate.license = crate.add(
        ContextEntity(crate, "https://spdx.org/licenses/MIT", {"@type": "CreativeWork", "name": "MIT License"})
    )
    crate.root_dataset["datePublished"] = _when(max((j.end for j in jobs), default=0.0))
    profiles = [
        crate.add(ContextEntity(crate, uri, {"@type": "CreativeWork", "name": key, "version": uri.rsplit("/", 1)[-1]}))
        for key, uri in PROFILES.items()
    ]
    crate.root_dataset["conformsTo"] = profiles

    files: dict[str, object] = {}

    def data(rel: str, source: Path | None = None, kind: str | list = "File", **props):
        """The crate's File entity for ``rel`` (a path below the run), placed in the crate once."""
        if rel not in files:
            src = source if source is not None else workdir / rel
            props.setdefault("sha256", digests(rel) if source is None else file_sha256(src))  # before the link
            _place(src, out, rel, progress)
            props.setdefault("contentSize", str(src.stat().st_size))
            props.setdefault("name", Path(rel).name)
            fmt = FORMATS.get(Path(rel).suffix)
            if fmt:
                props.setdefault("encodingFormat", fmt)
            with warnings.catch_warnings():  # the file is placed here, not copied by the library
                warnings.simplefilter("ignore", UserWarning)
                files[rel] = crate.add_file(None, dest_path=rel, properties={"@type": kind, **props})
        return files[rel]

    # the workflow, its rules and scripts, as they were in the checkout
    commit, dirty = git_state(checkout)
    rules = sorted((checkout / "workflow" / "rules").glob("*.smk"))
    scripts = sorted((checkout / "workflow" / "scripts").glob("*.py"))
    for p in rules + scripts:  # the rule files and scripts, as they were in the checkout
        data(p.relative_to(checkout).as_posix(), p, kind=["File", "SoftwareSourceCode"], version=commit or "unknown")
    snakefile = checkout / "Snakefile"
    _place(snakefile, out, "Snakefile", progress)
    workflow = crate.add_workflow(
        None,
        dest_path="Snakefile",
        main=True,
        lang="snakemake",
        properties={
            "@type": ["File", "SoftwareSourceCode", "ComputationalWorkflow", "HowTo"],  # HowTo: it has steps
            "name": "particle-entropy workflow",
            "encodingFormat": FORMATS[".smk"],
            "sha256": file_sha256(snakefile),
            "version": commit or "unknown",
        },
    )
    state = crate.add(
        ContextEntity(
            crate,
            "#git",
            {
                "@type": "PropertyValue",
                "name": "git checkout of the workflow",
                "propertyID": "git",
                "value": f"the workflow's files in this crate: commit {commit or 'unknown'}; "
                + {True: "dirty (tracked files differ from the commit)", False: "clean", None: "not a git checkout"}[
                    dirty
                ]
                + "; each job's commit is in its action's description",
            },
        )
    )
    workflow["identifier"] = state

    # the config as run, the lock file, the citation
    _write_text(out, CONFIG_AS_RUN, config_text(config), progress)
    config_file = crate.add_file(
        None,
        dest_path=CONFIG_AS_RUN,
        properties={"name": "the config as run", "sha256": config_digest(config), "encodingFormat": "application/yaml"},
    )
    lock = data("requirements.lock", checkout / "requirements.lock", name="the pinned environment")
    citation_path = checkout / "CITATION.cff"
    citation = data("CITATION.cff", citation_path, name="how to cite")
    paper = _paper(yaml.safe_load(citation_path.read_text()) or {})
    if paper:
        article = crate.add(ContextEntity(crate, paper.pop("@id"), paper))
        crate.root_dataset["citation"] = article
        workflow["citation"] = article

    software = [
        crate.add(
            ContextEntity(
                crate,
                f"#software-{name}",
                {"@type": "SoftwareApplication", "name": name, "softwareVersion": _version(name)},
            )
        )
        for name in KEY_PACKAGES
    ]
    python = crate.add(
        ContextEntity(
            crate,
            "#python",
            {"@type": "SoftwareApplication", "name": "Python", "softwareVersion": platform.python_version()},
        )
    )
    engine = crate.add(
        ContextEntity(
            crate,
            "#snakemake",
            {
                "@type": "SoftwareApplication",
                "name": "Snakemake",
                "url": SNAKEMAKE_URL,
                "softwareVersion": _version("snakemake"),
            },
        )
    )
    workflow["softwareRequirements"] = [python, *software]

    # formal parameters: the config in, each figure out
    config_param = crate.add(
        ContextEntity(
            crate,
            "#param-config",
            {"@type": "FormalParameter", "name": "config", "additionalType": "File", "workExample": config_file},
        )
    )
    config_file["exampleOfWork"] = config_param
    figures = sorted({o for j in jobs for o in j.outputs if o.startswith("figures/") and o not in changed})
    out_params = []
    for rel in figures:
        entity = data(rel, name=Path(rel).name)
        param = crate.add(
            ContextEntity(
                crate,
                f"#param-{rel}",
                {"@type": "FormalParameter", "name": rel, "additionalType": "File", "workExample": entity},
            )
        )
        entity["exampleOfWork"] = param
        out_params.append(param)
    workflow["input"] = config_param
    workflow["output"] = _one(out_params)

    # per rule a tool and a step; per job a CreateAction and a ControlAction
    tools, steps = {}, {}
    script_of = {j.rule: j.script for j in jobs}
    codes: dict[str, set] = defaultdict(set)
    for j in jobs:
        codes[j.rule].add(j.code)
    for position, rule in enumerate(sorted(script_of)):
        tool = {"@type": "SoftwareApplication", "name": f"rule {rule}"}
        if codes[rule] - {""}:  # its version: the code hash of the modules it ran (one per code version)
            tool["softwareVersion"] = ", ".join(sorted(codes[rule] - {""}))
        script = f"workflow/scripts/{script_of[rule]}"
        if script_of[rule] and script in files:
            tool["hasPart"] = files[script]  # the rule's script, as it was in the checkout
        tools[rule] = crate.add(ContextEntity(crate, f"#rule-{rule}", tool))
        steps[rule] = crate.add(
            ContextEntity(
                crate,
                f"#step-{rule}",
                {"@type": "HowToStep", "name": rule, "position": str(position), "workExample": tools[rule]},
            )
        )
    workflow["hasPart"] = list(tools.values())  # the tools it orchestrates: one per rule that ran
    workflow["step"] = list(steps.values())

    controls, actions = [], []
    by_rule: dict[str, int] = defaultdict(int)
    for k, job in enumerate(jobs):
        by_rule[job.rule] += 1
        inputs = [data(i) for i in job.inputs if (workdir / i).is_file() and not i.startswith(CRATE_DIR)]
        name = f"{job.rule} #{by_rule[job.rule]}"
        for rel in job.outputs:
            if rel in changed:
                data(rel)["description"] = f"changed since the job {name} wrote it, so not its output"
        outputs = [data(o) for o in job.outputs if o not in changed]
        run = run_of[job]
        props = {
            "name": name,
            "startTime": _when(job.start),
            "endTime": _when(job.end),
            "actionStatus": "http://schema.org/CompletedActionStatus",
        }
        other = run is not None and run.get("config_sha256") != digest
        props["description"] = "; ".join(
            [*([f"code hash {job.code}"] if job.code else []), f"ran at {ran_at(run)}"]
            + ([f"with another config (SHA-256 {run['config_sha256']})"] if other else [])
        )
        action = crate.add_action(
            tools[job.rule], identifier=f"#job-{k}", object=_one(inputs), result=_one(outputs), properties=props
        )
        actions.append(action)
        controls.append(
            crate.add(
                ContextEntity(
                    crate,
                    f"#control-{k}",
                    {"@type": "ControlAction", "name": props["name"], "instrument": steps[job.rule], "object": action},
                )
            )
        )
        if (k + 1) % 200 == 0:
            progress(f"crate: {k + 1} of {len(jobs)} jobs described")

    run = crate.add_action(
        workflow,
        identifier="#run",
        object=[config_file, lock],
        result=[files[r] for r in figures],
        properties={
            "name": "the workflow run",
            "description": "Snakemake ran the workflow with the config as run: every job, and the figures it made",
            "startTime": _when(min((j.start for j in jobs), default=0.0)),
            "endTime": _when(max((j.end for j in jobs), default=0.0)),
            "actionStatus": "http://schema.org/CompletedActionStatus",
        },
    )
    crate.add(
        ContextEntity(
            crate,
            "#organize",
            {
                "@type": "OrganizeAction",
                "name": "Snakemake's run",
                "instrument": engine,
                "object": controls,
                "result": run,
            },
        )
    )
    crate.root_dataset["mentions"] = [run, *actions]
    crate.root_dataset["about"] = citation
    counts: dict[str, int] = defaultdict(int)
    for job in jobs:
        counts[ran_at(run_of[job])] += 1
    ran = [f"{where} ({n} jobs)" for where, n in sorted(counts.items())]
    _write_text(out, README, _readme(commit, dirty, config, ran, len(files), sorted(changed)), progress)
    crate.add_file(
        None,
        dest_path=README,
        properties={"name": "what this crate is", "encodingFormat": "text/markdown", "about": crate.root_dataset},
    )
    digests.linked()
    built = crate.metadata.generate()
    merged, added = merge_additions(built, old, generated) if old else (built, set())
    if added:
        progress(f"crate: kept {len(added)} entities added to the crate since it was built: {', '.join(sorted(added))}")
    _remove_others(out, {out / rel for rel in files} | {out / i for i in added})
    _write_text(out, METADATA, json.dumps(merged, indent=4, sort_keys=True, ensure_ascii=False), progress)
    record = workdir / GENERATED
    record.parent.mkdir(parents=True, exist_ok=True)
    write_bytes_atomically(json.dumps({"crate": str(out), "metadata": built}).encode(), record, sync=False)
    return {
        "files": len(files) + 2,
        "jobs": len(jobs),
        "hashed": digests.reads,
        "tables": digests.tables_read,
        "path": str(out),
    }


def _previous(out: Path, workdir: Path) -> tuple[dict | None, dict | None]:
    """The crate's metadata before this build (None: there is none), and the metadata the last
    build wrote there (GENERATED; None: no record of it). CrateError when the metadata does not
    parse: it may hold a person's additions."""
    path = out / METADATA
    if not path.is_file():
        return None, None
    try:
        old = json.loads(path.read_text())
        if not isinstance(old, dict) or not isinstance(old.get("@graph"), list):
            raise ValueError("no @graph list")
    except (ValueError, UnicodeDecodeError) as e:
        raise CrateError(
            f"{path.relative_to(workdir)} does not parse as RO-Crate metadata ({e}); it may hold your additions: "
            "fix it, or move it away to build the crate afresh"
        ) from None
    try:
        record = json.loads((workdir / GENERATED).read_text())
        generated = record["metadata"] if record.get("crate") == str(out) else None
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        generated = None
    return old, generated


def _version(name: str) -> str:
    try:
        return version(name)
    except PackageNotFoundError:
        return "not installed"


def verify_crate(folder: str | os.PathLike) -> list[str]:
    """What is wrong with the crate in ``folder``: each file it describes with a SHA-256 must exist
    there and have that digest. [] when all hold."""
    folder = Path(folder)
    graph = json.loads((folder / METADATA).read_text())["@graph"]
    problems = []
    for entity in graph:
        digest = entity.get("sha256")
        if not digest:
            continue
        path = folder / entity["@id"]
        if not path.is_file():
            problems.append(f"{entity['@id']}: missing")
        elif file_sha256(path) != digest:
            problems.append(f"{entity['@id']}: its SHA-256 differs from the crate's record")
    return problems


def described(folder: str | os.PathLike) -> Iterable[str]:
    """The ids of every File the crate in ``folder`` describes."""
    graph = json.loads((Path(folder) / METADATA).read_text())["@graph"]
    return [e["@id"] for e in graph if "File" in (e["@type"] if isinstance(e["@type"], list) else [e["@type"]])]


@functools.cache
def _git_state_once(checkout: str) -> tuple[str, bool | None]:
    """git_state of a checkout, asked once per process: a report asks it for every figure."""
    return git_state(Path(checkout))


@functools.cache
def _runs_once(workdir: str) -> tuple[dict, ...]:
    return tuple(sessions(Path(workdir)))


def output_run(output: str, workdir: str | os.PathLike = ".") -> dict | None:
    """The recorded run of jobs (start_session) in which the job that wrote ``output`` started, by
    Snakemake's record of it; None without one."""
    key = base64.urlsafe_b64encode(str(output).encode()).decode()
    try:
        start = float(json.loads((Path(workdir) / ".snakemake" / "metadata" / key).read_bytes())["starttime"])
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return session_of(start, list(_runs_once(str(Path(workdir).resolve()))))


def provenance(figure: str, rule: str, module: str, data: str, config: Mapping, checkout) -> dict[str, str]:
    """Where a figure came from, for its entry in the report (as showyourwork's margins): the
    commit its job ran at (and whether the tree was dirty) as its run recorded it (else the
    checkout's now, marked so), the config's digest, its rule and module, its source data table
    and that table's SHA-256 as recorded beside it."""
    run = output_run(figure)
    if run is not None:
        commit, dirty, now = run.get("commit") or "", run.get("dirty"), ""
    else:
        (commit, dirty), now = _git_state_once(str(checkout)), " (the checkout now: no record of its run)"
    recorded = recorded_digest(data) if data.endswith(".parquet") else None
    if recorded is None:
        recorded = file_sha256(data) if Path(data).is_file() else "not made yet"
    return {
        "figure": figure,
        "commit": (commit[:12] or "not a git checkout") + (" (dirty)" if dirty else "") + now,
        "config sha256": config_digest(config)[:16],
        "rule": rule,
        "module": module,
        "source data": data,
        "source sha256": recorded[:16],
    }
