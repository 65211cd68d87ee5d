"""Where a finished workflow run spent its time, per rule family, from Snakemake's benchmark files.

    python benchmarks/rule_budget.py [WORKDIR]          # a Markdown table for the README

Every rule that starts a process has a ``benchmark:`` file under results/benchmarks/<rule>/...
(Snakemake writes wall seconds ``s`` and ``cpu_time``, user + system seconds of the job's
processes). Simulation jobs are split by model: the authors' loop (scheme sequential*), the other
MTPT, PT and FD. Rules that run inside the Snakemake process (summarise_case) have no file; the
difference between the run's wall time on two cores and half the core-seconds listed is theirs,
Snakemake's own scheduling and the set-aside scan.
"""

from __future__ import annotations

import csv
import sys
from collections import defaultdict
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.core.registry import SCHEME_RECORDS  # noqa: E402


def family(rel: Path) -> str:
    """Rule family of a benchmark file, from its path below results/benchmarks."""
    parts = rel.parts
    if parts[0] != "simulate":
        return parts[0]
    # simulate/<kind>/<method>/<kernel>/n~/eta~/trunc~/growth~/scheme~<scheme>/seeds~...
    method = parts[2]
    scheme = next((p.split("~", 1)[1] for p in parts if p.startswith("scheme~")), "")
    if method == "mtpt" and scheme in SCHEME_RECORDS and SCHEME_RECORDS[scheme].sequential:
        return "simulate: authors' loop"
    return f"simulate: {method}"


def read(tsv: Path) -> tuple[float, float]:
    """(wall s, cpu s) of one benchmark file (the mean over its rows, if repeated)."""
    with tsv.open() as f:
        rows = list(csv.DictReader(f, delimiter="\t"))
    wall = sum(float(r["s"]) for r in rows) / len(rows)
    cpu = sum(float(r.get("cpu_time") or 0.0) for r in rows) / len(rows)
    return wall, cpu


def budget(root: Path) -> dict[str, list[float]]:
    out: dict[str, list[float]] = defaultdict(lambda: [0, 0.0, 0.0])
    base = root / "results" / "benchmarks"
    for tsv in sorted(base.rglob("*.tsv")):
        wall, cpu = read(tsv)
        row = out[family(tsv.relative_to(base))]
        row[0] += 1
        row[1] += wall
        row[2] += cpu
    return dict(out)


def main() -> None:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    rows = sorted(budget(root).items(), key=lambda kv: -kv[1][1])
    if not rows:
        raise SystemExit(f"no benchmark files under {root / 'results' / 'benchmarks'}: run the workflow first")
    total_wall = sum(r[1] for _, r in rows)
    print("| rule family | jobs | wall s | cpu s | wall s per job | share of wall |")
    print("| --- | ---: | ---: | ---: | ---: | ---: |")
    for name, (jobs, wall, cpu) in rows:
        print(f"| {name} | {jobs} | {wall:.1f} | {cpu:.1f} | {wall / jobs:.2f} | {100 * wall / total_wall:.0f} % |")
    jobs = sum(r[0] for _, r in rows)
    cpu = sum(r[2] for _, r in rows)
    print(f"| **all** | {jobs} | {total_wall:.1f} | {cpu:.1f} | {total_wall / jobs:.2f} | 100 % |")


if __name__ == "__main__":
    main()
