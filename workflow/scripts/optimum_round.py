"""One round of an adaptive COMIC search: round 0 is the coarse grid; round k reads the COMIC of
every run of plan k-1 at the search's time and writes the next plan (or plan k-1, done). How long
the runs took is not read (Search.read_runs): the plan depends on the config and the values only."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.optimum import Search
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
search = Search.from_config(snakemake.wildcards.name, par.spec, par.settings)
plan = read_parquet(inp.plan) if "plan" in inp.keys() else None
plan = search.round(plan, list(inp.runs) if plan is not None else [], int(par.base_seed))  # the search engine's round
write_parquet(plan, out[0])
print(plan.to_string(), file=sys.stderr)
