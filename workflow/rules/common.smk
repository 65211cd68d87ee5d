# Config validation, the sweep table (one row per simulation) and target helpers.
import math
import sys
from pathlib import Path

import pandas as pd
from snakemake.utils import validate

sys.path.insert(0, str(Path(workflow.basedir) / "workflow" / "lib"))
validate(config, str(Path(workflow.basedir) / "workflow" / "schemas" / "config.schema.yaml"))

from particle_entropy.aggregate import summarise_files  # noqa: E402
from particle_entropy.sweeps import (  # noqa: E402
    spec_cases,
    case_runs,
    check_sweeps,
    figure_cases,
    run_path,
    summary_path,
)

check_sweeps(config)
FIGURES = sorted(config["figures"])
SHEAR_FIGURE = ["fig10"] if "shear" in config else []
ALL_FIGURES = [f for f in ["fig1", "fig2", "fig3", "fig4", "fig5", "fig6", "fig7", "fig8", "fig9"] if f in FIGURES]


wildcard_constraints:
    method="pt|mtpt|fd",
    kernel="bins|fixed|adaptive|collision|sph|implicit|explicit",
    n=r"\d+",
    eta=r"[0-9.eE+-]+",
    trunc=r"none|[0-9.eE+-]+",
    growth=r"[0-9.eE+-]+",
    first=r"\d+",
    last=r"\d+",
    nreal=r"\d+",
    fig=r"fig\d+",


def all_targets():
    figs = [f"figures/{f}.{ext}" for f in ALL_FIGURES + SHEAR_FIGURE for ext in ("png", "pdf")]
    if "tradeoff" in config:
        figs += ["figures/tradeoff.png", "figures/tradeoff.pdf", "results/tables/tradeoff.parquet"]
    return figs + [
        "results/tables/comic.parquet",
        "results/tables/comic_minima.parquet",
        "results/tables/paper_claims.parquet",
        "results/paper_claims.md",
    ]


def figure_inputs(fig):
    """What a figure reads: single runs (Figs. 1, 2), final states (Fig. 7), the COMIC table
    (Fig. 9) or case summaries (ensemble figures and FD)."""
    if fig == "fig9":
        return ["results/tables/fig9/comic.parquet"]
    cases = figure_cases(config, fig)
    if config["figures"][fig].get("snapshot"):
        return [run_path(c, config["base_seed"], kind="snapshots") for c in cases]
    if fig in ("fig1", "fig2"):
        return [run_path(c, config["base_seed"]) for c in cases]
    return [summary_path(c) for c in cases]


def summary_runs(wildcards):
    """The run tables that one case summary averages."""
    return case_runs(wildcards, config)


def comic_summaries():
    """Case summaries of the COMIC models: FD (Fig. 8) and the MTPT models of Fig. 9."""
    return [summary_path(c) for f in ("fig8", "fig9") if f in FIGURES for c in figure_cases(config, f)]


def sim_mem_mb(wildcards):
    return 300 + int(wildcards.n) // 20


def sim_runtime_min(wildcards):
    seeds = int(wildcards.last) - int(wildcards.first) + 1
    return seeds * (2 if int(wildcards.n) <= 3000 else 10)


def first_step(wildcards):
    """FD runs use their own fixed step (Fig. 8); particle runs start at dt0, or take the
    fixed step time.fixed_dt when their growth factor is 1."""
    if wildcards.method == "fd":
        return config["time"]["fd_dt"]
    return config["time"]["fixed_dt"] if float(wildcards.growth) == 1.0 else config["time"]["dt0"]
