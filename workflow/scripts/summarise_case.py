"""Average the realisations of one case, step by step."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import pandas as pd  # noqa: E402

from particle_entropy.aggregate import summarise_runs  # noqa: E402
from particle_entropy.io import write_parquet  # noqa: E402

blocks = pd.concat([pd.read_parquet(p) for p in snakemake.input], ignore_index=True)  # noqa: F821
runs = [g for _, g in blocks.groupby("seed", sort=True)]
write_parquet(summarise_runs(runs), snakemake.output[0])  # noqa: F821
print(f"summarised {len(runs)} realisations", file=sys.stderr)
