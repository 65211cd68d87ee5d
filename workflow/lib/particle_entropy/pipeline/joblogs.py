"""The logs of failed jobs that Snakemake's error report lists but does not show.

With ``show-failed-logs`` (both workflow profiles), Snakemake prints the logs it lists under each
failed job, but it stops at the first one that is missing or empty (``show_logs`` in
snakemake/logging.py, 9.27: ``return`` where ``continue`` was meant). For a job submitted on its
own, a SLURM executor lists the job's log first and SLURM's log of the job second. A job that
fails before its script writes a line (srun or Python cannot start on the node, or the job is
killed for memory or time) leaves its own log missing or empty. The report then ends on
"Logfile logs/...: empty file", and the error, which is in SLURM's log, is never shown. A group
job lists SLURM's log first, so a failing simulation group did show it.

The workflow's ``onerror`` hook (Snakefile) reads the run's log (.snakemake/log/) and prints,
for each log listed under a failed job that the report did not show, its last lines. A log that
Snakemake did show is left out, so nothing is printed twice if a release fixes ``show_logs``.
Only the main process imports this module: editing it reruns no rule.
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterable
from pathlib import Path

PathLike = str | os.PathLike
TAIL_LINES = 80  # lines of each log shown: the error is at its end; a SLURM log of one job is about 50
TAIL_BYTES = 64 * 1024  # at most this much of a log is read

# "    log: a.log, b.log (check log file(s) for error details)": the logs of a failed job or group
# (snakemake/logging.py DefaultFormatter._format_job_error and _format_group_error)
_LISTED = re.compile(r"^\s*log: (.+) \(check log file\(s\) for error details\)\s*$")
# what show_logs writes of each log it reaches: a header, "...: empty file", "... not found." or
# "... is not a text file." (a missing or empty one also ends show_logs)
_SHOWN = re.compile(r"^\s*Logfile (.+?)(?::| not found\.| is not a text file\.)(?: empty file)?\s*$")


def listed_and_shown(run_log: str) -> tuple[list[str], set[str]]:
    """The logs listed under failed jobs in a Snakemake run log (each once, in order) and those
    whose content, emptiness or absence the report showed."""
    listed: dict[str, None] = {}
    shown: set[str] = set()
    for line in run_log.splitlines():
        if m := _LISTED.match(line):
            listed.update(dict.fromkeys(p.strip() for p in m.group(1).split(", ") if p.strip()))
        elif m := _SHOWN.match(line):
            shown.add(m.group(1))
    return list(listed), shown


def tail(path: PathLike, lines: int = TAIL_LINES, max_bytes: int = TAIL_BYTES) -> tuple[list[str], bool]:
    """The last ``lines`` lines of a text file (from its last ``max_bytes`` bytes, undecodable
    bytes replaced) and whether any were left out."""
    with open(path, "rb") as f:
        size = f.seek(0, os.SEEK_END)
        start = max(0, size - max_bytes)
        f.seek(max(0, start - 1))  # with the byte before: is the first line read whole?
        data = f.read()
    if start:
        data = data[data.index(b"\n") + 1 :] if b"\n" in data else b""
    out = data.decode("utf-8", errors="replace").splitlines()
    return out[-lines:], bool(start) or len(out) > lines


def unshown_job_logs(run_logs: PathLike | Iterable[PathLike], root: PathLike = ".") -> list[str]:
    """Lines to print after a failed run: each non-empty log listed under a failed job in the run
    log(s) ``run_logs`` (Snakemake's ``log`` of an onerror hook) whose content the report did not
    show, with a header; its relative path read below ``root`` (the working directory)."""
    if isinstance(run_logs, str | os.PathLike):
        run_logs = [run_logs]
    out = []
    for run_log in run_logs:
        try:
            text = Path(run_log).read_text(errors="replace")
        except OSError:
            continue
        listed, shown = listed_and_shown(text)
        for name in listed:
            if name in shown:
                continue
            path = Path(root, name)
            try:
                if path.stat().st_size == 0:
                    continue
                lines, cut = tail(path)
            except OSError:
                continue
            header = f"Logfile {name} (not shown above{', its last lines' if cut else ''}):"
            rule = "=" * min(max([len(header), *map(len, lines)]), 80)
            out += [header, rule, *lines, rule]
    return out
