"""Cost beside error for every model, N and requested time."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import pandas as pd  # noqa: E402

from particle_entropy.analysis.aggregate import tradeoff_table  # noqa: E402
from particle_entropy.core.io import write_parquet  # noqa: E402

table = tradeoff_table([pd.read_parquet(p) for p in snakemake.input], [float(t) for t in snakemake.params.times])  # noqa: F821
write_parquet(table, snakemake.output[0])  # noqa: F821
print(table.to_string(), file=sys.stderr)
