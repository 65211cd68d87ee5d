"""Draw one scene's figure from its table."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)

import matplotlib

matplotlib.use("Agg")

import pandas as pd

from particle_entropy.figures.scene import scene
from particle_entropy.figures.style import save_figure

figure = scene(pd.read_parquet(snakemake.input[0]))
save_figure(figure, snakemake.output.png, snakemake.output.pdf)
