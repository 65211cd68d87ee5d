"""Draw figures/optimum_<name>.png from the result table of an adaptive COMIC search."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

import pandas as pd

from particle_entropy.figures.optimum import optimum_figure
from particle_entropy.figures.style import save_figure

inp, out = snakemake.input, snakemake.output
table = pd.read_parquet(inp[0])
save_figure(optimum_figure(table), out.png, out.pdf)
print(f"drew {len(table)} visited N of search {snakemake.wildcards.name}", file=sys.stderr)
