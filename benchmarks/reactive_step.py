"""How a reactive answer moves with the time step, per method, at fixed resolution (issue 50 point 8).

    python benchmarks/reactive_step.py [--mtpt-seeds 16] [--pt-seeds 8] [--only fd mtpt pt]
    python benchmarks/reactive_step.py --only mtpt --halvings 0 2 0 --n 0 4624 0   # another N

The scene is carried_reaction's physics (config.yaml; written out here so that the benchmark stays
put if the config moves): a Gaussian A (x0 0, sd 0.02) carried by v 0.5 with D 1e-4 to t_final 50
through a uniform B of 0.3, A + B -> C at k 2, target product_rmse 0.005. Each candidate runs at
one resolution and at its step halved (Scene.half_step: FD's Courant number halved; a particle's
dt0 and growth - 1 halved, which halves dt = dt0 + (g - 1) t at every time), and halved again
(--halvings per method, --n the resolutions):

- FD, TVD advection, Courant 0.75, 0.375, 0.1875, at n = 2048 (deterministic: one run each);
- MTPT, collision kernel, eta 1, at N = 2312: the default step, /2, /4 (--mtpt-seeds seeds each);
- PT, adaptive kernel, dt_growth 1.01 and halved, at N = 4000 (--pt-seeds seeds each).

Every step of a candidate runs the same seeds (base seed 0, 1, ...), so the change a halving makes is
measured paired, seed by seed. Measured on each run's last row (models/reactive_run.run_arrow,
judged against the scene's reference, experiments/reactive.compute): the signed product-mass error
mass_C / M_C,ref - 1 and the product's RMSE at the scene's points, sqrt(SSE_points_C / points).
Printed: per step, the mean of each over seeds with its 95 % t interval; per halving, the paired
mean change with its 95 % t interval and whether it exceeds the noise (the interval excludes 0).
Single process. About a minute of CPU (MTPT's 48 runs most of it).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "workflow" / "lib"))
from particle_entropy.experiments import reactive  # noqa: E402
from particle_entropy.experiments.scene import Scene  # noqa: E402
from particle_entropy.models import reactive_run  # noqa: E402

SPEC = {
    "D": 1.0e-4,
    "v": 0.5,
    "t_final": 50.0,
    "source": {"kind": "gaussian", "x0": 0.0, "sd": 0.02},
    "reaction": {"kind": "bimolecular", "k": 2.0, "B": {"uniform": 0.3}},
    "target": {"measure": "product_rmse", "value": 0.005},
    "max_realisations": 16,
    "candidates": [
        {"method": "fd", "kernel": "implicit", "advection": "tvd", "courant": 0.75, "n_range": [64, 16384]},
        {"method": "mtpt", "kernel": "collision", "eta": 1, "n_range": [30, 8000]},
        {"method": "pt", "kernel": "adaptive", "dt_growth": 1.01, "n_range": [300, 8000]},
    ],
}
RESOLUTION = {"fd": 2048, "mtpt": 2312, "pt": 4000}


@dataclass
class Level:
    """One step of a candidate: its label and the per-seed measures."""

    label: str
    steps: int
    product: np.ndarray  # mass_C / M_C,ref - 1
    rmse: np.ndarray  # sqrt(SSE_points_C / points)
    cpu: float


def interval(values: np.ndarray) -> tuple[float, float]:
    """Mean and the half-width of its 95 % t interval (nan with one value)."""
    values = np.asarray(values, dtype=np.float64)
    mean = float(values.mean())
    if values.size < 2:
        return mean, math.nan
    half = float(stats.t.ppf(0.975, values.size - 1) * values.std(ddof=1) / math.sqrt(values.size))
    return mean, half


def run_level(scene: Scene, cand, n: int, seeds: list[int], ref: dict) -> Level:
    """Every seed of one candidate at resolution n -> its measures."""
    product, rmse, cpu, steps = [], [], 0.0, 0
    points = len(ref["points"])
    for seed in seeds:
        cfg = scene.run_config(cand, n, seed=seed)
        start = time.process_time()
        table = reactive_run.run_arrow(cfg, scene.reaction, ref)
        last = table.slice(table.num_rows - 1).to_pylist()[0]
        cpu += time.process_time() - start
        steps = int(last["step"])
        product.append(last["mass_C"] / ref["product_mass"] - 1.0)
        rmse.append(math.sqrt(last["SSE_points_C"] / points))
    return Level("", steps, np.array(product), np.array(rmse), cpu)


def step_text(scene: Scene, cand, n: int) -> str:
    """The candidate's step as set: FD's Courant number, a particle's dt0 and growth."""
    if cand.case.method == "fd":
        return f"courant {cand.courant:g}"
    cfg = scene.run_config(cand, n)
    return f"dt0 {cfg.dt0:.4g} growth {cfg.dt_growth:.6g}"


def fmt(mean: float, half: float, scale: float = 100.0, digits: int = 2) -> str:
    """mean +- half in percent (scale 100) or as is."""
    body = f"{mean * scale:+.{digits}f}"
    return body if math.isnan(half) else f"{body} ± {half * scale:.{digits}f}"


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--mtpt-seeds", type=int, default=16)
    p.add_argument("--pt-seeds", type=int, default=8)
    p.add_argument("--halvings", type=int, nargs=3, default=(2, 2, 1), metavar=("FD", "MTPT", "PT"))
    p.add_argument("--n", type=int, nargs=3, default=None, metavar=("FD", "MTPT", "PT"), help="resolutions")
    p.add_argument("--only", nargs="*", choices=("fd", "mtpt", "pt"), default=("fd", "mtpt", "pt"))
    p.add_argument("--base-seed", type=int, default=0)
    args = p.parse_args(argv)

    scene = Scene.from_config("carried_reaction", SPEC)
    t0 = time.process_time()
    ref = reactive.compute(reactive.physics(scene))
    for key in ("points", "c_points"):
        ref[key] = np.asarray(ref[key], dtype=np.float64)
    print(f"reference: M_C = {ref['product_mass']:.6g} ({time.process_time() - t0:.1f} s CPU)", flush=True)
    halvings = dict(zip(("fd", "mtpt", "pt"), args.halvings))
    resolution = RESOLUTION if args.n is None else dict(zip(("fd", "mtpt", "pt"), args.n))
    n_seeds = {"fd": 1, "mtpt": args.mtpt_seeds, "pt": args.pt_seeds}

    head = f"{'method':6s} {'N':>5s} {'step':32s} {'steps':>6s} {'seeds':>5s}"
    print(f"\n{head} {'product error [%]':>18s} {'product_rmse [1e-3]':>20s} {'CPU s/run':>9s}")
    results = {}
    for cand in scene.candidates:
        method = cand.case.method
        if method not in args.only:
            continue
        n = resolution[method]
        seeds = [args.base_seed + i for i in range(n_seeds[method])]
        levels, c = [], cand
        for _ in range(halvings[method] + 1):
            level = run_level(scene, c, n, seeds, ref)
            level.label = step_text(scene, c, n)
            levels.append(level)
            print(
                f"{method:6s} {n:5d} {level.label:32s} {level.steps:6d} {len(seeds):5d}"
                f" {fmt(*interval(level.product)):>18s} {fmt(*interval(level.rmse), scale=1e3):>20s}"
                f" {level.cpu / len(seeds):9.2f}",
                flush=True,
            )
            c = scene.half_step(c)
        results[method] = levels

    print("\nPaired change per halving (finer - coarser, same seeds; 95 % t interval; * : beyond the noise)")
    print(f"{'method':6s} {'N':>5s} {'from -> to':28s} {'d product error [%]':>22s} {'d product_rmse [1e-3]':>24s}")
    for method, levels in results.items():
        for k, (lo, hi) in enumerate(zip(levels, levels[1:])):
            cells = []
            for attr, scale in (("product", 100.0), ("rmse", 1e3)):
                mean, half = interval(getattr(hi, attr) - getattr(lo, attr))
                beyond = "" if math.isnan(half) else ("*" if abs(mean) > half else " ")
                cells.append(fmt(mean, half, scale) + beyond)
            step = f"step/{2**k} -> step/{2 ** (k + 1)}"
            print(f"{method:6s} {resolution[method]:5d} {step:28s} {cells[0]:>22s} {cells[1]:>24s}")


if __name__ == "__main__":
    main()
