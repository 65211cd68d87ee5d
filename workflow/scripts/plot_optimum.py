"""Draw figures/optimum_<name>.png from the result table of an adaptive COMIC search."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.core.io import exit_on_table_errors, read_parquet
from particle_entropy.figures.optimum import optimum_figure
from particle_entropy.figures.style import save_figure

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

inp, out = snakemake.input, snakemake.output
table = read_parquet(inp[0])
save_figure(optimum_figure(table), out.png, out.pdf)
print(f"drew {len(table)} visited N of search {snakemake.wildcards.name}", file=sys.stderr)
