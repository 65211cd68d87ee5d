# Config validation, the cases of every config section, target helpers and code versions.
import re
import sys
from pathlib import Path
from functools import partial

from snakemake.exceptions import WorkflowError
from snakemake.io import regex_from_filepattern
from snakemake.utils import validate

LIB = str(Path(workflow.basedir) / "workflow" / "lib")
sys.path.insert(0, LIB)
from particle_entropy.pipeline.codeversion import export_library_path

export_library_path(LIB)  # jobs import this checkout's library in any software environment
from particle_entropy.pipeline.configcheck import check_schema, load_schema, retype_overrides

SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"
retype_overrides(config, workflow.config_settings.config)  # --config physics={D: 0.002}: a number
# the merged config (config.yaml, --configfile, --config): one short message naming the key path; an
# integer is an int, so --config base_seed=1e3 (1000.0 to Snakemake) is refused, not run as seeds~1000.0
check_schema(config, load_schema(SCHEMA))
validate(config, str(SCHEMA))  # fills the schema's defaults

from particle_entropy.core.case import Case, SettingError
from particle_entropy.pipeline.codeversion import SHEAR_ENTRIES, code_version, simulation_code
from particle_entropy.numerics.compiled import kernels_folder
from particle_entropy.pipeline.verify import (
    CORRUPT_SUFFIX,
    CRATE_DIR,
    DIGESTS,
    TableError,
    folder_problems,
    numba_cache_folders,
    numba_cache_problem,
    set_aside_corrupt,
    tables_below,
)
from particle_entropy.pipeline.crate import (
    METADATA as CRATE_METADATA,
    crate_folder_problem,
    end_session,
    provenance,
    start_session,
)
from particle_entropy.pipeline.memory import available_bytes, estimate_mb
from particle_entropy.core.registry import ALL_KERNELS, METHODS, SCHEMES, SHEAR_CASES, TIME_GRIDS
from particle_entropy.core.settings import MAX_REALISATIONS, SHEAR
from particle_entropy.figures import BY_NAME as FIGURE, CASE_FIGURES, figure_options
from particle_entropy.figures import FIGURES as ALL_FIGURES
from particle_entropy.pipeline.sweeps import (
    CASE_DIR,
    FIGURE_DATA_PATTERN,
    RUN_PATTERN,
    SUMMARY_PATTERN,
    Ensemble,
    case_run_paths,
    figure_ensembles,
    lattice_cases,
    mechanism_ensembles,
    run_config,
    run_path,
    run_settings,
    spec_ensembles,
)

from particle_entropy.pipeline.crosschecks import check_memory, check_scene, check_sweeps, optimum_searches
from particle_entropy.experiments.scene import SCENE_RUN_PATTERN, SWEEP_PREFIX, scenes
from particle_entropy.pipeline.jobcost import estimated_seconds, shear_seconds
from particle_entropy.pipeline.memory import shear_memory_mb

check_sweeps(config)
# jobs run here: each must fit in this machine's memory (read once, for the sections and the searches)
AVAILABLE = available_bytes() if workflow.is_main_process and workflow.local_exec else None
if AVAILABLE is not None:
    check_memory(config, AVAILABLE)
# The adaptive COMIC searches (workflow/rules/optimum.smk), by name; each is checked when a
# requested target first needs it, so a config layered over config.yaml's searches runs.
OPTIMUM = optimum_searches(config, AVAILABLE)
# The scenes (workflow/rules/scenes.smk), by name, each checked when a requested target first needs
# it; their runs are keyed by a digest of their physics (scenes share equal runs: SCENES.settings).
SCENES = scenes(
    config,
    partial(check_scene, base_seed=config["base_seed"], available=AVAILABLE),
    paper=(RUN_PATTERN, partial(run_config, config=config)),  # the paper scene's runs are the paper's
)
# A scene's name: a user's (the schema's pattern) or one of the Peclet sweep's, peclet-<k>.
SCENE_NAME = rf"[A-Za-z0-9_]+|{SWEEP_PREFIX}[0-9]+"


def set_aside_corrupt_tables(root="results", look_only=False, digests=DIGESTS):
    """Tables whose bytes no longer match their checksum (truncated, a flipped bit, empty) are
    moved to <name>.corrupt before the DAG is built. The default target rebuilds every table set
    aside and not yet rebuilt, so a dry run in between loses nothing. ``look_only`` (a dry run):
    read no table and move none, only name those set aside before. ``digests``: each table's
    SHA-256 against its size, mtime, inode and ctime (verify.corrupt_tables), so a table is reread
    only when it changed; beside Snakemake's own state, not in results/, which may be copied
    elsewhere. Deleting it makes the next run read every table. Folders linked under ``root`` are
    followed (results/runs on another disk), each once (verify.tables_below)."""
    if not look_only:
        try:
            set_aside_corrupt(root, digests, named_columns, report=lambda line: print(line, file=sys.stderr))
        except TableError as e:  # a read-only results/: one line, and stop
            raise WorkflowError(str(e)) from None
    aside = tables_below(root, f".parquet{CORRUPT_SUFFIX}")
    missing = [str(p)[: -len(CORRUPT_SUFFIX)] for p in aside]
    return sorted(m for m in missing if not Path(m).exists())


NAMED_BY_PATH = [(re.compile(regex_from_filepattern(p)), p) for p in (RUN_PATTERN, SUMMARY_PATTERN)]


def named_columns(path):
    """The column values a run or summary table's path names (its case, and its block of seeds),
    or None for another table: verify.content_problem holds the table to them."""
    for regex, pattern in NAMED_BY_PATH:
        m = regex.match(Path(path).as_posix())
        if m:
            w = m.groupdict()
            named = Case.from_wildcards(w).columns()
            return named | ({"seed": (int(w["first"]), int(w["last"]))} if "first" in w else {})
    return None


def rebuildable(tables):
    """The set-aside ``tables`` that this workflow can write, each made a target. Snakemake
    does not rerun a job for a missing output when the output a target asked for exists (a
    figure's source data beside its PNG, a section's bootstrap table beside its COMIC table).
    A path of an older layout, which no rule writes, is left. Called once every rule is defined."""
    return [t for t in tables if any(r.is_producer(t) for r in workflow.rules)]


# Only the main Snakemake process checks: a job re-parsing this file on a cluster node must not
# judge tables that other jobs are writing at that moment. A run that will not hold the lock only
# looks, changing no file: a dry run, a command that runs no job (the run that follows checks the
# tables before it plans), and any run while a lock is held, which Snakemake then refuses (another
# run is writing these tables; a stale lock needs --unlock, which also only looks). Snakemake
# takes its lock after this file is read, so two runs started in the same instant may both check.
# Snakemake picks its action (a run, --unlock, --summary, --dag ...) only after reading this file:
# pipeline/invocation.py reads the command line again with Snakemake's own parser.
from particle_entropy.pipeline.invocation import runs_no_job, snakemake_options

DRY_RUN = bool(getattr(workflow.output_settings, "dryrun", False))  # from a profile too


def looks_only():
    """Whether this invocation must change no table (see above)."""
    locks = Path(".snakemake/locks")
    return DRY_RUN or runs_no_job(snakemake_options(sys.argv)) or (locks.is_dir() and any(locks.iterdir()))


def check_writable(look_only):
    """Stop in one line, before any job, where this run cannot write what it must: .snakemake/
    (every invocation: Snakemake keeps its state there), and for a run of jobs results/ and, run
    here before this code's kernels are compiled, numba's cache (verify.numba_cache_folders; a
    cluster node has its own). Else every job fails on a traceback or an empty log."""
    problems = folder_problems([".snakemake"] if look_only else [".snakemake", "results"])
    if not look_only and workflow.local_exec and not Path(kernels_folder()).is_dir():
        # numba's cache is written while the first job compiles the kernels of this code (compiled.take);
        # once they are, jobs load them and numba caches nothing
        problems += [p for p in [numba_cache_problem(numba_cache_folders(LIB))] if p]
    if problems:
        raise WorkflowError("\n".join(problems))


def hold_results():
    """Hold results/'s own lock for this run (pipeline/runlock.py): Snakemake's lock is per working
    directory, so two clones whose results/ link to one folder would both write there. A second
    run is refused in one line naming the first; a file system without locks is said, not fatal."""
    from particle_entropy.pipeline.runlock import FolderBusy, hold

    try:
        note = hold("results")
    except FolderBusy as e:
        raise WorkflowError(str(e)) from None
    if note:
        print(note, file=sys.stderr)


def crate_requested(options):
    """Whether the command line (``options``, snakemake_options) asks for the crate: its rule or a
    path in its folder; an unknown command line (the API) may."""
    if options is None:
        return True
    return any(t == "crate" or Path(t).as_posix().startswith(CRATE_DIR) for t in options.get("targets") or [])


def check_crate_folder():
    """Stop in one line, before any job, when the crate is asked for and cannot be written where
    it goes (crate.crate_folder_problem): a file there, or a link out of results/."""
    problem = crate_folder_problem(".") if crate_requested(snakemake_options(sys.argv)) else None
    if problem:
        raise WorkflowError(problem)


RUN_RECORDS = []  # the record of this run of jobs (Snakefile: onstart), ended on success or error
if workflow.is_main_process:
    check_writable(looks_only())
    check_crate_folder()
    if not looks_only():
        hold_results()
CORRUPT = set_aside_corrupt_tables(look_only=looks_only()) if workflow.is_main_process else []


def unmade_targets():
    """The requested targets (a target rule's inputs where it has no output) that are not there
    after a run; none to check under --until or --omit-from, which stop short of them on purpose."""
    dag = workflow.dag
    if dag.untilrules or dag.untilfiles or dag.omitrules or dag.omitfiles:
        return []
    files = {str(f) for job in dag.targetjobs for f in (job.output or job.input)}
    return sorted(f for f in files if not Path(f).exists())


def in_config(section):
    """Whether the config has ``section``, a dotted key (figures.fig3, tradeoff, shear)."""
    node = config
    for part in section.split("."):
        if not isinstance(node, dict) or part not in node:
            return False
        node = node[part]
    return True


# The figures of the default target whose section the config has (figures.FIGURES, the one list):
# those drawn from their cases by the shared plot rule (figures.smk), and the shear flow's.
PLOTTED = [f for f in CASE_FIGURES if in_config(FIGURE[f].section)]
SHEAR_FIGURE = [f.name for f in ALL_FIGURES if f.section == "shear" and in_config(f.section)]


wildcard_constraints:
    method="|".join(METHODS),
    kernel="|".join(ALL_KERNELS),
    scheme="|".join(SCHEMES),
    grid="|".join(TIME_GRIDS),
    n=r"\d+",
    eta=r"[0-9.eE+-]+",
    trunc=r"none|[0-9.eE+-]+",
    growth=r"[0-9.eE+-]+",
    first=r"\d+",
    last=r"\d+",
    nreal=r"\d+",
    kind="runs|snapshots",
    fig=r"fig\d+",


def all_targets():
    figs = [f"figures/{f}.{ext}" for f in PLOTTED + SHEAR_FIGURE for ext in ("png", "pdf")]
    if in_config("tradeoff"):
        figs.append("results/tables/tradeoff.parquet")
    return (
        rebuildable(CORRUPT)
        + figs
        + [
            "results/tables/comic.parquet",
            "results/tables/comic_minima.parquet",
            "results/tables/paper_claims.parquet",
            "results/paper_claims.md",
        ]
    )


def ensembles(section):
    """The ensembles of a figure (fig1 ... fig9), of `tradeoff` or of `mechanism`."""
    if section == "tradeoff":
        return spec_ensembles(config["tradeoff"], config) if "tradeoff" in config else []
    if section == "mechanism":
        return mechanism_ensembles(config)
    return figure_ensembles(config, section) if section in config["figures"] else []


def section_inputs(section):
    """What a figure reads, in the order of its cases: single runs, final states, the COMIC
    table or case summaries (figures.FIGURES)."""
    reads = FIGURE[section].reads
    base = config["base_seed"]
    if reads == "comic":  # the COMIC table, its minima and the bootstrap argmin shares
        return [f"results/tables/{section}/{t}.parquet" for t in ("comic", "comic_minima", "comic_argmin")]
    if reads == "tradeoff":
        return ["results/tables/tradeoff.parquet"]
    if reads in ("runs", "snapshots"):
        return [run_path(e.case, base, kind=reads) for e in ensembles(section)]
    return [e.summary_path() for e in ensembles(section)]


def section_cases(section):
    """The cases of a section as wildcard dicts (a plot rule's parameter)."""
    return [e.case.wildcards() for e in ensembles(section)]


MAX_TARGET_SEEDS = MAX_REALISATIONS  # seeds of one hand-written run table: more is a typo, not a job


def target_case(wildcards, pattern):
    """The case a (perhaps hand-written) table path names, checked: one line naming the pattern
    expected where it names none (eta~1e, n~1, seeds~5-2, r~0), never a traceback from a job."""
    try:
        case = Case.from_wildcards(wildcards)
        seeds = (int(wildcards.first), int(wildcards.last)) if "first" in wildcards.keys() else (0, 0)
        if "nreal" in wildcards.keys() and int(wildcards.nreal) < 1:
            raise ValueError(f"r~{wildcards.nreal}: an ensemble of at least 1 realisation")
        if not 0 <= seeds[0] <= seeds[1] or seeds[1] - seeds[0] >= MAX_TARGET_SEEDS:
            raise ValueError(f"seeds~{seeds[0]}-{seeds[1]}: first <= last, at most {MAX_TARGET_SEEDS:,} seeds")
        run_config(case, config)
    except (ValueError, SettingError) as e:
        example = pattern.format(**Case("mtpt", "collision", 1000).wildcards(), kind="runs", first=0, last=3, nreal=20)
        raise WorkflowError(f"a table path names no valid run ({e}); expected {pattern}, e.g. {example}") from None
    return case


def summary_runs(wildcards):
    """The run tables that one case summary averages."""
    target_case(wildcards, SUMMARY_PATTERN)
    return case_run_paths(Ensemble.from_wildcards(wildcards), config)


def summaries_of(*sections):
    return [e.summary_path() for s in sections for e in ensembles(s)]


def fd_report_times(count=20):
    """Times of the FD domain experiment: count even steps to t_final, on the FD time grid."""
    t_final, dt = float(config["physics"]["t_final"]), float(config["time"]["fd_dt"])
    return [round(k * t_final / count / dt) * dt for k in range(1, count + 1)]


def runs_of(*sections):
    """The run tables behind the ensembles of these sections (per-realisation values), each once."""
    return list(dict.fromkeys(p for s in sections for e in ensembles(s) for p in case_run_paths(e, config)))


def sim_mem_mb(wildcards):
    """Estimated peak memory of a job's runs (memory.py, fitted to measured peaks)."""
    seeds = int(wildcards.last) - int(wildcards.first) + 1
    return estimate_mb(run_config(target_case(wildcards, RUN_PATTERN), config), seeds)


def sim_priority(wildcards):
    """The job's estimated seconds (jobcost): Snakemake starts the longest simulations first."""
    seeds = int(wildcards.last) - int(wildcards.first) + 1
    return estimated_seconds(run_config(target_case(wildcards, RUN_PATTERN), config), seeds)


def sim_runtime_min(wildcards):
    seeds = int(wildcards.last) - int(wildcards.first) + 1
    return seeds * (2 if int(wildcards.n) <= 3000 else 10)


def sim_settings(wildcards):
    """Physics and numerics of a run (config.physics, config.time, config.numerics)."""
    return run_settings(target_case(wildcards, RUN_PATTERN), config)


# The code each task runs (its script, the library modules it uses and what they import), hashed:
# a rule reruns when, and only when, the content of its code changes (params rerun trigger).
SCRIPTS = Path(workflow.basedir) / "workflow" / "scripts"
SIM_CODE = {m: simulation_code(m, METHODS, SCRIPTS / "simulate.py") for m in METHODS}
SUMMARY_CODE = code_version(
    "analysis.aggregate", files=[Path(workflow.basedir) / "workflow" / "rules" / "summarise.smk"]
)
COMIC_CODE = code_version("analysis.aggregate", "core.io", "pipeline.htmlpage", files=[SCRIPTS / "comic_tables.py"])
TRADEOFF_CODE = code_version("analysis.aggregate", "core.io", files=[SCRIPTS / "tradeoff_table.py"])
CLAIMS_CODE = code_version("analysis.claims", "core.io", "pipeline.htmlpage", files=[SCRIPTS / "paper_claims.py"])

PLOT_CODE = {  # per figure, the module that draws it: editing one figure redraws it alone
    fig: code_version(f"figures.{fig}", "core.io", files=[SCRIPTS / "plot_figure.py"]) for fig in CASE_FIGURES
}
SHEAR_CODE = code_version(*SHEAR_ENTRIES, files=[SCRIPTS / "shear2d.py"])
SHEAR_PLOT_CODE = code_version("figures.fig10", "core.io", files=[SCRIPTS / "plot_fig10.py"])
MECHANISM_PLOT_CODE = code_version("figures.fig9_mechanism", "core.io", files=[SCRIPTS / "plot_fig9_mechanism.py"])
FD_DOMAIN_CODE = code_version("experiments.fd_domain", "core.io", files=[SCRIPTS / "fd_domain.py"])
LATTICE_CODE = code_version("experiments.lattice", "core.io", files=[SCRIPTS / "mechanism_floors.py"])
OPTIMUM_ROUND_CODE = code_version("analysis.optimum", "core.io", files=[SCRIPTS / "optimum_round.py"])
OPTIMUM_TABLE_CODE = code_version("analysis.optimum", "core.io", files=[SCRIPTS / "optimum_table.py"])
OPTIMUM_PLOT_CODE = code_version("figures.optimum", "core.io", files=[SCRIPTS / "plot_optimum.py"])
SCENE_ROUND_CODE = code_version("analysis.scene_search", "core.io", files=[SCRIPTS / "scene_round.py"])
SCENE_TABLE_CODE = code_version("analysis.scene_search", "core.io", files=[SCRIPTS / "scene_table.py"])
SCENE_PLOT_CODE = code_version(
    "figures.scene",
    "analysis.scene_search",
    "core.io",
    files=[SCRIPTS / "plot_scene.py", SCRIPTS / "plot_scenes_peclet.py"],
)
CRATE_CODE = code_version("pipeline.crate", files=[SCRIPTS / "crate.py"])


def coded_rules(rules):
    """The rules with a `code` parameter (their code hash, pipeline/codeversion.py): the crate
    reads each job's from Snakemake's record of its params (pipeline/crate.py)."""
    return sorted(r.name for r in rules if "code" in r.params.keys())


def beyond_default_target():
    """This config's targets outside the default one (its scenes and optimum searches, the
    mechanism figure): the crate describes those a run of this same config made."""
    by_name = {r.name: r for r in workflow.rules}
    found = [str(f) for name in ("scenes", "optimum") if name in by_name for f in by_name[name].input]
    if "plot_fig9_mechanism" in by_name:
        found += [str(f) for f in by_name["plot_fig9_mechanism"].output]
    return found


def figure_labels(figure, rule, data, drawn_by=None):
    """The report's labels of a figure: where it came from (pipeline/crate.provenance), worked out
    when the report is built; ``data`` is its source-data table's path pattern, ``drawn_by`` the
    figures module that draws it (default: the one named for it)."""
    path = f"workflow/lib/particle_entropy/figures/{drawn_by or figure}.py"
    return lambda w: provenance(figure.format(**w), rule, path, data.format(**w), config, workflow.basedir)
