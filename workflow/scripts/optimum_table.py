"""The result of a finished adaptive COMIC search: every visited N, the optimum and its bracket,
the runs and core-seconds spent, and the estimated cost of a full sweep."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.optimum import Search, read_runs, result_table
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, par, out = snakemake.input, snakemake.params, snakemake.output
search = Search.from_config(snakemake.wildcards.name, par.spec, par.settings)
realisations, costs = read_runs(list(inp.runs), search.time)
table = result_table(search, read_parquet(inp.plan), realisations, costs)
write_parquet(table, out[0])
print(table.to_string(), file=sys.stderr)
