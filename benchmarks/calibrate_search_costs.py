"""Calibrate the cost model of every adaptive search that has a core-second budget: the
seconds one run takes at each point of the search's coarse grid, written into config.yaml as
the search's `cost` (optimum.py, Search.cost).

    python benchmarks/calibrate_search_costs.py [--config config.yaml] [--repeat 3] [SEARCH ...]

Each point runs up to `--repeat` realisations (seeds base_seed, base_seed + 1, ...) in this
process, one after another, as a simulation job would (models.simulate.run_seeds_arrow), and
takes the median of their summed step wall times (job start-up excluded, as in the run tables'
`wall_s`).
Time with nothing else running. The printed `cost:` lines go under `optimum.<name>` in the
config: from then on the search predicts the cost of a run from them (interpolated in log-log),
on every machine alike, so its path depends only on the config and the seeds.
"""

from __future__ import annotations

import argparse
import statistics
import time

from particle_entropy.core.heap import keep_freed_pages
from particle_entropy.core.runconfig import RunConfig
from particle_entropy.models.simulate import run_seeds_arrow
from particle_entropy.pipeline.configcheck import load_yaml
from particle_entropy.pipeline.sweeps import run_settings

LONG_S = 2.0  # a run this long is timed once: its noise is small against its cost


def seconds_per_run(cfg: RunConfig, seed: int) -> float:
    """Summed step wall times of one realisation (the run table's `wall_s`)."""
    table = run_seeds_arrow(cfg, [seed])
    return float(table.column("wall_s").to_numpy().sum())


def calibrate(search, config: dict, repeat: int) -> list[list[float]]:
    """[[searched value, seconds per run], ...] over the search's coarse grid: the median of up to
    ``repeat`` realisations, fewer once one takes over LONG_S; after one untimed run that compiles
    the kernels (a job loads them from numba's cache)."""
    points, base = [], int(config["base_seed"])
    for k, x in enumerate(search.coarse):
        case = search.case_at(x)
        cfg = RunConfig.for_case(case, **run_settings(case, config)).resolved()
        if k == 0:
            seconds_per_run(cfg, base)
        times = []
        for r in range(repeat):
            times.append(seconds_per_run(cfg, base + r))
            if times[-1] > LONG_S:
                break
        seconds = statistics.median(times)
        points.append([x, float(f"{seconds:.3g}")])
        print(f"  {search.name}: {search.over} = {x:g}: {seconds:.3g} s a run", flush=True)
    return points


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("names", nargs="*", help="searches to calibrate (default: every one with budget_core_s)")
    parser.add_argument("--config", default="config.yaml")
    parser.add_argument("--repeat", type=int, default=3, help="realisations per point (their median is taken)")
    a = parser.parse_args()
    from particle_entropy.analysis.optimum import Search

    keep_freed_pages()
    config = load_yaml(a.config)
    specs = config.get("optimum", {})
    names = a.names or [k for k, v in specs.items() if "budget_core_s" in v]
    lines = []
    start = time.perf_counter()
    for name in names:
        spec = {k: v for k, v in specs[name].items() if k not in ("cost", "budget_core_s")}
        search = Search.from_config(name, spec, config)
        points = calibrate(search, config, a.repeat)
        lines.append(f"  {name}:\n    cost: {points}")
    print(f"\n# calibrated in {time.perf_counter() - start:.0f} s; paste under `optimum`:")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
