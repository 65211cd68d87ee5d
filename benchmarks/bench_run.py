"""Benchmark whole runs: wall time, time per step and peak memory of one simulation.

    python benchmarks/bench_run.py --method mtpt --kernel collision --n 30000
    python benchmarks/bench_run.py --n 10000 30000 --truncation 3 --scheme sequential   # the authors' loop

Runs in a fresh process per configuration so that peak RSS belongs to that run alone.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time

CHILD = """
import json, resource, sys, time
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models.simulate import run
from particle_entropy.numerics.gauss import gauss_transform
import numpy as np
gauss_transform(np.zeros(2), np.zeros(2), np.ones(2), 1.0, method='direct')  # JIT/cache load
gauss_transform(np.zeros(2), np.zeros(2), np.ones(2), 1.0, method='taylor')
cfg = RunConfig.of(**json.loads(sys.argv[1]))
t0 = time.perf_counter()
table, _ = run(cfg)
wall = time.perf_counter() - t0
print(json.dumps({
    "wall_s": wall,
    "steps": int(table["step"].max()),
    "median_step_ms": 1e3 * float(table["wall_s"].iloc[1:].median()),
    "max_step_ms": 1e3 * float(table["wall_s"].iloc[1:].max()),
    "max_substeps": int(table["substeps"].max()),
    "steps_split": int((table["substeps"] > 1).sum()),
    "mass_error": float((table["mass_total"] - 1).abs().max()),
    "H_C_error_final": float(table["H_C"].iloc[-1] - table["H_C_analytic"].iloc[-1]),
    "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
}))
"""


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--method", default="mtpt")
    p.add_argument("--kernel", default="collision")
    p.add_argument("--n", type=int, nargs="+", default=[30000])
    p.add_argument("--eta", type=float, default=1.0)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--truncation", type=float, default=None, help="kernel widths (default: whole Gaussian)")
    p.add_argument("--scheme", default="symmetric")
    a = p.parse_args()
    for n in a.n:
        cfg = {"method": a.method, "kernel": a.kernel, "n": n, "eta": a.eta, "seed": a.seed}
        if a.method == "mtpt":
            cfg.update(truncation=a.truncation, scheme=a.scheme)
        t0 = time.perf_counter()
        out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(cfg)], capture_output=True, text=True, check=True)
        res = json.loads(out.stdout.strip().splitlines()[-1])
        res["process_s"] = time.perf_counter() - t0
        print(json.dumps({**cfg, **res}))


if __name__ == "__main__":
    main()
