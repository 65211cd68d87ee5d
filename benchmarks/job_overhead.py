"""Per-job overhead of a finished workflow run: job wall time minus time spent in steps.

    python benchmarks/job_overhead.py [WORKDIR]

Reads every simulate job's benchmark file (results/benchmarks/simulate/...tsv, written by Snakemake)
and its output table (results/runs/...parquet, wall_s per step) and prints the distribution
of (job wall time - simulation time): interpreter start-up, imports, JIT cache loading,
Snakemake's script preamble and the Parquet write.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd


def main() -> None:
    root = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    rows = []
    for tsv in sorted((root / "results" / "benchmarks" / "simulate").rglob("*.tsv")):
        rel = tsv.relative_to(root / "results" / "benchmarks" / "simulate").with_suffix(".parquet")
        table = root / "results" / "runs" / rel
        if not table.exists():
            continue
        job_s = float(pd.read_csv(tsv, sep="\t")["s"].iloc[0])
        t = pd.read_parquet(table, columns=["wall_s", "seed", "n"])
        rows.append(
            {
                "job": str(rel),
                "n": int(t["n"].iloc[0]),
                "seeds": t["seed"].nunique(),
                "job_s": job_s,
                "sim_s": float(t["wall_s"].sum()),
            }
        )
    df = pd.DataFrame(rows)
    df["overhead_s"] = df["job_s"] - df["sim_s"]
    print(f"{len(df)} simulate jobs, {df['seeds'].sum()} realisations")
    print(f"job wall time total {df['job_s'].sum():.1f} s, in steps {df['sim_s'].sum():.1f} s")
    q = np.percentile(df["overhead_s"], [10, 50, 90])
    print(f"overhead per job: median {q[1]:.2f} s (10%: {q[0]:.2f} s, 90%: {q[2]:.2f} s)")
    print(f"overhead per realisation (blocked seeds): {df['overhead_s'].sum() / df['seeds'].sum():.3f} s")


if __name__ == "__main__":
    main()
