"""What a benchmark names its machine by: the CPU model (/proc/cpuinfo's, as `lscpu` shows it)."""

from __future__ import annotations

from pathlib import Path


def cpu() -> str:
    """The CPU's model name, or 'unknown' where /proc/cpuinfo does not give one."""
    for line in Path("/proc/cpuinfo").read_text().splitlines():
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return "unknown"
