"""One step of the 2-D FD model (models/fd2d.py) on one core: issue 52 point 7 asks for at most 60 ms
a step at 1,024 x 1,024 nodes.

    python benchmarks/fd2d_step.py [NODES ...]      # default 256 512 1024 (nodes per side)

Each (size, scheme) runs in its own process, so that its peak RSS (getrusage's ru_maxrss) is its own,
with OMP, OpenBLAS and MKL held to one thread. A Gaussian (sd 0.08) under the tensor of a flow at 30
degrees (D_L 1e-4, D_T 2e-5, |v| 1) on [0, 1]^2 at Courant 0.5: the solver is built (the matrix and
its sparse LU, timed apart), one step is taken to warm up, then the median of 5 steps is reported,
tvd's explicit advection (x then y sweeps and their balance) timed apart as well.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_name] = "1"

import json  # noqa: E402
import math  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

LIB = Path(__file__).resolve().parents[1] / "workflow" / "lib"
sys.path.insert(0, str(LIB))
from machine import cpu  # noqa: E402

from particle_entropy.models import fd2d  # noqa: E402

SCHEMES = ("upwind", "central", "tvd")
TARGET_MS = 60.0
REPEATS = 5


def one(nodes: int, scheme: str) -> dict:
    """Build, warm up and time one (size, scheme) -> its measurements."""
    theta = math.pi / 6
    rot = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    d, v = rot @ np.diag([1e-4, 2e-5]) @ rot.T, rot[:, 0]
    n = nodes - 1  # intervals: nodes per side n + 1
    grid = fd2d.Grid(0.0, 0.0, 1.0 / n, 1.0 / n, n, n)
    dt = fd2d.step_for_courant(0.5, v, grid.dx, grid.dy)
    x, y = grid.interior()
    c = np.exp(-((x - 0.45) ** 2 + (y - 0.45) ** 2) / (2 * 0.08**2)) / (2 * math.pi * 0.08**2)
    del x, y
    t0 = time.perf_counter()
    solver = fd2d.solver(d, v, grid, dt, scheme)
    build = time.perf_counter() - t0
    lu = solver.factorisation_seconds
    c = solver.solve(c)  # warm-up (and the compiled tvd kernel's first call)
    steps, advects = [], []
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        c = solver.solve(c)
        steps.append(time.perf_counter() - t0)
        if scheme == "tvd":
            t0 = time.perf_counter()
            solver.advect(c)
            advects.append(time.perf_counter() - t0)
    return {
        "nodes": nodes,
        "scheme": scheme,
        "unknowns": (n - 1) ** 2,
        "assemble_s": build - lu,
        "factor_s": lu,
        "step_ms": 1e3 * statistics.median(steps),
        "advect_ms": 1e3 * statistics.median(advects) if advects else float("nan"),
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def main(sizes: list[int]) -> None:
    print(f"CPU: {cpu()}; one thread (OMP/OpenBLAS/MKL = 1); median of {REPEATS} steps after a warm-up")
    head = ("nodes", 11), ("scheme", 8), ("assemble s", 10), ("factor s", 9), ("step ms", 9), ("advect ms", 9)
    print(" ".join(f"{name:>{width}}" for name, width in head), f"{'peak MB':>8}")
    rows = []
    for nodes in sizes:
        for scheme in SCHEMES:
            out = subprocess.run(
                [sys.executable, __file__, "--one", str(nodes), scheme], capture_output=True, text=True, check=True
            )
            row = json.loads(out.stdout.strip().splitlines()[-1])
            rows.append(row)
            print(
                f"{nodes:>5} x {nodes:<5}{scheme:>8} {row['assemble_s']:>10.2f} {row['factor_s']:>9.2f} "
                f"{row['step_ms']:>9.1f} {row['advect_ms']:>9.1f} {row['peak_rss_mb']:>8.0f}",
                flush=True,
            )
    big = [r for r in rows if r["nodes"] == 1024]
    for r in big:
        verdict = "met" if r["step_ms"] <= TARGET_MS else f"missed by {r['step_ms'] / TARGET_MS:.1f}x"
        print(f"1024 x 1024, {r['scheme']}: {r['step_ms']:.0f} ms a step, target {TARGET_MS:.0f} ms {verdict}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--one"]:
        print(json.dumps(one(int(sys.argv[2]), sys.argv[3])))
    else:
        main([int(a) for a in sys.argv[1:]] or [256, 512, 1024])
