"""One step of the 2-D FD model (models/fd2d.py) on one core, by both of its solves side by side:
issue 52 point 7 asks for at most 60 ms a step at 1,024 x 1,024 nodes.

    python benchmarks/fd2d_step.py [NODES ...]        # default 256 512 1024 (nodes per side)
    python benchmarks/fd2d_step.py --iterations [NODES] # Krylov iterations over dt D / dx^2 and Courant

Each (size, scheme, method) runs in its own process, so that its peak RSS (getrusage's ru_maxrss)
is its own, with OMP, OpenBLAS and MKL held to one thread. A Gaussian (sd 0.08) under the tensor of
a flow at 30 degrees (D_L 1e-4, D_T 2e-5, |v| 1) on [0, 1]^2 at Courant 0.5: the solver is built
(for "lu" the sparse matrix and its LU, the factorisation timed apart; for "krylov" the stencil and
BiCGSTAB's vectors), one step is taken to warm up (and compile), then the median of 5 steps is
reported (wall time, and the process's CPU time: on a machine others load, the wall time grows and
the CPU time much less) with the Krylov iterations of the last, tvd's explicit advection (x then y
sweeps and their balance) timed apart as well. Run it on an idle machine: the load average is
printed before and after.
"""

from __future__ import annotations

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
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
METHODS = ("lu", "krylov")
TARGET_MS = 60.0
REPEATS = 5
THETA = math.pi / 6


def _flow(d_long: float = 1e-4, d_trans: float = 2e-5, speed: float = 1.0):
    """(D, v) of a flow at 30 degrees: the tensor R diag(D_L, D_T) R^T [L^2/T] and v [L/T]."""
    rot = np.array([[math.cos(THETA), -math.sin(THETA)], [math.sin(THETA), math.cos(THETA)]])
    return rot @ np.diag([d_long, d_trans]) @ rot.T, speed * rot[:, 0]


def _start(grid: fd2d.Grid) -> np.ndarray:
    """The Gaussian (sd 0.08) about (0.45, 0.45) on the interior [1/L^2]."""
    x, y = grid.interior()
    return np.exp(-((x - 0.45) ** 2 + (y - 0.45) ** 2) / (2 * 0.08**2)) / (2 * math.pi * 0.08**2)


def one(nodes: int, scheme: str, method: str) -> dict:
    """Build, warm up and time one (size, scheme, method) -> its measurements."""
    d, v = _flow()
    n = nodes - 1  # intervals: nodes per side n + 1
    grid = fd2d.Grid(0.0, 0.0, 1.0 / n, 1.0 / n, n, n)
    dt = fd2d.step_for_courant(0.5, v, grid.dx, grid.dy)
    c = _start(grid)
    t0 = time.perf_counter()
    solver = fd2d.solver(d, v, grid, dt, scheme, method)
    build = time.perf_counter() - t0
    c = solver.solve(c)  # warm-up (and the compiled kernels' first call)
    steps, cpus, advects = [], [], []
    for _ in range(REPEATS):
        t0, p0 = time.perf_counter(), time.process_time()
        c = solver.solve(c)
        steps.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - p0)
        if scheme == "tvd":
            t0 = time.perf_counter()
            solver.advect(c)
            advects.append(time.perf_counter() - t0)
    return {
        "nodes": nodes,
        "scheme": scheme,
        "method": solver.method,
        "unknowns": (n - 1) ** 2,
        "setup_s": build,
        "factor_s": solver.factorisation_seconds,
        "step_ms": 1e3 * statistics.median(steps),
        "cpu_ms": 1e3 * statistics.median(cpus),
        "advect_ms": 1e3 * statistics.median(advects) if advects else float("nan"),
        "iterations": solver.iterations if solver.method == "krylov" else 0,
        "fallbacks": solver.fallbacks,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
    }


def iterations(nodes: int) -> None:
    """BiCGSTAB's iterations to 1e-13 (cap 400, no LU) over dt D / dx^2 and the Courant number."""
    n = nodes - 1
    grid = fd2d.Grid(0.0, 0.0, 1.0 / n, 1.0 / n, n, n)
    c = _start(grid)
    print(f"{nodes} x {nodes} nodes, flow at 30 degrees, D_T = D_L / 5; BiCGSTAB iterations (cap 400)")
    print(f"{'dt D_L/dx^2':>11} {'courant':>7} " + " ".join(f"{s:>8}" for s in SCHEMES))
    for r in (0.1, 1.0, 10.0, 100.0, 1e3):
        for courant in (0.1, 0.5, 1.0):
            dt = 1e-3  # any: D and v set r and the Courant number
            d, v = _flow(r * grid.dx**2 / dt, 0.2 * r * grid.dx**2 / dt, courant * grid.dx / dt / math.cos(THETA))
            counts = []
            for scheme in SCHEMES:
                solver = fd2d.solver(d, v, grid, dt, scheme, "krylov", max_iterations=400)
                solver.solve(c)
                counts.append(f"{solver.iterations:>8}" if not solver.fallbacks else f"{'> 400':>8}")
            print(f"{r:>11g} {courant:>7g} " + " ".join(counts), flush=True)


def _load() -> str:
    """The 1-minute load average."""
    return f"{os.getloadavg()[0]:.2f}"


def main(sizes: list[int]) -> None:
    print(f"CPU: {cpu()}; one thread (OMP/OpenBLAS/MKL/numba = 1); median of {REPEATS} steps after a warm-up")
    print(f"load average (1 min) before: {_load()}")
    head = (("nodes", 11), ("scheme", 8), ("method", 7), ("setup s", 8), ("factor s", 8), ("step ms", 8))
    head += (("cpu ms", 7), ("advect ms", 9), ("iters", 5), ("peak MB", 8))
    print(" ".join(f"{name:>{width}}" for name, width in head))
    rows = []
    for nodes in sizes:
        for scheme in SCHEMES:
            for method in METHODS:
                command = [sys.executable, __file__, "--one", str(nodes), scheme, method]
                out = subprocess.run(command, capture_output=True, text=True, check=True)
                row = json.loads(out.stdout.strip().splitlines()[-1])
                rows.append(row)
                print(
                    f"{nodes:>5} x {nodes:<5}{scheme:>8} {row['method']:>7} {row['setup_s']:>8.2f} "
                    f"{row['factor_s']:>8.2f} {row['step_ms']:>8.1f} {row['cpu_ms']:>7.1f} {row['advect_ms']:>9.1f} "
                    f"{row['iterations']:>5} {row['peak_rss_mb']:>8.0f}",
                    flush=True,
                )
    print(f"load average (1 min) after: {_load()}")
    for r in (r for r in rows if r["nodes"] == 1024):
        verdict = "met" if r["step_ms"] <= TARGET_MS else f"missed by {r['step_ms'] / TARGET_MS:.1f}x"
        print(f"1024 x 1024, {r['scheme']}, {r['method']}: {r['step_ms']:.0f} ms a step, target {verdict}")


if __name__ == "__main__":
    if sys.argv[1:2] == ["--one"]:
        print(json.dumps(one(int(sys.argv[2]), sys.argv[3], sys.argv[4])))
    elif sys.argv[1:2] == ["--iterations"]:
        iterations(int(sys.argv[2]) if len(sys.argv) > 2 else 512)
    else:
        main([int(a) for a in sys.argv[1:]] or [256, 512, 1024])
