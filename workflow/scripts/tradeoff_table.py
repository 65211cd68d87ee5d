"""Cost beside error for every model, N and requested time."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

from particle_entropy.analysis.aggregate import tradeoff_table
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

table = tradeoff_table([read_parquet(p) for p in snakemake.input], [float(t) for t in snakemake.params.times])
write_parquet(table, snakemake.output[0])
print(table.to_string(), file=sys.stderr)
