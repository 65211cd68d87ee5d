"""A failed job's error is shown (joblogs.py and the Snakefile's onerror hook), although Snakemake's
report stops at the job's first empty log. The run logs are written by Snakemake's own formatter,
or by Snakemake itself, so a release that changes their wording fails here."""

from __future__ import annotations

import logging
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT, SNAKEFILE
from snakemake.logging import DefaultFormatter
from snakemake_interface_logger_plugins.common import LogEvent

from particle_entropy.pipeline.joblogs import listed_and_shown, tail, unshown_job_logs

ERROR = "srun: job made to fail on purpose"
JOB_LOG = "logs/compile_kernels/abc.log"
SLURM_LOG = ".snakemake/slurm_logs/rule_compile_kernels/17.log"


def job_error(logs, indent=False):
    """A failed job's entry in the run log, as Snakemake 9 writes it (show-failed-logs on)."""
    extra = dict(rule_name="compile_kernels", rule_msg=None, jobid=3, input=[], output=["results/kernels/abc"])
    extra |= dict(log=logs, conda_env=None, container_img=None, aux={}, indent=indent, shellcmd=None)
    return record(LogEvent.JOB_ERROR, "Error in rule compile_kernels, jobid: 3", **extra)


def group_error(aux_logs, member_logs):
    """A failed group job's entry: SLURM's log first, then each member's (each member's own entry follows)."""
    members = [dict(rule_name="simulate", jobid=i, output=[f"r{i}"], log=[log]) for i, log in enumerate(member_logs)]
    extra = dict(groupid="sims", aux_logs=aux_logs, job_error_info=members)
    entries = [record(LogEvent.GROUP_ERROR, "Error in group sims", **extra)]
    return "\n".join([*entries, *(job_error([log], indent=True) for log in member_logs)])


def record(event, message, **extra):
    rec = logging.LogRecord("snakemake", logging.ERROR, __file__, 0, message, None, None)
    rec.__dict__.update(extra, event=event)
    return DefaultFormatter(show_failed_logs=True).format(rec)


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name, text in ((JOB_LOG, ""), (SLURM_LOG, f"some start-up line\n{ERROR} (exit 3)\n")):
        Path(name).parent.mkdir(parents=True, exist_ok=True)
        Path(name).write_text(text)
    return tmp_path


def write_run_log(text):
    path = Path(".snakemake/log/2026-12-03T170000.snakemake.log")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"Building DAG of jobs...\n{text}\nShutting down, this might take some time.\n")
    return str(path.resolve())


def test_a_submitted_jobs_error_after_its_empty_log_is_shown(workdir):
    report = job_error([JOB_LOG, SLURM_LOG])  # a SLURM executor: the job's own log, then SLURM's
    run_log = write_run_log(report)
    shown = "\n".join(unshown_job_logs([run_log]))  # `log` of an onerror hook: a list of paths
    assert (report + shown).count(ERROR) == 1
    assert shown.startswith(f"Logfile {SLURM_LOG} (not shown above):")
    assert unshown_job_logs(run_log) == unshown_job_logs([run_log])


def test_what_snakemake_showed_is_not_shown_again(workdir):
    Path(JOB_LOG).write_text("Traceback: the job's own error\n")  # a log with content does not stop the report
    report = job_error([JOB_LOG, SLURM_LOG])
    assert unshown_job_logs(write_run_log(report)) == []
    group = group_error([SLURM_LOG], ["logs/simulate/a.log", "logs/simulate/b.log"])
    listed, shown = listed_and_shown(group)
    assert listed == [SLURM_LOG, "logs/simulate/a.log", "logs/simulate/b.log"]
    assert set(listed) == shown  # the group's SLURM log first, then each member's own entry
    assert unshown_job_logs(write_run_log(group)) == []


def test_missing_empty_and_unreadable_logs_are_passed_over(workdir):
    report = job_error(["logs/missing.log", JOB_LOG, "logs/gone.log", SLURM_LOG])
    Path(SLURM_LOG).write_text("")
    assert unshown_job_logs(write_run_log(report)) == []
    assert unshown_job_logs(["no/such/run.log"]) == []
    assert unshown_job_logs([]) == []


def test_a_long_log_is_shown_by_its_end(tmp_path):
    path = tmp_path / "long.log"
    path.write_text("".join(f"line {i}\n" for i in range(10_000)))
    lines, cut = tail(path, lines=3)
    assert (lines, cut) == (["line 9997", "line 9998", "line 9999"], True)
    assert tail(path, lines=3, max_bytes=20) == (["line 9998", "line 9999"], True)  # whole lines
    assert tail(path, lines=3, max_bytes=15) == (["line 9999"], True)  # a cut first line is dropped
    assert tail(tmp_path / "long.log", lines=20_000)[0][0] != "line 0"  # at most max_bytes read
    (tmp_path / "short.log").write_bytes(b"ok\n\xff end\n")
    assert tail(tmp_path / "short.log") == (["ok", "\ufffd end"], False)


def test_the_workflows_onerror_hook_shows_a_failed_jobs_error(tmp_path):
    """A job whose first log is empty fails: Snakemake's report stops there, and the Snakefile's own
    onerror hook (copied into a one-rule workflow) prints the error from the job's second log."""
    text = SNAKEFILE.read_text()
    start = text.index("\nonerror:\n")
    hook = [text[start:].splitlines()[1]]
    hook += [line for line in text[start:].splitlines()[2:] if not line or line.startswith(" ")]
    (tmp_path / "Snakefile").write_text(
        f"import sys\nsys.path.insert(0, {str(ROOT / 'workflow' / 'lib')!r})\n"
        "RUN_RECORDS = []  # what the hook takes from common.smk: no run record to end here\n\n"
        "rule fail:\n    output: 'x'\n    log: 'a.log', 'b.log'\n"
        f"    shell: 'touch {{log[0]}}; echo {ERROR} >{{log[1]}}; exit 3'\n\n" + "\n".join(hook) + "\n"
    )
    run = subprocess.run(
        [sys.executable, "-m", "snakemake", "-j1", "--show-failed-logs", "-d", str(tmp_path)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
    )
    assert run.returncode != 0
    header = "Logfile b.log (not shown above):"
    rule = "=" * max(len(header), len(ERROR))
    assert "Logfile a.log: empty file\n" in run.stderr
    assert f"\n{header}\n{rule}\n{ERROR}\n{rule}\n" in run.stderr
