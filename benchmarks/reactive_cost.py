"""What a reactive scene's run costs against what the scenes' cost model counts for it, per method.

    python benchmarks/reactive_cost.py [--config config.yaml] [--max-s 2] [--repeat 3] [SCENE ...]

For each candidate of each reactive scene of the config (those with `reaction:`, or the scenes
named), the rungs calibrate_scene_costs.py would time (its ``rungs``: up to four, spread from the
ladder's low end to the highest rung counted at most --max-s) run at seed base_seed in this
process, as the jobs run them, side by side and interleaved --repeat times: the conservative run
of the rung's RunConfig (models/simulate.py, rule simulate_scene) and the reactive run of the same
RunConfig with the scene's reaction (models/simulate.py, rule simulate_scene, judged
against the scene's reference, read from results/scenes/references/ or computed once here), after
one untimed run of each at the candidate's lowest rung (numba's kernels loaded). Each is timed as
calibrate_scene_costs.py times it, by the sum of its steps' times (the tables' `wall_s`), but
clocked here by time.process_time, so that CPU seconds are summed and other work on the machine
counts for little; the median of the repeats.

Printed per rung: its counted seconds (Scene.run_cost, the cost model the scenes decide with,
with settings.REACTIVE_COST's factors), the measured CPU seconds of both runs and their ratios;
then per method the median and range of reactive / counted (the cost model's error on reactive
runs), conservative / transport (its run against the scene's `cost` alone: the calibration's own
error on this machine) and reactive / conservative (what the reaction adds, free of the machine's
speed), and the factors to paste into settings.REACTIVE_COST, fitted by scipy.optimize.nnls as
calibrate_scene_costs.py fits (its ``fit``, relative least squares): the reactive CPU seconds on
the transport's counted step part (seconds a step x steps) and work part (seconds a unit x work),
each scaled by the rung's measured conservative / transport, so that the factors are the
reaction's alone (a method whose reactive / conservative stays within about 20 % of 1, as FD's,
is left out of REACTIVE_COST: factor 1). Takes about 3 minutes. Time with nothing else running;
quote the CPU (`lscpu`).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections import defaultdict
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
from calibrate_scene_costs import fit, rungs

from particle_entropy.core import records
from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.runcost import StepWork
from particle_entropy.models import simulate
from particle_entropy.pipeline.configcheck import load_yaml
from particle_entropy.scenes import reference as reactive
from particle_entropy.scenes.scene import scenes


def reference(scene) -> dict:
    """The scene's reference, as its jobs read it: the workflow's file if there is one, else computed."""
    path = reactive.path(scene)
    if os.path.exists(path):
        return reactive.read(path)
    out = reactive.compute(reactive.physics(scene))
    for key in ("points", "a_points", "a_error", "c_points", "c_error", "times", "product_series"):
        out[key] = np.asarray(out[key], dtype=np.float64)
    return out


def steps_cpu(table) -> float:
    """The CPU seconds of a run's steps: its table's summed `wall_s`, clocked by process_time here."""
    return float(np.sum(table.column("wall_s").to_numpy()))


def transport_parts(scene, cfg) -> tuple[float, float]:
    """The counted cost of a run's transport (the scene's `cost`, no reaction factor) split into its
    steps' part and its work's part [s] (StepWork)."""
    per_step, per_unit = dict(scene.cost)[cfg.method]
    tally = StepWork(per_step, per_unit).tally(cfg)
    return per_step * float(np.sum(tally.steps)), per_unit * float(np.sum(tally.work))


def measure(config: dict, names: list[str], max_s: float, repeat: int) -> dict[str, list[dict]]:
    """Per method, one row per rung timed: counted, its parts, the CPU seconds of both runs' steps."""
    out: dict[str, list[dict]] = defaultdict(list)
    table_of = scenes(config)
    names = names or [name for name in table_of if table_of.spec(name).get("reaction")]
    seed = int(config.get("base_seed", 0))
    for name in names:
        scene = table_of[name]
        ref = reference(scene)
        for cand in scene.candidates:
            picked = rungs(scene, cand, max_s)
            if picked:  # untimed: numba's kernels of both runs loaded before either is timed
                low = scene.run_config(cand, picked[0], seed=seed)
                simulate.run_seeds_arrow(replace(low, reaction=None), [low.seed])
                simulate.run_seeds_arrow(low, [low.seed], reference=ref)
            for n in picked:
                cfg = scene.run_config(cand, n, seed=seed)
                cons, react = [], []
                for _ in range(repeat):  # interleaved: both runs see the same machine
                    cons.append(steps_cpu(simulate.run_seeds_arrow(replace(cfg, reaction=None), [cfg.seed])))
                    react.append(steps_cpu(simulate.run_seeds_arrow(cfg, [cfg.seed], reference=ref)))
                step_s, work_s = transport_parts(scene, cfg)
                row = {
                    "what": f"{name}: {cand.label} n={n}",
                    "counted": scene.run_cost(cand, n),
                    "transport": step_s + work_s,
                    "step_s": step_s,
                    "work_s": work_s,
                    "cons_cpu": statistics.median(cons),
                    "react_cpu": statistics.median(react),
                }
                out[cfg.method].append(row)
                print(
                    f"{row['what']:55s} counted {row['counted']:7.3f} s  CPU: conservative {row['cons_cpu']:7.3f} s"
                    f"  reactive {row['react_cpu']:7.3f} s  reactive / counted {row['react_cpu'] / row['counted']:5.2f}"
                    f"  reactive / conservative {row['react_cpu'] / row['cons_cpu']:5.2f}",
                    flush=True,
                )
    return out


def spread(values: list[float]) -> str:
    """Median and range of ratios."""
    return f"{statistics.median(values):5.2f} [{min(values):.2f}, {max(values):.2f}]"


def factors(rows: list[dict]) -> tuple[float, float, list[float]]:
    """The reaction's factors on the counted cost's step and work parts, fitted (calibrate_scene_costs.fit)
    to the reactive CPU seconds on those parts scaled by each rung's conservative CPU / counted."""
    points = []
    for r in rows:
        machine = r["cons_cpu"] / r["transport"]  # this machine's (and this rung's) measured / counted
        points.append((r["step_s"] * machine, r["work_s"] * machine, r["react_cpu"], r["what"]))
    return fit(points)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default="config.yaml")
    ap.add_argument("--max-s", type=float, default=2.0, help="skip rungs counted dearer than this [s]")
    ap.add_argument("--repeat", type=int, default=3, help="interleaved runs of each kind per rung (median)")
    ap.add_argument("scenes", nargs="*", help="scene names (default: every reactive scene of the config)")
    args = ap.parse_args()
    keep_freed_pages()
    records.time = SimpleNamespace(perf_counter=time.process_time)  # the tables' step times in CPU seconds
    rows = measure(load_yaml(args.config), args.scenes, args.max_s, args.repeat)
    print(f"\n{'method':6s} {'runs':>4s}  {'reactive / counted':>24s}  {'conservative / transport':>24s}", end="")
    print(f"  {'reactive / conservative':>24s}  (CPU; median [range])")
    for method in sorted(rows):
        rs = rows[method]
        react = [r["react_cpu"] / r["counted"] for r in rs]
        cons = [r["cons_cpu"] / r["transport"] for r in rs]
        both = [r["react_cpu"] / r["cons_cpu"] for r in rs]
        print(f"{method:6s} {len(rs):4d}  {spread(react):>24s}  {spread(cons):>24s}  {spread(both):>24s}")
    print("\nreactive factors on the transport's counted [step part, work part] (nnls, relative):")
    lines = []
    for method in sorted(rows):
        on_step, on_work, ratios = factors(rows[method])
        print(f"{method}: [{on_step:.3g}, {on_work:.3g}]  measured / fitted {spread(ratios)}")
        lines.append(f'"{method}": [{on_step:.3g}, {on_work:.3g}]')
    print("REACTIVE_COST = {" + ", ".join(lines) + "}")


if __name__ == "__main__":
    main()
