"""Calibrate the scenes' cost model: seconds a time step and seconds a unit of work, per method
(settings.SCENE's `cost`, or `scenes.<name>.cost`), fitted to runs timed here.

    python benchmarks/calibrate_scene_costs.py [--config config.yaml] [--max-s 2] [SCENE ...]

For each candidate of each scene (all of the config's, Peclet sweep included, or those named), up
to four rungs of its ladder spread from its low end to the highest rung whose counted cost under
the current model is below --max-s run once each (seed base_seed) in this process, as a
simulation job would, and are timed by the sum of their steps' wall times (job start-up excluded,
as the run tables' `wall_s`). Per method a non-negative least-squares fit (scipy.optimize.nnls)
of the measured seconds on [steps, work] gives the two unit costs; the fit is weighted by
1/seconds so that cheap and dear runs count alike (a relative error). Printed: the YAML to paste
as `cost:` (or into settings.SCENE's default) and, per method, the median and worst ratio of
measured to fitted seconds. Time with nothing else running; quote the CPU (`lscpu`).
"""

from __future__ import annotations

import argparse
import statistics
from collections import defaultdict
from dataclasses import replace

import numpy as np
from scipy.optimize import nnls

from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.models.simulate import run_seeds_arrow
from particle_entropy.pipeline.configcheck import load_yaml
from particle_entropy.scenes.scene import scenes

RUNGS = 4  # rungs timed per candidate


def rungs(scene, cand, max_s: float) -> list[int]:
    """Up to RUNGS rungs of a candidate's ladder, spread from its low end to the highest rung whose
    counted cost under the current model is at most ``max_s`` [s]."""
    ladder = [n for n in cand.ladder() if scene.run_cost(cand, n) <= max_s]
    return sorted({ladder[round(k * (len(ladder) - 1) / (RUNGS - 1))] for k in range(RUNGS)}) if ladder else []


def timed_points(config: dict, names: list[str], max_s: float) -> dict[str, list[tuple[float, float, float, str]]]:
    """Per method, (steps, work, measured s, what) of the runs timed."""
    out: dict[str, list] = defaultdict(list)
    seen = set()
    table_of = scenes(config)
    for name in names or list(table_of):
        scene = table_of[name]
        for cand in scene.candidates:
            for n in rungs(scene, cand, max_s):
                # the transport's cost: a reactive scene's run without its reaction (reactive_cost.py prices that)
                cfg = replace(scene.run_config(cand, n, seed=int(config.get("base_seed", 0))), reaction=None)
                key = (cfg.method, cfg.kernel, n, cfg.t_final, cfg.dt0, cfg.v != 0.0, cand.advection)
                if key in seen:
                    continue
                seen.add(key)
                table = run_seeds_arrow(cfg, [cfg.seed]).to_pandas()
                last = table.loc[table["step"].idxmax()]
                seconds = float(table["wall_s"].sum())
                what = f"{name}: {cand.label} n={n}"
                out[cfg.method].append((float(last["step"]), float(last["work"]), seconds, what))
                counts = f"steps {int(last['step']):>7,}  work {last['work']:>13,.0f}"
                print(f"{what:60s} {counts}  {seconds:8.3f} s", flush=True)
    return out


def fit(points: list[tuple[float, float, float, str]]) -> tuple[float, float, list[float]]:
    """(seconds a step, seconds a unit of work, measured / fitted per run), relative least squares."""
    a = np.array([[s, w] for s, w, _, _ in points])
    y = np.array([t for _, _, t, _ in points])
    weight = 1.0 / np.maximum(y, 1e-6)
    (per_step, per_work), _ = nnls(a * weight[:, None], y * weight)
    fitted = a @ np.array([per_step, per_work])
    return float(per_step), float(per_work), list(y / np.maximum(fitted, 1e-12))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="config.yaml")
    ap.add_argument("--max-s", type=float, default=2.0, help="skip rungs counted dearer than this [s]")
    ap.add_argument("scenes", nargs="*", help="scene names (default: every scene of the config)")
    args = ap.parse_args()
    keep_freed_pages()
    points = timed_points(load_yaml(args.config), args.scenes, args.max_s)
    lines = []
    for method in sorted(points):
        per_step, per_work, ratios = fit(points[method])
        worst = max(ratios, key=lambda r: abs(np.log(r)))
        print(
            f"{method}: {len(ratios)} runs; measured / fitted: median {statistics.median(ratios):.2f}, "
            f"worst {worst:.2f}"
        )
        lines.append(f"  {method}: [{per_step:.2e}, {per_work:.2e}]")
    print("cost:")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
