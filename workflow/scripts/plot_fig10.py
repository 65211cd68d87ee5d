"""Draw Fig. 10 (Appendix B shear flow) from the final particle tables of the three cases."""

import sys

sys.stderr = open(snakemake.log[0], "w", buffering=1)  # noqa: F821

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import pandas as pd  # noqa: E402

from particle_entropy import plots_shear  # noqa: E402

states = [pd.read_parquet(p) for p in snakemake.input]  # noqa: F821
plots_shear.save_figure(plots_shear.fig10(states), snakemake.output.png, snakemake.output.pdf)  # noqa: F821
print(f"drew fig10 from {len(states)} state tables", file=sys.stderr)
