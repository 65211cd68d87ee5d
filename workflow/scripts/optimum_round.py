"""One round of an adaptive COMIC search: round 0 is the coarse grid; round k reads the COMIC of
every run of plan k-1 at the search's time and writes the next plan (or plan k-1, done). How long
the runs took is not read (optimum.advance): the plan depends on the config and the values only."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.optimum import Search, advance, initial_plan
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
search = Search.from_config(snakemake.wildcards.name, par.spec, par.settings)
if "plan" in inp.keys():
    plan = advance(search, read_parquet(inp.plan), list(inp.runs))
else:
    plan = initial_plan(search, int(par.base_seed))
write_parquet(plan, out[0])
print(plan.to_string(), file=sys.stderr)
