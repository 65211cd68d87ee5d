"""Draw one scene's figure from its table."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

from particle_entropy.core.io import exit_on_table_errors, read_parquet
from particle_entropy.figures.scene import scene
from particle_entropy.figures.style import save_figure

exit_on_table_errors()  # a table that fails its page checksums: one line naming it, exit 1

figure = scene(read_parquet(snakemake.input[0]))
save_figure(figure, snakemake.output.png, snakemake.output.pdf)
