"""The adaptive COMIC searches (config `optimum`) against the paper's full grid, and what the
paper's three open points on COMIC do to each optimum.

    python benchmarks/bench_optimum.py RUN_DIR [--cores 2] [--no-run]

RUN_DIR is a checkout where the paper has been reproduced (`snakemake -j2`: the Fig. 8 / Fig. 9
grids and their run tables). The script then, in RUN_DIR,
1. runs `snakemake optimum` (the shipped searches), then the same with an overlay config
   (written to RUN_DIR/bench_optimum_options.yaml) adding three variants of every N search:
   `<name>__points` (SSE at the 15 common measurement points), `<name>__mean_sse` (COMIC of the
   mean SSE) and `<name>__dt` (the time step in the sampling volume); a search already done is
   not rerun (--no-run: report only);
2. for each shipped N search, compares it with the paper's grid for the same model: the grid's
   optimum and bracket (results/tables/comic_minima.parquet, the grid points around the 95 %
   interval of the argmin) and its measured core-seconds (summed step wall times of the grid's
   runs: the realisations Fig. 8 / Fig. 9 average), and with the estimated full sweep giving
   the search's own bracket (`full_sweep_core_s`);
3. prints two Markdown tables and writes them to RUN_DIR/bench_optimum.md.

Core-seconds of the search and of the grid come from the same run tables, so from the same
session when RUN_DIR was made in one. Cached runs shared between a search and the grid count for
both, as each would have to run them alone.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import pandas as pd
import yaml

from particle_entropy.analysis.optimum import read_costs
from particle_entropy.core.case import Case, rows_of
from particle_entropy.pipeline.configcheck import load_yaml
from particle_entropy.pipeline.crosschecks import optimum_searches
from particle_entropy.pipeline.sweeps import case_run_paths, figure_ensembles

VARIANTS = {  # suffix -> what it changes in the search
    "points": {"measure": "points"},
    "mean_sse": {"convention": "COMIC_of_mean_SSE"},
    "dt": {"time_volume": True},
}
GRID_FIGURES = ("fig8", "fig9")  # the paper's full N grids (FD at t = 250; the three MTPT models)


def overlay(config: dict) -> dict:
    """The variant searches of every shipped search (a growth search: with the time step in the
    sampling volume switched the other way)."""
    out = {}
    for name, spec in config.get("optimum", {}).items():
        if "growth_range" in spec:
            out[f"{name}__dt"] = {**spec, "time_volume": not spec.get("time_volume", False)}
            continue
        for suffix, change in VARIANTS.items():
            out[f"{name}__{suffix}"] = {**spec, **change}
    return {"optimum": out}


def snakemake(run_dir: Path, cores: int, *configfiles: str) -> None:
    cmd = [sys.executable, "-m", "snakemake", f"-j{cores}", "optimum", "-q"]
    if configfiles:
        cmd += ["--configfile", *configfiles]
    subprocess.run(cmd, cwd=run_dir, check=True)


def grid_of(search, config: dict, run_dir: Path) -> dict | None:
    """The paper grid's optimum, bracket, runs and measured core-seconds for the search's model."""
    for fig in GRID_FIGURES:
        if fig not in config.get("figures", {}):
            continue
        ens = [e for e in figure_ensembles(config, fig) if Case.at(e.case, None) == search.model]
        if not ens:
            continue
        paths = [run_dir / p for e in ens for p in case_run_paths(e, config)]
        costs = read_costs([str(p) for p in paths])
        keep = pd.concat(
            [costs[(costs["n"] == e.case.n) & (costs["seed"] < config["base_seed"] + e.realisations)] for e in ens]
        )
        minima = pd.read_parquet(run_dir / "results/tables/comic_minima.parquet")
        row = rows_of(minima[minima["time"] == search.time], search.model)
        if row.empty:
            continue
        row = row.iloc[0]
        ns = sorted(e.case.n for e in ens)
        lo, hi = int(row["n_opt_ci_lo"]), int(row["n_opt_ci_hi"])
        if lo < 0:  # no resampling (FD): the interval is the optimum itself
            lo = hi = int(row["n_opt"])
        below = [n for n in ns if n < lo]
        above = [n for n in ns if n > hi]
        return {
            "grid_opt": int(row["n_opt"]),
            "grid_ci": (lo, hi),
            "grid_bracket": (below[-1] if below else ns[0], above[0] if above else ns[-1]),
            "grid_runs": len(keep),
            "grid_core_s": float(keep["core_s"].sum()),
        }
    return None


def _n(v: float, growth: bool = False) -> str:
    return f"{v:.4g}" if growth else f"{int(round(v)):,}"


def report(run_dir: Path, config: dict) -> str:
    searches = optimum_searches(config)
    rows, options = [], []
    for name, search in searches.items():
        path = run_dir / f"results/optimum/{name}.parquet"
        if "__" in name or not path.exists():
            continue
        r = pd.read_parquet(path).iloc[0]
        growth = search.over == "dt_growth"
        line = (
            f"| {name} | {_n(r['optimum'], growth)} [{_n(r['ci_lo'], growth)}, {_n(r['ci_hi'], growth)}] "
            f"| [{_n(r['bracket_lo'], growth)}, {_n(r['bracket_hi'], growth)}] | {r['reason']} "
            f"| {int(r['runs_spent'])} | {r['core_s_spent']:.1f} | {r['full_sweep_core_s']:.1f} "
            f"| {r['core_s_spent'] / r['full_sweep_core_s']:.2f} |"
        )
        grid = None if growth else grid_of(search, config, run_dir)
        if grid:
            b = grid["grid_bracket"]
            inside = b[0] <= r["optimum"] <= b[1]
            line += (
                f" {grid['grid_opt']:,} [{b[0]:,}, {b[1]:,}] | {grid['grid_runs']} | {grid['grid_core_s']:.1f} "
                f"| {r['core_s_spent'] / grid['grid_core_s']:.2f} | {'yes' if inside else 'NO'} |"
            )
        else:
            line += " – | – | – | – | – |"
        rows.append(line)
        cells = [f"{_n(r['optimum'], growth)} [{_n(r['ci_lo'], growth)}, {_n(r['ci_hi'], growth)}]"]
        for suffix in VARIANTS:
            v = run_dir / f"results/optimum/{name}__{suffix}.parquet"
            if v.exists():
                o = pd.read_parquet(v).iloc[0]
                interval = f"{_n(o['optimum'], growth)} [{_n(o['ci_lo'], growth)}, {_n(o['ci_hi'], growth)}]"
                cells.append(f"{interval} ({int(o['runs_spent'])} runs, {o['core_s_spent']:.1f} core-s)")
            else:
                cells.append("–")
        options.append(f"| {name} | " + " | ".join(cells) + " |")
    head = (
        "| search | optimum [95 % interval] | bracket | stopped | runs | core-s | same-bracket sweep core-s (est.) "
        "| ratio | paper grid: optimum [bracket] | grid runs | grid core-s | ratio to grid | inside grid bracket |\n"
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    )
    head2 = (
        "| search | as shipped | SSE at the 15 common points | COMIC of the mean SSE "
        "| dt in the sampling volume (a growth search: switched) |\n"
        "|---|---|---|---|---|"
    )
    return "\n".join([head, *rows, "", head2, *options]) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run_dir", type=Path)
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--no-run", action="store_true", help="report on the searches already run")
    a = ap.parse_args(argv)
    run_dir = a.run_dir.resolve()
    config = dict(load_yaml(run_dir / "config.yaml"))
    extra = overlay(config)
    (run_dir / "bench_optimum_options.yaml").write_text(yaml.safe_dump(extra, sort_keys=False))
    if not a.no_run:
        snakemake(run_dir, a.cores)
        snakemake(run_dir, a.cores, "config.yaml", "bench_optimum_options.yaml")
    merged = {**config, "optimum": {**config.get("optimum", {}), **extra["optimum"]}}
    text = report(run_dir, merged)
    (run_dir / "bench_optimum.md").write_text(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
