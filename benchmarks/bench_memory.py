"""Peak memory of whole CLI runs against memory.estimate_bytes (the estimate the CLI checks).

    python benchmarks/bench_memory.py            # ~2 min: a step sweep and an N sweep per method

Each run is a fresh `python -m particle_entropy simulate` process; its peak RSS comes from
os.wait4, so it is that process's alone. The estimate should lie above every measurement.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile

from particle_entropy.core.runconfig import RunConfig
from particle_entropy.core.timegrid import step_count
from particle_entropy.pipeline.memory import estimate_bytes

RUNS = [  # (method, kernel, n, t_final, dt0, dt_growth)
    ("fd", "implicit", 100, 1000.0, 0.01, 1.0),
    ("fd", "implicit", 100, 1000.0, 0.002, 1.0),
    ("pt", "bins", 100, 1000.0, 0.002, 1.0),
    ("fd", "implicit", 1_000_000, 10.0, 0.05, 1.0),
    ("pt", "bins", 1_000_000, 10.0, None, None),
    ("mtpt", "collision", 300_000, 10.0, None, None),
    ("mtpt", "sph", 300_000, 10.0, None, None),
]


def peak_rss(args: list[str]) -> int:
    """Peak resident set size of one child process, in bytes (Linux reports kB)."""
    proc = subprocess.Popen([sys.executable, "-m", "particle_entropy", "simulate", *args, "--quiet"])
    _, status, usage = os.wait4(proc.pid, 0)
    if status != 0:
        raise SystemExit(f"run failed: {args}")
    return usage.ru_maxrss * 1024


def main() -> None:
    print(f"{'method':6} {'kernel':9} {'N':>9} {'steps':>8} {'peak MB':>8} {'estimate MB':>11}")
    with tempfile.TemporaryDirectory() as tmp:
        for method, kernel, n, t_final, dt0, growth in RUNS:
            cfg = RunConfig.of(method=method, kernel=kernel, n=n, t_final=t_final, dt0=dt0, dt_growth=growth).resolved()
            args = ["--method", method, "--kernel", kernel, "--n", str(n), "--t-final", str(t_final)]
            args += ["--dt0", str(cfg.dt0), "--dt-growth", str(cfg.dt_growth), "--out", f"{tmp}/x.parquet"]
            steps = step_count(t_final, cfg.dt0, cfg.dt_growth)
            peak = peak_rss(args)
            est = estimate_bytes(cfg)
            flag = "" if est >= peak else "  UNDER-ESTIMATE"
            print(f"{method:6} {kernel:9} {n:>9,} {steps:>8,} {peak / 1e6:>8.0f} {est / 1e6:>11.0f}{flag}")


if __name__ == "__main__":
    main()
