"""Whether a Snakemake command line runs no job (a dry run, --unlock, --summary, --dag, ...).
Snakemake reads the Snakefile before it picks what to do: snakemake/cli.py ``args_to_api``
builds the workflow, whose first DAG action includes the Snakefile (snakemake/api.py
``DAGApi.__post_init__``), and only then chooses ``execute_workflow`` or one of the other
actions; during the parse no setting on the workflow tells them apart (only a dry run shows,
in ``workflow.output_settings``). So the command line is read again with Snakemake's own
parser (``snakemake.cli.get_argument_parser``), which resolves aliases (-S), unique prefixes
(--summ, --unl) and combined short flags (-pS) exactly as Snakemake did, and the action is
judged from the parsed options by their argparse names (dests). Which dests lead away from
``execute_workflow`` is Snakemake's if/elif chain in ``args_to_api``, which no API exposes:
``NO_JOB_OPTIONS`` copies it, and tests/test_invocation.py reads that function's source and
fails when a Snakemake release changes the chain. Snakemake is imported inside the function
only, so the library still imports without it. After a run, ``unmade_targets`` reads Snakemake's
DAG for the requested targets that are not there."""

from __future__ import annotations

import contextlib
import io
from collections.abc import Mapping, Sequence
from pathlib import Path

# The dests after which snakemake/cli.py args_to_api (Snakemake 9.27) calls something other
# than DAGApi.execute_workflow; --export-cwl is parsed but not dispatched there, so it runs.
NO_JOB_OPTIONS = frozenset(
    {
        *("deploy_sources", "lint", "list_target_rules", "list_rules", "print_compilation"),
        *("containerize", "report", "reporter", "generate_unit_tests", "dag", "rulegraph"),
        *("filegraph", "d3dag", "unlock", "cleanup_metadata", "conda_cleanup_envs"),
        *("conda_create_envs_only", "list_conda_envs", "cleanup_shadow", "container_cleanup_images"),
        *("list_changes", "list_input_changes", "list_params_changes", "list_untracked", "summary"),
        *("detailed_summary", "archive", "delete_all_output", "delete_temp_output"),
    }
)
# --report (or --reporter) with --report-after-run executes the workflow first, then reports.
REPORT_OPTIONS = frozenset({"report", "reporter"})


def runs_no_job(options: Mapping[str, object] | None) -> bool:
    """Whether Snakemake, given its parsed ``options`` (dest -> value, as ``snakemake_options``
    returns them), runs no job: an action other than executing the workflow, or a dry run.
    None (not a Snakemake command line) tells nothing: False."""
    if options is None:
        return False
    chosen = {dest for dest in NO_JOB_OPTIONS if options.get(dest) not in (None, False)}
    if options.get("report_after_run"):
        chosen -= REPORT_OPTIONS
    return bool(chosen) or bool(options.get("dryrun"))


def snakemake_options(argv: Sequence[str]) -> dict[str, object] | None:
    """``argv`` (``sys.argv``) parsed by Snakemake's own parser, by dest, when it is a
    Snakemake command line (the program ``snakemake`` or ``python -m snakemake``); None for
    another program (the Python API called from a script, pytest) or an argv that does not
    parse. A profile's options are not read: profiles set defaults (cores, resources), not
    actions, and a profile's dry run shows in ``workflow.output_settings``."""
    program = Path(argv[0]) if argv else Path()
    if not (program.stem == "snakemake" or (program.name == "__main__.py" and program.parent.name == "snakemake")):
        return None
    from snakemake.cli import get_argument_parser

    try:
        with contextlib.redirect_stderr(io.StringIO()):  # argparse's usage text on an error
            options, _ = get_argument_parser().parse_known_args(list(argv[1:]))
    except SystemExit:
        return None
    return vars(options)


def unmade_targets(dag) -> list[str]:
    """The requested targets (a target rule's inputs where it has no output) that are not there
    after a run, from Snakemake's ``dag`` (``workflow.dag``); none to check under --until or
    --omit-from, which stop short of them on purpose. Snakemake can end a run "100% done" with a
    target unmade (a rerun job with an ancient output hides the jobs after it)."""
    if dag.untilrules or dag.untilfiles or dag.omitrules or dag.omitfiles:
        return []
    files = {str(f) for job in dag.targetjobs for f in (job.output or job.input)}
    return sorted(f for f in files if not Path(f).exists())
