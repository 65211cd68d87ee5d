"""COMIC statistics per model, N and time, the per-realisation values behind them, a bootstrap of
where the COMIC minimum lies, and the N that minimises mean COMIC with its interval."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import pandas as pd  # noqa: E402

from particle_entropy.aggregate import comic_argmin, comic_minima, comic_table, read_realisations  # noqa: E402
from particle_entropy.io import write_parquet  # noqa: E402

inp, out = snakemake.input, snakemake.output  # noqa: F821
times = [float(t) for t in snakemake.params.times]  # noqa: F821
comic = comic_table([pd.read_parquet(p) for p in inp.summaries], times)
realisations = read_realisations(list(inp.runs), times)
argmin = comic_argmin(realisations)
minima = comic_minima(comic, argmin)
for table, path in ((comic, out.comic), (realisations, out.realisations), (argmin, out.argmin), (minima, out.minima)):
    write_parquet(table, path)
print(minima.to_string(), file=sys.stderr)
