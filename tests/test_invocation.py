"""Which Snakemake command lines run no job (invocation.py): every option that leads Snakemake's
dispatch (snakemake/cli.py args_to_api) away from executing the workflow, under each of its
names and abbreviations, and the runs and run modifiers that do not. The dispatch is read from
Snakemake's source, so a release that adds, renames or drops an action fails here."""

from __future__ import annotations

import ast
import inspect
import subprocess
import sys
import textwrap

import pytest
from conftest import ROOT
from snakemake import cli

from particle_entropy.pipeline.invocation import NO_JOB_OPTIONS, REPORT_OPTIONS, runs_no_job, snakemake_options

PARSER = cli.get_argument_parser()
ACTIONS = {action.dest: action for action in PARSER._actions}
VALUES = {"deploy_sources": ["query", "checksum"], "cleanup_metadata": ["a.parquet"], "list_changes": ["code"]}
VALUES |= {"archive": ["workflow.tar.gz"], "reporter": ["html"]}  # the other options take none or one optional


def runs_none(*args, program="snakemake"):
    return runs_no_job(snakemake_options([program, *args]))


def _dispatch():
    """What args_to_api tests before it falls through to DAGApi.execute_workflow: the
    ``args.<dest>`` names, and any other name, in the condition of each if/elif passed over."""
    tree = ast.parse(textwrap.dedent(inspect.getsource(cli.args_to_api)))
    parent = {child: node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call) and getattr(n.func, "attr", "") == "execute_workflow"]
    assert len(calls) == 1, "args_to_api no longer executes the workflow in one place: reread it"
    dests, names, node = set(), set(), calls[0]
    while node in parent:
        if isinstance(parent[node], ast.If) and node in parent[node].orelse:
            for n in ast.walk(parent[node].test):
                if isinstance(n, ast.Attribute) and getattr(n.value, "id", "") == "args":
                    dests.add(n.attr)
                elif isinstance(n, ast.Name) and n.id != "args":
                    names.add(n.id)
        node = parent[node]
    return tree, dests, names


def test_no_job_options_are_snakemakes_dispatch():
    """NO_JOB_OPTIONS is the chain of actions in args_to_api; its one condition on another
    name, the report plugin, comes from --report or --reporter, not with --report-after-run."""
    tree, dests, names = _dispatch()
    assert dests == (NO_JOB_OPTIONS - REPORT_OPTIONS) | {"report_after_run"}
    assert names == {"report_plugin"}
    assigned = {
        ast.unparse(n.test): {ast.unparse(t) for s in n.body if isinstance(s, ast.Assign) for t in s.targets}
        for n in ast.walk(tree)
        if isinstance(n, ast.If)
    }
    assert "args.reporter" in assigned["args.report"] and "report_plugin" in assigned["args.reporter"]


def test_every_name_of_every_no_job_option_runs_no_job():
    assert NO_JOB_OPTIONS <= set(ACTIONS)
    for dest in sorted(NO_JOB_OPTIONS):
        for option in ACTIONS[dest].option_strings:
            assert runs_none(option, *VALUES.get(dest, [])), option


@pytest.mark.parametrize(
    "args",
    [
        ["--unl"],  # unique prefixes, which argparse accepts and a list of spellings missed
        ["--summ"],
        ["--delete-all"],
        ["--list-u"],
        ["-pS"],  # short flags joined
        ["-pn"],
        ["--dry-r"],
        ["--report=out.html"],
        ["--dag=mermaid-js"],
        ["--reporter", "html"],
        ["--list-conda-envs"],
        ["-s", "Snakefile", "-d", "work", "-j2", "--unlock", "--configfile", "config.yaml"],
    ],
    ids=str,
)
def test_runs_no_job(args):
    assert runs_none(*args)


@pytest.mark.parametrize(
    "args",
    [
        [],
        ["-j2"],
        ["-s", "Snakefile", "-d", "work", "-j2", "--configfile", "config.yaml"],
        ["--keep-incomplete"],  # modifiers of a run, listed among Snakemake's utilities
        ["--keep-inc"],
        ["--skip-script-cleanup"],
        ["--drop-metadata"],
        ["--report", "out.html", "--report-after-run"],  # runs, then reports
        ["--touch"],  # executes under the lock, touching outputs
        ["--export-cwl", "workflow.cwl"],  # parsed, but args_to_api (9.27) does not dispatch it: a run
        ["--cores", "2", "results/tables/comic.parquet"],
        ["--config", "physics={D: 0.002}"],
        ["--cores", "2", "--", "-S"],  # after --, a target named -S, for Snakemake too
    ],
    ids=str,
)
def test_runs_jobs(args):
    assert not runs_none(*args)


def test_only_a_snakemake_command_line_is_read(capsys):
    main = "/venv/lib/python3.11/site-packages/snakemake/__main__.py"  # python -m snakemake
    assert runs_none("--summ", program=main) and runs_none("--summ", program="/venv/bin/snakemake")
    assert snakemake_options(["pytest", "-S"]) is None and not runs_none("-S", program="pytest")
    assert snakemake_options([]) is None and runs_no_job(None) is False
    assert snakemake_options(["snakemake", "--lc"]) is None  # does not parse: Snakemake stops before the Snakefile
    assert capsys.readouterr().err == ""


def test_the_workflow_reads_its_command_line(tmp_path):
    """common.smk, end to end: an abbreviated --summary leaves a corrupt table in place, a run
    (here of a target no rule makes, so no job) sets it aside while Snakemake reads the Snakefile."""
    table = tmp_path / "results" / "tables" / "x.parquet"
    table.parent.mkdir(parents=True)
    table.write_bytes(b"not a table")
    table.with_name("x.parquet.sha256").write_text(f"{'0' * 64}  x.parquet\n")
    cmd = [sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "-d", str(tmp_path), "-j1"]
    config = ["--configfile", str(ROOT / "tests" / "data" / "tiny_config.yaml")]  # last: it takes every word
    summary = subprocess.run([*cmd, "--summ", *config], capture_output=True, text=True)
    assert summary.returncode == 0, summary.stderr[-2000:]
    assert table.exists() and "corrupt table" not in summary.stderr
    run = subprocess.run([*cmd, "no-such-target.txt", *config], capture_output=True, text=True)
    assert "corrupt table results/tables/x.parquet" in run.stderr and not table.exists()


def test_unmade_targets_are_the_requested_files_not_there(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from particle_entropy.pipeline.invocation import unmade_targets

    monkeypatch.chdir(tmp_path)
    (tmp_path / "made.png").write_text("x")
    jobs = [SimpleNamespace(output=[], input=["made.png", "missing.png"]), SimpleNamespace(output=["gone.pdf"])]
    dag = SimpleNamespace(untilrules=set(), untilfiles=set(), omitrules=set(), omitfiles=set(), targetjobs=jobs)
    assert unmade_targets(dag) == ["gone.pdf", "missing.png"]
    dag.untilrules = {"simulate"}  # --until stops short of the targets on purpose
    assert unmade_targets(dag) == []
