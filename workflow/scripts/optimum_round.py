"""One round of an adaptive COMIC search: round 0 is the coarse grid; round k reads the COMIC of
every run of plan k-1 at the search's time and writes the next plan (or plan k-1, done)."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import pandas as pd

from particle_entropy.analysis.optimum import Search, initial_plan, next_plan, read_runs
from particle_entropy.core.io import write_parquet

inp, par, out = snakemake.input, snakemake.params, snakemake.output
search = Search.from_config(snakemake.wildcards.name, par.spec, par.settings)
if "plan" in inp.keys():
    realisations, costs = read_runs(list(inp.runs), search.time)
    plan = next_plan(search, pd.read_parquet(inp.plan), realisations, costs)
else:
    plan = initial_plan(search, int(par.base_seed))
write_parquet(plan, out[0])
print(plan.to_string(), file=sys.stderr)
