"""Draw the speed-accuracy trade-off figure from its table."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import pandas as pd  # noqa: E402

from particle_entropy import plots  # noqa: E402

table = pd.read_parquet(snakemake.input[0])  # noqa: F821
plots.save_figure(plots.tradeoff(table), snakemake.output.png, snakemake.output.pdf)  # noqa: F821
