"""A box source's FD runs against their counted cost, before and after box_entropy's rule was built once.

    python benchmarks/box_cost.py [--config config.yaml] [--scene spill] [--n 64 256 1024] [--repeat 3]

Runs the scene's first FD candidate (``spill``: a box [-0.5, 0.5], D 1e-3, v 5e-3, t_final 200,
fd_dt 0.5) and its Gaussian twin (the same scene with a Gaussian source of the box's variance), each
in a fresh process as a simulation job runs, once as this checkout computes it ("new") and once with
the reference of main at 77a862f patched in ("old": box_entropy's Gauss-Legendre rule rebuilt every
call, box_mean's two forms by masks, no warm-up of scipy.special or LAPACK). Measured is a run's
``core_s``, the sum of its steps' wall_s (job start-up excluded); counted is Scene.run_cost under the
default `cost` constants. Printed per source, n and version: the least measured seconds of
--repeat runs, the median step, and measured / counted. Time with nothing else running and quote
the CPU (`lscpu`).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys

CHILD = """
import json, sys
import box_cost
print(json.dumps(box_cost.child(*json.loads(sys.argv[1]))))
"""


def _old_reference():
    """box_entropy, box_mean and the warm-ups of main at 77a862f."""
    import functools

    import numpy as np

    from particle_entropy.core import sources as S
    from particle_entropy.models import fd

    @functools.lru_cache(maxsize=256)
    def box_entropy(width: float, dt: float) -> float:
        if not width > 0:
            raise ValueError(f"box width must be > 0, got {width!r}")
        if dt <= 0:
            return math.log(width)
        s = math.sqrt(4.0 * dt)
        half = 0.5 * width
        start = max(0.0, half - 12.0 * s)
        flat = start * math.log(width) / width
        end = half + 12.0 * s
        panels = math.ceil(4.0 * (end - start) / s)
        nodes, weights = np.polynomial.legendre.leggauss(16)
        edges = np.linspace(start, end, panels + 1)
        mid, rad = 0.5 * (edges[1:] + edges[:-1]), 0.5 * (edges[1:] - edges[:-1])
        x = (mid[:, None] + rad[:, None] * nodes[None, :]).ravel()
        w = (rad[:, None] * weights[None, :]).ravel()
        c = box_mean(x / s, half / s) / s
        safe = np.where(c > 0, c, 1.0)
        return float(2.0 * (flat + np.dot(w, -c * np.log(safe))))

    def box_mean(u, h):
        from scipy.special import erf, erfc

        u = np.asarray(u, dtype=np.float64)
        h = float(h)
        a = np.abs(u)
        narrow = (4.0 * a * h < 0.05) & (h < 0.1)
        out = np.empty_like(u)
        if narrow.any():
            nodes, weights = np.polynomial.legendre.leggauss(5)
            z = a[narrow][..., None] + h * nodes
            out[narrow] = (0.5 / math.sqrt(math.pi)) * (np.exp(-z * z) @ weights)
        side = ~narrow & (a >= h)
        if side.any():
            out[side] = (erfc(a[side] - h) - erfc(a[side] + h)) / (4.0 * h)
        straddle = ~narrow & (a < h)
        if straddle.any():
            out[straddle] = (erf(a[straddle] + h) + erf(h - a[straddle])) / (4.0 * h)
        return out

    def fd_warm_up(cfg) -> None:
        fd.ImplicitSolver(8, 0.1).solve(np.ones(8))

    S.box_entropy, S.box_mean, S.Box.warm_up, fd.warm_up = box_entropy, box_mean, lambda self: None, fd_warm_up


def _scene(config: str, name: str, source: str):
    from dataclasses import replace

    from particle_entropy.core.sources import Source
    from particle_entropy.pipeline.configcheck import load_yaml
    from particle_entropy.scenes.scene import scenes

    scene = scenes(load_yaml(config))[name]
    if source == "gaussian":  # the twin: a Gaussian of the box's variance
        scene = replace(
            scene, source=Source.of("gaussian", x0=scene.source.centre, sd=math.sqrt(scene.source.variance))
        )
    return scene, next(c for c in scene.candidates if c.case.method == "fd")


def child(config: str, name: str, source: str, n: int, version: str) -> dict:
    """One run in this process: its measured seconds (sum of wall_s), median step and counted cost."""
    if version == "old":
        _old_reference()
    from particle_entropy.models.simulate import run_seeds_arrow

    scene, cand = _scene(config, name, source)
    wall = run_seeds_arrow(scene.run_config(cand, n), [0]).column("wall_s").to_pylist()
    return {
        "measured": sum(wall),
        "median": statistics.median(wall),
        "steps": len(wall) - 1,
        "counted": scene.run_cost(cand, n),
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="config.yaml")
    ap.add_argument("--scene", default="spill", help="a scene with a box source and an FD candidate")
    ap.add_argument("--n", type=int, nargs="+", default=[64, 256, 1024])
    ap.add_argument("--repeat", type=int, default=3, help="runs of each (the least is kept)")
    args = ap.parse_args()
    here = sys.path[0]
    print(
        f"{'source':9s} {'n':>5s} {'steps':>5s} {'counted s':>9s} | {'version':7s} {'measured s':>10s} "
        f"{'step us':>8s} {'measured/counted':>16s}"
    )
    for source in ("box", "gaussian"):
        for n in args.n:
            for version in ("old", "new"):
                runs = []
                for _ in range(args.repeat):
                    arg = json.dumps([args.config, args.scene, source, n, version])
                    out = subprocess.run(
                        [sys.executable, "-c", CHILD, arg],
                        capture_output=True,
                        text=True,
                        env={**os.environ, "PYTHONPATH": here},
                        check=True,
                    )
                    runs.append(json.loads(out.stdout.strip().splitlines()[-1]))
                best = min(runs, key=lambda r: r["measured"])
                print(
                    f"{source:9s} {n:5d} {best['steps']:5d} {best['counted']:9.4f} | {version:7s} "
                    f"{best['measured']:10.4f} {best['median'] * 1e6:8.1f} {best['measured'] / best['counted']:16.2f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
