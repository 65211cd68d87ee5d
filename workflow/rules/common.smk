# The workflow's table of contents: the library on the path, the config checked, the main process's
# checks before any job (the one place that may move files while the Snakefile is read), the names
# the rule files share, the wildcards and the default target. The logic is the library's
# (workflow/lib/particle_entropy/pipeline/); each rule file holds its feature's rules, and each rule
# passes its code hash as codeversion.script_code reads it from the rule's script.
import sys
from functools import partial
from pathlib import Path

from snakemake.exceptions import WorkflowError
from snakemake.utils import validate

LIB = str(Path(workflow.basedir) / "workflow" / "lib")
sys.path.insert(0, LIB)
from particle_entropy.pipeline.codeversion import export_library_path

export_library_path(LIB)  # jobs import this checkout's library in any software environment
from particle_entropy.analysis.rounds import read_path
from particle_entropy.core.registry import ALL_KERNELS, METHODS, SCHEMES, SHEAR_CASES, TIME_GRIDS
from particle_entropy.core.settings import SHEAR
from particle_entropy.scenes.reference import REFERENCE_PATTERN, path as reactive_reference_path
from particle_entropy.scenes.scene import SCENE_RUN_PATTERN, SWEEP_NAME, has_sweep, scenes
from particle_entropy.figures import BY_NAME as FIGURE, figure_options
from particle_entropy.pipeline import inputs
from particle_entropy.pipeline.codeversion import script_code, simulation_code
from particle_entropy.pipeline.configcheck import check_parsed_config
from particle_entropy.pipeline.crate import METADATA as CRATE_METADATA, end_session, start_session
from particle_entropy.pipeline.crosschecks import check_scene, optimum_searches
from particle_entropy.pipeline.invocation import unmade_targets
from particle_entropy.pipeline.jobcost import shear_seconds
from particle_entropy.pipeline.memory import available_bytes, shear_memory_mb
from particle_entropy.pipeline.preflight import preflight
from particle_entropy.pipeline.sweeps import (
    CASE_DIR,
    FIGURE_DATA_PATTERN,
    RUN_PATTERN,
    SUMMARY_PATTERN,
    lattice_cases,
    run_config,
    run_path,
    run_settings,
)
from particle_entropy.pipeline.verify import CRATE_DIR

# jobs run here: each must fit in this machine's memory (read once, for the sections and the searches)
AVAILABLE = available_bytes() if workflow.is_main_process and workflow.local_exec else None
# The merged config (config.yaml, --configfile, --config) checked and its defaults filled in, each
# problem in one short message naming its key path (pipeline/configcheck.check_parsed_config).
# CONFIG: the same config parsed once, typed (pipeline/config.py), which the planning reads; the
# mapping `config` stays what rule params that Snakemake records read as written.
SCHEMA = Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"
CONFIG = check_parsed_config(config, workflow.config_settings.config, SCHEMA, validate, AVAILABLE)
# The adaptive COMIC searches (workflow/rules/optimum.smk), by name; each is checked when a
# requested target first needs it, so a config layered over config.yaml's searches runs.
OPTIMUM = optimum_searches(config, AVAILABLE)
# The scenes (workflow/rules/scenes.smk), by name, each checked when a requested target first needs
# it; their runs are keyed by a digest of their physics (scenes share equal runs: SCENES.settings).
SCENES = scenes(
    config,
    partial(check_scene, base_seed=CONFIG.base_seed, available=AVAILABLE),
    paper=(RUN_PATTERN, partial(run_config, config=config)),  # the paper scene's runs are the paper's
)
# A scene's name: a user's (the schema's pattern) or one of a Peclet sweep's, peclet-<k> or peclet2d-<k>.
SCENE_NAME = rf"[A-Za-z0-9_]+|{SWEEP_NAME}"

# Before any job, the main process stops in one line where the run cannot write, holds results/'s
# own lock and sets corrupt tables aside; a dry run, a command that runs no job and a run that a
# held lock will refuse only look (pipeline/preflight.py, the one call that may move files while
# the Snakefile is read). CORRUPT: the tables set aside and not yet rebuilt (all_targets).
DRY_RUN = bool(getattr(workflow.output_settings, "dryrun", False))  # from a profile too
CORRUPT = preflight(DRY_RUN, sys.argv, workflow.local_exec, LIB, WorkflowError) if workflow.is_main_process else []
RUN_RECORDS = []  # the record of this run of jobs (Snakefile: onstart), ended on success or error

INPUTS = inputs.Inputs(config, WorkflowError, CONFIG)  # the rules' input, params and resources functions
PLOTTED = inputs.plotted_figures(CONFIG)  # the figures that the shared plot rule draws (figures.smk)
figure_labels = partial(inputs.figure_labels, config=config, checkout=workflow.basedir)  # report labels
SCRIPTS = Path(workflow.basedir) / "workflow" / "scripts"  # a rule's code: script_code(SCRIPTS / its script)


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
    """The default target (inputs.default_targets) after the set-aside tables that a rule here
    writes: Snakemake does not rerun a job for a missing output when the output a target asked
    for exists (a figure's source data beside its PNG, a section's bootstrap table beside its
    COMIC table). A path of an older layout, which no rule writes, is left, and so are scene
    references (only the scenes target knows whose they are). Called once every rule is defined."""
    references = Path(REFERENCE_PATTERN).parent.as_posix()  # the scenes target's (scene_files_set_aside)
    rebuilt = [t for t in CORRUPT if not t.startswith(references) and any(r.is_producer(t) for r in workflow.rules)]
    return rebuilt + inputs.default_targets(CONFIG)


def scene_files_set_aside(wildcards=None):
    """The files of this config's scenes set aside and not yet rebuilt (CORRUPT): their tables,
    plans, runs and references, and the Peclet sweep's data. The `scenes` target makes them, for
    the reason all_targets gives; files of scenes no longer configured are left. Evaluated only
    when `scenes` is planned, and each scene built only when one of its files is set aside."""
    aside = [t for t in CORRUPT if t.startswith("results/scenes")]
    if not aside:
        return []
    scenes = [SCENES[name] for name in SCENES]
    ids = {scene.identity(c) for scene in scenes for c in scene.candidates}
    references = {reactive_reference_path(scene) for scene in scenes if scene.reaction is not None}
    sweep = ["results/scenes_peclet.parquet"] if has_sweep(config) else []

    def ours(path):
        parts = Path(path).parts  # results, scenes, <name>.parquet | <name> | <run digest>, ...
        return (
            path in references
            or path in sweep
            or (len(parts) > 2 and parts[2].removesuffix(".parquet") in {*SCENES, *ids})
        )

    return [t for t in aside if ours(t)]


# summarise.smk's text is the summaries' code (a run: block, no script): it names these two, so
# that what moves here reruns no summary
summary_runs = INPUTS.summary_runs
SUMMARY_CODE = script_code(Path(workflow.basedir) / "workflow" / "rules" / "summarise.smk")
