"""Draw the Peclet sweep: the cost of the best grid and the best particle model against v L / D."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.analysis.scene_search import peclet_table
from particle_entropy.core.io import exit_on_table_errors, read_parquet, write_parquet
from particle_entropy.figures.scenes_peclet import scenes_peclet
from particle_entropy.figures.style import save_figure

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

table = peclet_table([read_parquet(p) for p in snakemake.input])
save_figure(scenes_peclet(table), snakemake.output.png, snakemake.output.pdf)
write_parquet(table, snakemake.output.data)
print(table.to_string(), file=sys.stderr)
