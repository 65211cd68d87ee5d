"""FD in a flow, old against new side by side in one process on the same states: the tridiagonal
solve by LAPACK's dgttrs against the compiled sweeps that flush subnormal results
(numerics/thomas.gt_solve), and tvd's advection step in numpy (advect_tvd_numpy) against its
compiled twin (numerics/thomas.tvd_advect).

    python benchmarks/fd_solvers.py [N ...]      # default 4096 16384 65536

The carried scene's implicit upwind and central candidates (D 1e-4, v 1, fd_dt 0.01): each N is
stepped 300 steps from its source, then both solves are timed on that state (best of 5 of 50
calls), and their results compared (the largest difference, and whether every value above 2^53
times the smallest normal is equal).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from scipy.linalg import lapack  # noqa: E402

from particle_entropy.models import fd  # noqa: E402
from particle_entropy.numerics.compiled import kernels  # noqa: E402
from particle_entropy.numerics.thomas import SMALLEST_NORMAL  # noqa: E402
from particle_entropy.scenes.scene import Scene  # noqa: E402


def best(fn, calls: int = 50, repeats: int = 5) -> float:
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            fn()
        times.append((time.perf_counter() - t0) / calls)
    return min(times)


def main(sizes: list[int]) -> None:
    import platform

    print(f"python {platform.python_version()}, {platform.processor() or platform.machine()}")
    for scheme in ("upwind", "central"):
        spec = {
            "D": 1e-4,
            "v": 1.0,
            "t_final": 100.0,
            "target": {"value": 0.1},
            "candidates": [
                {"method": "fd", "kernel": "implicit", "advection": scheme, "fd_dt": 0.01, "n_range": [64, 65536]}
            ],
        }
        scene = Scene.from_config("bench", spec)
        for n in sizes:
            cfg = scene.run_config(scene.candidates[0], n)
            x, dx = fd.grid(cfg)
            c = fd.initial_concentration(cfg)
            solver = fd.solver(cfg, cfg.dt0, dx)
            for _ in range(300):
                c[1:-1] = solver.solve(c[1:-1])
            b = c[1:-1].copy()
            f = solver._factors[:5]
            old = best(lambda f=f, b=b: lapack.dgttrs(*f, b))
            new = best(lambda f=f, b=b: kernels().gt_solve(*f, b))
            want, got = lapack.dgttrs(*f, b)[0], kernels().gt_solve(*f, b)
            big = np.abs(want) >= SMALLEST_NORMAL * 2.0**53
            same = got[big].tobytes() == want[big].tobytes()
            print(
                f"{scheme:7s} N={n:6d}: dgttrs {old * 1e3:.3f} ms, gt_solve {new * 1e3:.3f} ms, ratio {old / new:.2f}; "
                f"max |diff| {np.abs(got - want).max():.3g}, equal above 2^-969: {same}"
            )

    for n in sizes:  # tvd at Courant 0.75 on a Gaussian: the same bits, one pass
        x = np.linspace(-1.0, 1.0, n)
        c = np.exp(-(x**2) / 0.01)
        old = best(lambda c=c: fd.advect_tvd_numpy(c, 0.75))
        new = best(lambda c=c: fd.advect_tvd(c, 0.75))
        same = fd.advect_tvd(c, 0.75)[0].tobytes() == fd.advect_tvd_numpy(c, 0.75)[0].tobytes()
        print(
            f"tvd     N={n:6d}: numpy {old * 1e3:.3f} ms, compiled {new * 1e3:.3f} ms, ratio {old / new:.1f}; "
            f"same bits: {same}"
        )


if __name__ == "__main__":
    main([int(a) for a in sys.argv[1:]] or [4096, 16384, 65536])
