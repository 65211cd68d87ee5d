"""COMIC statistics per model, N and time, and the N that minimises mean COMIC."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import pandas as pd  # noqa: E402

from particle_entropy.aggregate import comic_minima, comic_table  # noqa: E402
from particle_entropy.io import write_parquet  # noqa: E402

summaries = [pd.read_parquet(p) for p in snakemake.input]  # noqa: F821
comic = comic_table(summaries, [float(t) for t in snakemake.params.times])  # noqa: F821
minima = comic_minima(comic)
write_parquet(comic, snakemake.output.comic)  # noqa: F821
write_parquet(minima, snakemake.output.minima)  # noqa: F821
print(minima.to_string(), file=sys.stderr)
