"""Cost beside error for every model, N and requested time."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import pandas as pd

from particle_entropy.analysis.aggregate import tradeoff_table
from particle_entropy.core.io import write_parquet

table = tradeoff_table([pd.read_parquet(p) for p in snakemake.input], [float(t) for t in snakemake.params.times])
write_parquet(table, snakemake.output[0])
print(table.to_string(), file=sys.stderr)
