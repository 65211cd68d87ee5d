"""Wall time of a small simulate job, whole process, today's library against another checkout's.

    python benchmarks/bench_startup.py [--other PATH] [--repeats 7]

A job here is what workflow/scripts/simulate.py does, without Snakemake's own preamble (about
0.2 s, the same for both): start Python, import what the job imports, run a 5-step case of
N = 30 for one seed and write its Parquet table. Cases: the authors' loop (mtpt, sph, truncation
3, sequential), the symmetric MTPT (collision), PT (bins) and FD. ``--other`` points to another
checkout (e.g. a git worktree of an earlier commit) whose library is timed alternately with this
one; numba's cache is warm for both (one untimed run each first). Prints medians, and
``python -X importtime`` totals of the job's imports.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]
CASES = {
    "authors' loop": "method='mtpt', kernel='sph', truncation=3.0, scheme='sequential'",
    "mtpt symmetric": "method='mtpt', kernel='collision'",
    "pt bins": "method='pt', kernel='bins'",
    "fd": "method='fd', kernel='implicit'",
}
JOB = """
import sys
from particle_entropy.core.case import Case
from particle_entropy.core.io import write_parquet
from particle_entropy.core.runconfig import RunConfig
try:
    from particle_entropy.models.simulate import run_seeds_arrow as run_seeds
except ImportError:  # an earlier checkout
    from particle_entropy.models.simulate import run_seeds
cfg = getattr(RunConfig, "of", RunConfig)({case}, n=30, t_final=0.0551, dt0=0.01, seed=0).resolved()
write_parquet(run_seeds(cfg, range(1)), sys.argv[1])
"""


def job(lib: Path, case: str, out: Path, importtime: bool = False) -> float:
    env = {**os.environ, "PYTHONPATH": str(lib)}
    args = [sys.executable] + (["-X", "importtime"] if importtime else []) + ["-c", JOB.format(case=case), str(out)]
    t0 = time.perf_counter()
    res = subprocess.run(args, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if res.returncode != 0:
        raise SystemExit(f"job failed under {lib}:\n{res.stderr[-2000:]}")
    if importtime:
        top = [line for line in res.stderr.splitlines() if line.startswith("import time:") and "|" in line]
        total = sum(int(line.split("|")[0].split(":")[1]) for line in top[1:])  # self times, microseconds
        return total / 1e6
    return wall


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--other", type=Path, help="another checkout to time alongside (its workflow/lib)")
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    libs = {"this": HERE / "workflow" / "lib"}
    if args.other:
        libs["other"] = args.other.resolve() / "workflow" / "lib"
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "job.parquet"
        print(f"{'case':<16}" + "".join(f" {name + ' wall s':>14} {name + ' import s':>15}" for name in libs))
        for label, case in CASES.items():
            for lib in libs.values():
                job(lib, case, out)  # numba's cache filled or loaded, untimed
            walls = {name: [] for name in libs}
            for _ in range(args.repeats):
                for name, lib in libs.items():
                    walls[name].append(job(lib, case, out))
            imports = {name: job(lib, case, out, importtime=True) for name, lib in libs.items()}
            print(f"{label:<16}" + "".join(f" {statistics.median(walls[n]):>14.2f} {imports[n]:>15.2f}" for n in libs))


if __name__ == "__main__":
    main()
