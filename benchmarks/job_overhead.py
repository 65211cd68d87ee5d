"""Per-job fixed cost of a finished workflow run: job wall time minus the time spent in steps.

    python benchmarks/job_overhead.py [WORKDIR]

Reads every simulate job's benchmark file (results/benchmarks/simulate/<kind>/<case>/seeds~A-B.tsv,
written by Snakemake; kind = runs or snapshots) and the run table of the same case and seeds
(results/runs/<case>/seeds~A-B.parquet, wall_s per step: a snapshots job runs the same steps,
its table holds final states), and prints the median, 10 % and 90 % of (job wall time - time in
steps) over all jobs and per method: interpreter start-up, imports, loading compiled kernels,
Snakemake's script preamble and the Parquet write. A snapshots job whose run table is absent is
left out.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq


def jobs(root: Path) -> list[dict]:
    """One row per simulate job: kind, method, seeds, job wall time and time in steps [s]."""
    bench = root / "results" / "benchmarks" / "simulate"
    rows = []
    for tsv in sorted(bench.rglob("*.tsv")):
        rel = tsv.relative_to(bench)
        kind, case = rel.parts[0], Path(*rel.parts[1:]).with_suffix(".parquet")
        table = root / "results" / "runs" / case
        if not table.exists():
            continue
        with tsv.open() as f:
            job_s = float(next(csv.DictReader(f, delimiter="\t"))["s"])
        t = pq.read_table(table, columns=["wall_s", "seed"])
        rows.append(
            {
                "job": str(rel),
                "kind": kind,
                "method": case.parts[0],
                "seeds": len(set(t.column("seed").to_pylist())),
                "job_s": job_s,
                "sim_s": float(np.sum(t.column("wall_s").to_numpy())),
            }
        )
    return rows


def summary(label: str, overhead: list[float]) -> str:
    q = np.percentile(overhead, [10, 50, 90])
    return f"{label:<8} {len(overhead):>5} jobs  median {q[1]:.2f} s  (10%: {q[0]:.2f} s, 90%: {q[2]:.2f} s)"


def main() -> None:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    rows = jobs(root)
    if not rows:
        raise SystemExit(f"no simulate job with a benchmark file and a run table under {root / 'results'}")
    for r in rows:
        r["overhead_s"] = r["job_s"] - r["sim_s"]
    print(f"{len(rows)} simulate jobs, {sum(r['seeds'] for r in rows)} realisations")
    print(f"job wall time total {sum(r['job_s'] for r in rows):.1f} s, in steps {sum(r['sim_s'] for r in rows):.1f} s")
    print("fixed cost a job (job wall - time in steps):")
    print(summary("all", [r["overhead_s"] for r in rows]))
    for method in sorted({r["method"] for r in rows}):
        print(summary(method, [r["overhead_s"] for r in rows if r["method"] == method]))
    per_seed = sum(r["overhead_s"] for r in rows) / sum(r["seeds"] for r in rows)
    print(f"fixed cost a realisation (blocked seeds): {per_seed:.3f} s")


if __name__ == "__main__":
    main()
